// `demcal scale` end to end, on each engine: the reduced study of examples/materials/sand-scale-tiny.json (radii
// 3.5, 4 and 4.5 mm, three normal stresses, one packing, E and nu studied at 3 levels, 2 evaluations per calibration
// aiming at the reference's values within 5 % (--point-targets --strict: the tiny box's own interval would accept any
// start and skip the study and the search): about 50 runs of about 3 s CPU on YADE, 0.2-0.4 s on the kernel engine),
// then the same command again, which must compute nothing. With one packing per stress, a failed run leaves a line
// unfit: the study goes on with fresh packings (test_replacement_packings.cpp) instead of stopping.
#include "test_files.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

int run_scale(const fs::path& dir, const std::string& log, const std::string& engine) {
    const std::string cmd = std::string(DEMCAL_BINARY) + " scale " + DEMCAL_SOURCE_DIR +
                            "/examples/materials/sand-scale-tiny.json --radii 3.5e-3,4e-3,4.5e-3"
                            " --normal-stress 4e3,6e3,8e3 --levels 3 --span 0.3 --max-evaluations 2 --point-targets --strict"
                            " --jobs 2 --engine " + engine + " --dir " +
                            dir.string() + " > " + (dir / log).string() + " 2>&1";
    return WEXITSTATUS(std::system(cmd.c_str()));
}

void check_reduced_study(const std::string& engine) {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-scale-" + engine + "-" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const int rc = run_scale(dir, "first.log", engine);
    INFO(demcal::test::read_file(dir / "first.log"));
    // 0: every fit determined; 1: some fit not (reported); never 2 (bad input) or a crash
    REQUIRE((rc == 0 || rc == 1));
    const auto j = nlohmann::json::parse(demcal::test::read_file(dir / "scale.json"));
    CHECK((rc == 1) == !j.at("problems").empty());

    const auto& radii = j.at("per_radius");
    REQUIRE(radii.size() == 3);
    for (std::size_t i = 0; i < radii.size(); ++i) {
        const auto& cost = radii[i].at("cost");
        CHECK(cost.at("runs").get<int>() >= 3);  // more where a failed packing was replaced
        CHECK(cost.at("cpu_s_per_run").get<double>() > 0);
        CHECK(cost.at("steps").get<double>() > 0);
        CHECK(std::isfinite(radii[i].at("base_line").at("mu_b").get<double>()));
        if (i == 0) continue;
        // larger spheres: fewer of them in the same box, and a longer critical time step (proportional to r)
        CHECK(cost.at("particles").get<double>() < radii[i - 1].at("cost").at("particles").get<double>());
        const double dt_ratio = cost.at("timestep_s").get<double>() /
                                radii[i - 1].at("cost").at("timestep_s").get<double>();
        const double r_ratio = radii[i].at("radius").get<double>() / radii[i - 1].at("radius").get<double>();
        CHECK(dt_ratio == Approx(r_ratio).epsilon(0.1));
        // every radius above the reference was calibrated: accepted at its start (no study), or searched after its
        // own study of E and nu (the search may stall at its start)
        REQUIRE(radii[i].contains("calibration"));
        const auto& calibration = radii[i].at("calibration");
        CHECK(calibration.at("evaluations").get<int>() >= 1);
        if (calibration.at("study").is_null())
            CHECK(calibration.at("status") == "converged");
        else
            CHECK(calibration.at("study").at("parameters").size() == 2);
    }
    // 4.5 mm spheres in a 4 cm box: 4 particle lengths across, below ASTM D3080's 10
    CHECK_FALSE(radii[2].at("box_ratio").at("adequate").get<bool>());
    CHECK(j.at("warnings").dump().find("ASTM D3080") != std::string::npos);
    CHECK(j.at("cost").at("law").at("law") == "power");
    CHECK(fs::exists(dir / "scale.md"));
    CHECK(fs::exists(dir / "scale_macro.png"));
    CHECK(fs::exists(dir / "scale_cost.png"));
    const int run_first = j.at("simulations_run").get<int>();
    CHECK(run_first > 0);
    CHECK(j.at("replacement_rounds").get<int>() <= 2 * j.at("evaluations").get<int>());
    if (j.at("replacement_rounds").get<int>() > 0) CHECK(j.at("simulations_failed").get<int>() > 0);

    // The same command again: every failure line comes from the store.
    const int rc_again = run_scale(dir, "second.log", engine);
    INFO(demcal::test::read_file(dir / "second.log"));
    CHECK(rc_again == rc);
    const auto again = nlohmann::json::parse(demcal::test::read_file(dir / "scale.json"));
    CHECK(again.at("simulations_run").get<int>() == 0);
    CHECK(again.at("evaluations") == j.at("evaluations"));
    CHECK(again.at("per_radius").at(1).at("base_line") == radii[1].at("base_line"));
    // `demcal resume` on the study's folder runs its shear campaigns only, and says the study is the command's
    // (probe 62: it exited 0 after an interrupted study as if the study were done)
    const std::string resume = std::string(DEMCAL_BINARY) + " resume " + dir.string() + " > " +
                               (dir / "resume.log").string() + " 2> " + (dir / "resume.err").string();
    (void)std::system(resume.c_str());
    CHECK_THAT(demcal::test::read_file(dir / "resume.err"),
               Catch::Matchers::Contains("holds the runs of a `demcal scale`") &&
                   Catch::Matchers::Contains("the same `demcal scale` command is run again"));
    fs::remove_all(dir);
}

}  // namespace

TEST_CASE("a reduced scale study on real YADE runs writes every per-radius number and resumes computing nothing",
          "[yade]") {
    check_reduced_study("yade");
}

TEST_CASE("a reduced scale study on the kernel engine writes every per-radius number and resumes computing nothing") {
    check_reduced_study("kernel");
}
