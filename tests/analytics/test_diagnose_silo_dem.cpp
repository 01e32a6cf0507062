// demcal diagnose --model silo-dem: the measured-rate reader's refusals, the DEM candidate table, outputs checked
// before any run, and end to end on a tiny silo: "measured" rates made by the kernel itself with the wall friction
// raised get wall_friction named with an interval holding the truth; rates made with the declared material get nothing.
// Real kernel runs through the demcal binary (300 grains, short windows).
#include "analytics/dem_diagnosis.hpp"
#include "demcal_cli.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
namespace an = demcal::analytics;

namespace {

using demcal::test::read_file;

an::SiloMeasurements parse(const std::string& csv) {
    std::istringstream in(csv);
    return an::silo_measurements_from(an::parse_csv(in, "m.csv"));
}

std::string refusal(const std::string& csv) {
    try {
        parse(csv);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "(accepted)";
}

int demcal_run(const std::string& args, const fs::path& log) { return demcal::test::run_demcal_command(args, log); }

// The tiny silo of the CI: 300 grains in the reduced 70 mm silo, 1000 times softer contacts, 0.2 s of discharge.
const std::string kTinySilo = "--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                              "/examples/silo/reduced_conical_70deg.json' --particles 300 --stiffness-scale 0.001 "
                              "--fill-time 0.3 --max-time 0.2 --threads 1 --no-plots";
const std::string kDeclared = std::string(DEMCAL_SOURCE_DIR) + "/examples/materials/silo_wheat_table21.json";

}  // namespace

TEST_CASE("silo-dem data: unknown and ill-formed columns and cells are refused naming the line and column",
          "[diagnose][silo-dem]") {
    const auto ok = parse("theta_deg,rate_g_s,replicate\n# a comment\n30,160,1\n30,163,2\n50,120.5,1\n");
    CHECK(ok.rows() == 3);
    CHECK(ok.conditions.size() == 2);
    CHECK(ok.lines == std::vector<int>{3, 4, 5});
    CHECK(ok.condition_of_row == std::vector<std::size_t>{0, 0, 1});
    const auto geometry = parse("theta_deg,outlet_m,rate_g_s\n30,0.03,160\n30,0.035,200\n");
    CHECK(geometry.conditions.size() == 2);
    CHECK(geometry.conditions[1].label() == "theta30_outlet0.035");
    // close but apart by more than the 0.01 % resolution: two conditions
    CHECK(parse("theta_deg,rate_g_s\n30,160\n30.01,161\n").conditions.size() == 2);

    struct Case {
        std::string csv, message;
    };
    const std::vector<Case> cases{
        {"theta_deg,rate_g_s,moisture\n30,160,2\n", "line 1, column moisture: unknown column"},
        {"theta_deg,W_kg_s\n30,0.16\n", "line 1, column W_kg_s: unknown column"},
        {"rate_g_s\n160\n", "column theta_deg is missing"},
        {"theta_deg,rate_g_s\n30,fast\n", "line 2, column rate_g_s: value 'fast' is not a number"},
        {"theta_deg,rate_g_s\n30,160\n95,100\n", "line 3, column theta_deg: value '95' must be in (0, 90)"},
        {"theta_deg,rate_g_s\n30,-3\n", "line 2, column rate_g_s: value '-3' must be > 0 g/s"},
        {"theta_deg,rate_g_s\n30,1e999\n", "line 2, column rate_g_s"},
        {"theta_deg,rate_g_s\n30,nan\n", "line 2, column rate_g_s"},
        {"theta_deg,outlet_m,rate_g_s\n30,0,160\n", "line 2, column outlet_m: value '0' must be > 0 m"},
        {"theta_deg,rate_g_s\n30,160,5\n", "line 2"},
        {"theta_deg,rate_g_s\n", "no data rows"},
        // one silo written two ways (a spreadsheet's rounding) was taken as two conditions, each with its own runs
        {"theta_deg,rate_g_s\n30,160\n50,120\n30.0000001,161\n",
         "line 4, column theta_deg: the condition theta30.0000001 differs from theta30 (line 2) by less than 0.01 %"},
        {"theta_deg,outlet_m,rate_g_s\n30,0.035,160\n30,0.03500001,161\n", "differs from theta30_outlet0.035"}};
    for (const auto& c : cases) {
        INFO(c.csv);
        CHECK_THAT(refusal(c.csv), Catch::Matchers::Contains(c.message));
    }
}

TEST_CASE("silo-dem candidates: the table is sane, its defects are caught, and its grid spans its bounds",
          "[diagnose][silo-dem]") {
    const auto& table = an::dem_effect_candidates();
    CHECK(an::candidate_table_defects(table).empty());
    std::vector<std::string> names;
    for (const auto& c : table) names.push_back(c.name);
    CHECK(names == std::vector<std::string>{"rolling_friction", "wall_friction", "restitution", "cohesion",
                                            "grain_elongation"});
    // the declared wheat lies inside every candidate's bounds (a field it lacks: at the row's absent value, which may
    // be a bound, as no cohesion is), so each candidate is nested in the declared model
    const auto material = nlohmann::json::parse(read_file(kDeclared));
    for (const auto& c : table)
        for (const auto& f : c.fields) {
            const auto dot = f.find('.');
            const auto& object = material.at(f.substr(0, dot));
            INFO(c.name << " " << f);
            if (!object.contains(f.substr(dot + 1))) {
                REQUIRE(c.absent.has_value());
                CHECK(*c.absent >= c.lower);
                CHECK(*c.absent <= c.upper);
                continue;
            }
            const double v = object.at(f.substr(dot + 1)).get<double>();
            CHECK(v > c.lower);
            CHECK(v < c.upper);
        }
    CHECK_FALSE(material.at("grain_grain").contains("surface_energy_J_m2"));  // (so the branch above is taken)
    // a later row and broken rows
    auto extended = table;
    extended.push_back({"elongation", {"grain.elongation"}, 1, 3, an::ParameterScale::linear, "shape", std::nullopt});
    CHECK(an::candidate_table_defects(extended).empty());
    auto broken = table;
    broken.push_back({"wall_friction", {"grain_wall.friction"}, 0.5, 0.1, an::ParameterScale::log, "", std::nullopt});
    broken.push_back({"shape", {"elongation"}, 0, 1, an::ParameterScale::log, "", std::nullopt});
    broken.push_back({"moisture", {"grain_wall.surface_energy_J_m2"}, 0.1, 1, an::ParameterScale::linear, "", 0.0});
    // (the first broken row is also a log scale, but from 0.5 > 0: no defect of its own there)
    const auto defects = an::candidate_table_defects(broken);
    // name used twice, field in two rows, lower > upper; a field without an object, a log scale from 0; an absent
    // value outside the bounds
    CHECK(defects.size() == 6);
    const auto grid = an::candidate_grid(table[0], 5);  // log: 1e-3 .. 0.3 evenly in decades
    REQUIRE(grid.size() == 5);
    CHECK(grid.front() == Approx(1e-3));
    CHECK(grid.back() == Approx(0.3));
    CHECK(grid[2] == Approx(std::sqrt(1e-3 * 0.3)).epsilon(1e-3));
    CHECK(an::run_value(0.123456) == 0.1235);
}

TEST_CASE("diagnose silo-dem: bad input and unwritable outputs exit 2 before any run, naming them",
          "[diagnose][silo-dem]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-silo-dem-bad-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "folder");  // (tests run as root: a folder's permissions would not stop a write)
    std::ofstream(dir / "m.csv") << "theta_deg,rate_g_s\n30,160\n30,162\n50,120\n70,100\n";
    std::ofstream(dir / "few.csv") << "theta_deg,rate_g_s\n30,160\n30,162\n50,120\n";
    std::ofstream(dir / "same.csv") << "theta_deg,rate_g_s\n30,160\n30,160\n50,120\n70,100\n";
    const std::string data = " --data '" + (dir / "m.csv").string() + "'";
    const std::string campaign = " --campaign '" + (dir / "never").string() + "'";
    const std::string material = " --material '" + kDeclared + "'";
    struct Case {
        std::string args, message;
    };
    const std::vector<Case> cases{
        {"--model silo-dem" + data + campaign + material + " --json '" + (dir / "folder").string() + "' -- " +
             kTinySilo,
         "--json = '" + (dir / "folder").string() + "' is a folder"},
        {"--model silo-dem" + data + campaign + material + " --report '" + (dir / "m.csv/sub/r.md").string() +
             "' -- " + kTinySilo,
         "--report = '" + (dir / "m.csv/sub/r.md").string() + "': " + (dir / "m.csv").string() + " is a file, so the folder cannot be created"},
        {"--model silo-dem" + data + campaign + " -- " + kTinySilo, "--material"},
        {"--model silo-dem" + data + campaign + material + " -- " + kTinySilo + " --theta 30", "--theta"},
        {"--model silo-dem" + data + campaign + material + " -- " + kTinySilo + " --stop-fraction 7", "--stop-fraction = 7"},
        {"--model silo-dem --data '" + (dir / "few.csv").string() + "'" + campaign + material + " -- " + kTinySilo,
         "at least 3 conditions"},
        // repeats without scatter: found after the kernel had run, a campaign written (probe 59b)
        {"--model silo-dem --data '" + (dir / "same.csv").string() + "'" + campaign + material + " -- " + kTinySilo,
         "no repeats (rows of one condition with different rates)"},
        // the flow mode's angles on a shear test did nothing (probe 59b)
        {"--model failure-line --data '" + std::string(DEMCAL_SOURCE_DIR) +
             "/examples/diagnose/shear_curved.csv' --effective-friction-deg 40",
         "--effective-friction-deg: the silo models' flow mode takes it"},
        {"--model BEVERLOO" + data, "expected one of beverloo, johanson, oldal, oldal-rect, failure-line, silo-dem"},
        {"--model silo-dem" + data + campaign + " --material '" + (dir / "m.csv").string() + "' -- " + kTinySilo,
         "--material"},
        {"--model silo-dem" + data + campaign + material + " --candidates wall_friction,moisture -- " + kTinySilo,
         "--candidates: no DEM effect 'moisture' (known: rolling_friction, wall_friction, restitution, cohesion, "
         "grain_elongation)"},
        {"--model silo-dem" + data + campaign + material + " --candidates cohesion,cohesion -- " + kTinySilo,
         "--candidates: 'cohesion' named twice"},
        // 3 conditions x 20 seeds x (1 + 5 candidates x (30 + 20)) = 15060 runs
        {"--model silo-dem" + data + campaign + material + " --seeds 20 --grid-points 30 --refine-steps 20 -- " +
             kTinySilo,
         "diagnose silo-dem: 3 conditions x 20 seeds x (1 declared + 5 candidates x (30 grid points + 20 refine "
         "steps)) materials = 15060 simulations, more than the limit --max-runs = 10000"},
        {"--model oldal" + data + material, "--material: only --model silo-dem"},
        {"--model oldal" + data + " --max-runs 5", "--max-runs: only --model silo-dem"},
        {"--model silo-dem" + data + campaign + material + " --drop-outliers -- " + kTinySilo,
         "--drop-outliers: the analytical models take it"},
        {"--model oldal --data '" + std::string(DEMCAL_SOURCE_DIR) + "/examples/diagnose/oldal_clean.csv' --json '" +
             (dir / "folder").string() + "'",
         "--json = '" + (dir / "folder").string() + "' is a folder"}};
    for (const auto& c : cases) {
        INFO(c.args);
        CHECK(demcal_run("diagnose " + c.args, dir / "log") == 2);
        INFO(read_file(dir / "log"));
        CHECK_THAT(read_file(dir / "log"), Catch::Matchers::Contains(c.message));
        CHECK_FALSE(fs::exists(dir / "never"));
    }
    fs::remove_all(dir);
}

TEST_CASE("diagnose silo-dem: a raised wall friction or its mimic cohesion is named, the wall friction's fit holds its "
          "value in its interval - the declared material's own rates get nothing - the same command again runs "
          "nothing - more seeds reuse the campaign's runs",
          "[diagnose][silo-dem][slow]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-silo-dem-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    // the "measured" sets: the kernel with the wall friction raised from 0.25 to 0.6, and with the declared material,
    // seeds the predictions do not use
    constexpr double kTrueWallFriction = 0.6;
    auto material = nlohmann::json::parse(read_file(kDeclared));
    material["grain_wall"]["friction"] = kTrueWallFriction;
    std::ofstream(dir / "rough_wall.json") << material.dump(1);
    const int angles[] = {20, 30, 40, 50, 60};
    std::ofstream rough(dir / "rough.csv"), clean(dir / "clean.csv");
    rough << "theta_deg,rate_g_s,replicate\n";
    clean << "theta_deg,rate_g_s,replicate\n";
    for (int theta : angles)
        for (int seed : {101, 102, 103}) {
            for (const auto& [file, name, out] :
                 {std::tuple{(dir / "rough_wall.json").string(), std::string("rough"), &rough},
                  std::tuple{kDeclared, std::string("clean"), &clean}}) {
                const fs::path run = dir / "data" / (name + std::to_string(theta) + "_" + std::to_string(seed));
                REQUIRE(demcal_run("silo --theta " + std::to_string(theta) + " --seed " + std::to_string(seed) +
                                       " --material '" + file + "' --out '" + run.string() + "' " + kTinySilo,
                                   dir / "silo.log") == 0);
                const auto s = nlohmann::json::parse(read_file(run / "summary.json"));
                *out << theta << "," << s["rate"]["rate_kg_s"].get<double>() * 1e3 << "," << seed - 100 << "\n";
            }
        }
    rough.close();
    clean.close();
    // Every candidate, cohesion too. On this tiny set (300 grains, 5 angles, one seed) a small cohesion explains the
    // raised wall friction's rates about as well (measured 2026-12-02: cohesion 0.080 J/m^2, CV RMSE 8.79 %; wall
    // friction 0.63, 8.86 %; examples/diagnose/README.md; after the kernel's exact removal of 2026-12-04: cohesion
    // 0.083, 5.94 %; wall friction 0.629 [0.575, 0.684], 7.02 %, no longer within the rival rule), so the set cannot
    // tell the two apart: the named effect must be one of them, the wall friction's fit must hold the true value in its
    // interval and at least halve the CV RMSE, and cohesion's 0.3 J/m^2 arches the bed there.
    const std::string common = " --material '" + kDeclared + "' --campaign '" + (dir / "campaign").string() +
                               "' --jobs 2 --grid-points 4 --refine-steps 2 -- " + kTinySilo;

    const auto start = std::chrono::steady_clock::now();
    REQUIRE(demcal_run("diagnose --model silo-dem --data '" + (dir / "rough.csv").string() + "' --json '" +
                           (dir / "rough.json").string() + "' --report '" + (dir / "report/rough.md").string() + "'" +
                           common,
                       dir / "rough.log") == 0);
    INFO(read_file(dir / "rough.log"));
    const auto r = nlohmann::json::parse(read_file(dir / "rough.json"));
    REQUIRE(r["effect"].is_object());
    const std::string named = r["effect"]["name"];
    bool wall_rival = false;
    for (const auto& rival : r["effect"]["rivals"]) wall_rival = wall_rival || rival == "wall_friction";
    INFO("wall friction a rival of the named effect: " << wall_rival);
    CHECK((named == "wall_friction" || named == "cohesion"));
    nlohmann::json wall;
    for (const auto& c : r["candidates"])
        if (c["name"] == "wall_friction") wall = c;
    REQUIRE(wall.is_object());
    CHECK(wall["cv_rmse"].get<double>() < 0.5 * wall["cv_rmse_declared"].get<double>());
    CHECK(wall["interval"][0].get<double>() <= kTrueWallFriction);
    CHECK(wall["interval"][1].get<double>() >= kTrueWallFriction);
    nlohmann::json cohesion;
    for (const auto& c : r["candidates"])
        if (c["name"] == "cohesion") cohesion = c;
    REQUIRE(cohesion.is_object());
    CHECK(cohesion["declared"] == 0.0);  // (the wheat file has no surface energy: absent means none)
    CHECK(r["after"]["cv_rmse"].get<double>() < 0.95 * r["before"]["rmse"].get<double>());
    CHECK(fs::exists(dir / "report/rough_residuals_after.png"));
    CHECK_THAT(read_file(dir / "report/rough.md"), Catch::Matchers::Contains("**" + named + "**"));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    WARN("rough-wall diagnosis: " << seconds << " s wall, " << r["runs"]["run_now"] << " kernel runs");

    REQUIRE(demcal_run("diagnose --model silo-dem --data '" + (dir / "clean.csv").string() + "' --json '" +
                           (dir / "clean.json").string() + "'" + common,
                       dir / "clean.log") == 0);
    INFO(read_file(dir / "clean.log"));
    const auto c = nlohmann::json::parse(read_file(dir / "clean.json"));
    CHECK(c["effect"].is_null());
    CHECK(c["after"]["rmse"] == c["before"]["rmse"]);

    // the same command again: every run comes from the campaign
    REQUIRE(demcal_run("diagnose --model silo-dem --data '" + (dir / "rough.csv").string() + "'" + common,
                       dir / "again.log") == 0);
    CHECK_THAT(read_file(dir / "again.log"), Catch::Matchers::Contains("0 run now"));
    CHECK_THAT(read_file(dir / "again.log"), Catch::Matchers::Contains("DEM effect: " + named));

    // twice the prediction seeds (what a rival's separation design asks for) in the same campaign: the seed-1 runs are
    // reused, only the new seed's are made
    REQUIRE(demcal_run("diagnose --model silo-dem --seeds 2 --candidates wall_friction --data '" +
                           (dir / "rough.csv").string() + "' --json '" + (dir / "seeds2.json").string() + "'" + common,
                       dir / "seeds2.log") == 0);
    INFO(read_file(dir / "seeds2.log"));
    const auto s2 = nlohmann::json::parse(read_file(dir / "seeds2.json"));
    CHECK(s2["prediction_seeds"] == 2);
    CHECK(s2["runs"]["run_now"].get<int>() > 0);
    CHECK(s2["runs"]["run_now"].get<int>() < s2["runs"]["used"].get<int>());
    // other silo settings in the same campaign are still refused, before any run
    CHECK(demcal_run("diagnose --model silo-dem --data '" + (dir / "rough.csv").string() + "'" + common +
                         " --dt-fraction 0.2",
                     dir / "other.log") == 2);
    CHECK_THAT(read_file(dir / "other.log"), Catch::Matchers::Contains("other settings"));
    fs::remove_all(dir);
}
