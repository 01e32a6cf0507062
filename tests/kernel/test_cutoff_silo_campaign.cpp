// demcal cutoff in the silo: its runs are a campaign of demcal silo subprocesses (the seeds of a frequency side by
// side); the same command again runs nothing and reports the same; a folder of other settings, and the campaign's
// options with the small hopper, are refused before anything is written. A 300-grain bed in the 105 mm silo does not
// arch (it flows at 0 Hz), which keeps the search to its first frequency: seconds.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "demcal_cli.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;
using demcal::test::read_file;
using demcal::test::run_demcal_command;

TEST_CASE("demcal cutoff in the silo: runs kept in a campaign, the same command runs nothing again",
          "[silo][cutoff][cli]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-cutoff-campaign-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string silo = " -- --material '" + std::string(DEMCAL_SOURCE_DIR) +
                             "/examples/materials/silo_meal.json' --theta 30 --particles 300 --stiffness-scale 0.01 "
                             "--fill-time 0.3 --threads 1";
    const std::string search = "cutoff --amplitude 2.2e-4 --bracket 0,400 --tol 200 --seeds 1,2 --jobs 2 --campaign '" +
                               (dir / "c").string() + "' --json '";
    // no arch: "no cut-off found" (exit 1), both seeds run at 0 Hz and kept
    CHECK(run_demcal_command(search + (dir / "first.json").string() + "'" + silo, dir / "first.log") == 1);
    INFO(read_file(dir / "first.log"));
    CHECK_THAT(read_file(dir / "first.log"), Catch::Contains("no cut-off found: flows at the low end of the bracket"));
    CHECK_THAT(read_file(dir / "first.log"), Catch::Contains("[2/2] f0_seed2"));
    CHECK(fs::exists(dir / "c" / "runs" / "f0_seed1" / "summary.json"));
    CHECK(fs::exists(dir / "c" / "runs" / "f0_seed2" / "summary.json"));
    const auto first = nlohmann::json::parse(read_file(dir / "first.json"));
    REQUIRE(first["runs"].size() == 2);
    CHECK(first["runs"][0]["run"] == "f0_seed1");
    CHECK(first["runs"][0]["discharged_fraction"].get<double>() >= 0.5);
    CHECK(first["runs"][0]["end"] == "stop_fraction");  // read from the run's summary as a state
    CHECK(first["criterion"] == "flow-stops");
    CHECK(first["runs_at_window_end"] == 0);
    CHECK(first["seeds"].size() == 2);
    CHECK(first["campaign"] == (dir / "c").string());

    // the same search again: nothing runs, the same answers
    CHECK(run_demcal_command(search + (dir / "again.json").string() + "'" + silo, dir / "again.log") == 1);
    CHECK_THAT(read_file(dir / "again.log"), !Catch::Contains("[1/2]"));
    const auto again = nlohmann::json::parse(read_file(dir / "again.json"));
    CHECK(again["runs"] == first["runs"]);

    // another amplitude is another campaign: refused in this folder, nothing written
    CHECK(run_demcal_command("cutoff --amplitude 1e-4 --campaign '" + (dir / "c").string() + "'" + silo,
                             dir / "other.log") == 2);
    CHECK_THAT(read_file(dir / "other.log"), Catch::Contains("holds a cutoff campaign with other settings"));
    // the campaign's options belong to the silo search
    CHECK(run_demcal_command("cutoff --bond-number 10 --jobs 2", dir / "hopper.log") == 2);
    CHECK_THAT(read_file(dir / "hopper.log"), Catch::Contains("--jobs applies to the silo search"));
    fs::remove_all(dir);
}
