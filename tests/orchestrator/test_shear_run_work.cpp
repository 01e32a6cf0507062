// Shear-box parameters that are each in their range but make a run impossible or endless (hostile42 findings 10-12):
// the work the box implies (particles, steps) and the physical lower bounds (travel against the particle size,
// Young modulus against the normal stress), refused before anything runs by the one check of
// orchestrator/shear_params.cpp, in `demcal shear-run` (exit 2, `DEMCAL_FAILURE params:`, no result) and in every
// campaign (before its folder exists). Every material of the repository still passes, the estimate is the run's own
// (a real kernel run is compared with it), and the YADE script's copy of the table has the same ranges.
#include "campaign_test_support.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"
#include "orchestrator/shear_params.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace fs = std::filesystem;
using namespace demcal;
using Catch::Matchers::Contains;

namespace {

const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();

// sand-tiny.json as a run's params.json (5 kPa, seed 1), one field changed
nlohmann::json tiny_params(const std::string& field = "", nlohmann::json value = nullptr) {
    nlohmann::json p = nlohmann::json::parse(test::read_file(tiny));
    p.erase("name");
    p.erase("description");
    p["normal_stress"] = 5e3;
    p["seed"] = 1;
    if (!field.empty()) p[field] = value;
    return p;
}

// demcal with these arguments under a wall-clock limit: the old code ran some of these cases for ever (exit 137 then)
int run_demcal_limited(const std::vector<std::string>& args, const fs::path& log) {
    std::string cmd = "timeout -s KILL 60 '" + std::string(DEMCAL_BINARY) + "'";
    for (const auto& a : args) cmd += " '" + a + "'";
    cmd += " > '" + log.string() + "' 2>&1 < /dev/null";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// shear-run on params with `field` = `value`: exit 2, a DEMCAL_FAILURE params line naming everything in `expect`,
// no result written
void shear_run_refuses(const fs::path& dir, const std::string& field, const nlohmann::json& value,
                       const std::vector<std::string>& expect) {
    const fs::path params = dir / (field + ".json"), result = dir / (field + "_result.json"), log = dir / "run.log";
    orchestrator::write_text_file_atomically(params, tiny_params(field, value).dump());
    const int rc = run_demcal_limited({"shear-run", params.string(), result.string(), "--threads", "1"}, log);
    const std::string text = test::read_file(log);
    INFO(field << " = " << value.dump() << ": " << text.substr(0, 2000));
    CHECK(rc == 2);
    CHECK_THAT(text, Contains("DEMCAL_FAILURE params:"));
    for (const auto& e : expect) CHECK_THAT(text, Contains(e));
    CHECK(text.size() < 2000);  // one message, not a run's progress
    CHECK_FALSE(fs::exists(result));
}

// a campaign command refused with exit 2, naming everything in `expect`, before its folder exists
void campaign_refuses(const std::vector<std::string>& args, const fs::path& campaign,
                      const std::vector<std::string>& expect) {
    const fs::path log = campaign.parent_path() / "campaign.log";
    const int rc = run_demcal_limited(args, log);
    const std::string text = test::read_file(log);
    INFO(args[0] << ": " << text.substr(0, 2000));
    CHECK(rc == 2);
    for (const auto& e : expect) CHECK_THAT(text, Contains(e));
    CHECK_FALSE(fs::exists(campaign));
}

}  // namespace

TEST_CASE("shear-run refuses a box of absurdly many particles, naming particle_radius", "[params][shear_run]") {
    const fs::path dir = test::fresh_test_dir("work-particles");
    // 1 um grains in a 4 cm box: about 4e12 particles (ran for ever); 1 nm: an internal wall error, no field named
    shear_run_refuses(dir, "particle_radius", 1e-6, {"particle_radius = 1e-06 m", "particles", "limit 1e+06"});
    shear_run_refuses(dir, "particle_radius", 1e-9, {"particle_radius = 1e-09 m", "particles", "limit 1e+06"});
    fs::remove_all(dir);
}

TEST_CASE("shear-run refuses a run of absurdly many time steps, naming the fields that drive them",
          "[params][shear_run]") {
    const fs::path dir = test::fresh_test_dir("work-steps");
    shear_run_refuses(dir, "timestep_fraction", 1e-12, {"timestep_fraction = 1e-12", "steps", "limit 1e+08"});
    shear_run_refuses(dir, "shear_velocity", 1e-9, {"shear_velocity = 1e-09 m/s", "steps", "limit 1e+08"});
    // below the weight of the box's grains (sand-tiny: 260 Pa) the lid never settles: 1e-6 Pa would also need 7e9
    // consolidation steps, 100 Pa consolidated for 700,000 steps and failed (probe 44)
    shear_run_refuses(dir, "normal_stress", 1e-6, {"normal_stress = 1e-06 Pa", "below the weight of the box's grains"});
    shear_run_refuses(dir, "normal_stress", 100, {"normal_stress = 100 Pa", "about 260 Pa"});
    // lighter than any granular solid: a lower bound of the table
    shear_run_refuses(dir, "density", 1e-3, {"'density' = 0.001", "[10, 100000]"});
    // more samples than the shear's steps: one step each moved the frame past shear_displacement (probe 58b: 6.56
    // mm for 4 mm, a peak line of 2530 Pa against 1533; at 100000 the frame left the box)
    shear_run_refuses(dir, "samples", 20000, {"samples = 20000 is more than the shear's time steps", "at most"});
    // a seed above 2^63 was shown wrapped ("'seed' = -1 is outside ..."): as typed now
    shear_run_refuses(dir, "seed", nlohmann::json(18446744073709551615ULL), {"'seed' = 18446744073709551615"});
    fs::remove_all(dir);
}

TEST_CASE("shear-run refuses a travel shorter than a particle fraction and a modulus the stress squeezes flat",
          "[params][shear_run]") {
    const fs::path dir = test::fresh_test_dir("work-physics");
    // a "peak" after 3 micrometres of a 4 mm grain sample was reported with exit 0
    shear_run_refuses(dir, "shear_displacement", 1e-12, {"'shear_displacement' = 1e-12", "particle length"});
    // the run failed with exit 3 (a sphere escaped) instead of a refusal: 1e5 Pa holds the box's own weight (about
    // 260 Pa) but not the run's 5 kPa; 1e-3 Pa not even the weight, so no run of that material can hold
    shear_run_refuses(dir, "young_modulus", 1e5, {"young_modulus = 100000 Pa", "normal_stress = 5000 Pa", "overlap"});
    shear_run_refuses(dir, "young_modulus", 1e-3,
                      {"(at the box's own weight, the least stress it holds): young_modulus = 0.001 Pa", "overlap"});
    fs::remove_all(dir);
}

TEST_CASE("campaigns refuse the same materials and stresses before their folder exists", "[params][shear_run]") {
    const fs::path dir = test::fresh_test_dir("work-campaigns");
    const fs::path camp = dir / "camp";
    auto material = [&](const std::string& field, const nlohmann::json& value) {
        nlohmann::json m = nlohmann::json::parse(test::read_file(tiny));
        m[field] = value;
        const fs::path f = dir / ("m_" + field + ".json");
        orchestrator::write_text_file_atomically(f, m.dump());
        return f.string();
    };
    // each run would otherwise be started (the old code did), so a per-run limit keeps a failing test short
    const std::vector<std::string> limits{"--timeout", "5", "--retries", "0", "--jobs", "2"};
    auto with_limits = [&](std::vector<std::string> args) {
        args.insert(args.end(), limits.begin(), limits.end());
        return args;
    };
    const std::string radius = material("particle_radius", 1e-6), velocity = material("shear_velocity", 1e-9),
                      soft = material("young_modulus", 1e-3);
    campaign_refuses(with_limits({"shear", radius, "-s", "5e3,1e4,2e4", "--engine", "kernel", "-c", camp.string()}),
                     camp, {"particle_radius = 1e-06 m", "particles"});
    campaign_refuses(with_limits({"shear", velocity, "-s", "5e3,1e4,2e4", "-c", camp.string()}), camp,
                     {"shear_velocity = 1e-09 m/s", "steps"});
    campaign_refuses(with_limits({"shear", tiny, "-s", "1e-6,5e3,1e4", "--engine", "kernel", "-c", camp.string()}),
                     camp, {"normal_stress = 1e-06 Pa", "below the weight"});
    campaign_refuses(with_limits({"shear", soft, "-s", "5e3,1e4,2e4", "--engine", "kernel", "-c", camp.string()}), camp,
                     {"young_modulus = 0.001 Pa", "overlap"});
    campaign_refuses(with_limits({"sensitivity", velocity, "--params", "friction_coefficient", "-s", "5e3,1e4,2e4",
                                  "--engine", "kernel", "-c", camp.string()}),
                     camp, {"shear_velocity = 1e-09 m/s", "steps"});
    campaign_refuses(with_limits({"calibrate", "--start", velocity, "--target", "mu_b=1.3,tau_c=800", "--params",
                                  "friction_coefficient", "-s", "5e3,1e4,2e4", "--engine", "kernel", "-c",
                                  camp.string()}),
                     camp, {"shear_velocity = 1e-09 m/s", "steps"});
    // the scale study's radii replace the material's: the old code got only as far as its --max-runs guard
    campaign_refuses(with_limits({"scale", tiny, "--radii", "1e-9,2e-9,3e-9", "-s", "5e3,1e4,2e4", "--engine", "kernel",
                                  "--dir", camp.string()}),
                     camp, {"particle_radius = 1e-09 m", "particles"});
    fs::remove_all(dir);
}

TEST_CASE("every shear material of the repository passes the check at the stresses its examples use",
          "[params][shear_run]") {
    int materials = 0;
    for (const char* folder : {"examples/materials", "examples/calibration"})
        for (const auto& e : fs::recursive_directory_iterator(test::source_path(folder))) {
            if (e.path().extension() != ".json") continue;
            const auto m = nlohmann::json::parse(test::read_file(e.path()));
            if (!m.is_object() || !m.contains("particle_radius")) continue;  // a silo material, a result, a log
            INFO(e.path().string());
            nlohmann::json valid;
            REQUIRE_NOTHROW(valid = orchestrator::validate_material(m, e.path().string()));
            for (double sigma : {1e3, 2e3, 5e3, 1e4, 2e4})
                CHECK_NOTHROW(orchestrator::make_run_params(valid, sigma, 1));
            const auto work = orchestrator::estimate_shear_work(valid, 2e4);
            CHECK(work.particles < 0.01 * orchestrator::kMaxShearParticles);
            CHECK(work.steps() < 0.01 * orchestrator::kMaxShearSteps);
            ++materials;
        }
    CHECK(materials >= 12);  // 6 in examples/materials, 5 hidden ones and the calibrated ones in examples/calibration
}

TEST_CASE("the work estimate is the run's own: particle count, time step and steps of a real kernel run",
          "[params][shear_run]") {
    const fs::path dir = test::fresh_test_dir("work-estimate");
    const nlohmann::json p = tiny_params();
    orchestrator::write_text_file_atomically(dir / "params.json", p.dump());
    REQUIRE(test::run_demcal({"shear-run", (dir / "params.json").string(), (dir / "result.json").string()},
                             dir / "run.log") == 0);
    const auto r = orchestrator::read_shear_result(dir / "result.json");
    nlohmann::json material = p;
    material.erase("normal_stress");
    material.erase("seed");
    const auto work = orchestrator::estimate_shear_work(orchestrator::validate_material(material), 5e3);
    CHECK(r.at("particle_count").get<double>() == std::round(work.particles));
    // the smallest sphere is a little above r (1 - spread), so the estimated step is a little shorter
    CHECK(work.timestep <= r.at("timestep").get<double>());
    CHECK(work.timestep > 0.95 * r.at("timestep").get<double>());
    // growth runs in chunks of 200 steps and pauses while the lid holds more than the target: at least the nominal
    // steps (to a chunk), and on this box not twice them (2200 against 1778 at stop 64; the run's own limit is 20x)
    CHECK(r.at("growth_steps").get<double>() >= 0.8 * work.growth_steps);
    CHECK(r.at("growth_steps").get<double>() <= 2 * work.growth_steps + 200);
    CHECK(r.at("steps").get<double>() - r.at("consolidation_steps").get<double>() ==
          Approx(work.shear_steps).epsilon(0.05));
    CHECK(r.at("steps").get<double>() < work.steps());
    fs::remove_all(dir);
}

TEST_CASE("the YADE script's PARAM_SPECS has the ranges of the table", "[params][shear_run]") {
    // "name": ("unit", kind, low, low inclusive, high, high inclusive, ...
    std::ifstream f(test::source_path("yade_scripts/shear_box.py"));
    const std::regex entry(
        R"re(^\s*"(\w+)": \("([^"]*)", (float|int), ([-0-9.e+]+), (True|False), ([-0-9.e+]+), (True|False),)re");
    std::string line;
    std::smatch m;
    int entries = 0;
    while (std::getline(f, line)) {
        if (!std::regex_search(line, m, entry)) continue;
        INFO(line);
        const auto* spec = orchestrator::find_shear_param(m[1]);
        REQUIRE(spec);
        ++entries;
        CHECK(m[2] == spec->unit);
        CHECK((m[3] == "int") == spec->integer);
        CHECK(std::stod(m[4]) == spec->min);
        CHECK((m[5] == "False") == spec->min_exclusive);
        CHECK(std::stod(m[6]) == spec->max);
        // the one difference: YADE runs a stiffness ratio of 0.5, the kernel's materials need less (the table's)
        if (spec->name != "poisson_ratio") CHECK((m[7] == "False") == spec->max_exclusive);
    }
    CHECK(entries == int(orchestrator::shear_param_specs().size()));
}
