// demcal vibration: a sweep of demcal silo runs (angles x frequencies x repeats) into a campaign directory; the same
// command continues it without running anything twice; other settings and bad input are refused before anything is
// written.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "orchestrator/run_identity.hpp"
#include "slurm_for_test.hpp"
#include "demcal_cli.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

int demcal_run(const std::string& args, const fs::path& log) { return demcal::test::run_demcal_command(args, log); }

const std::string kTiny = "--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                          "/examples/silo/reduced_conical_70deg.json' --particles 300 --stiffness-scale 0.001 "
                          "--fill-time 0.3 --max-time 0.2 --threads 1 --no-plots";

}  // namespace

TEST_CASE("demcal vibration: a tiny sweep, continued by the same command without running anything twice",
          "[silo][vibration][cli]") {
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-vibration-sweep-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path campaign = dir / "sweep";
  const std::string sweep = "vibration --theta 45 --frequency 0,100 --amplitude 1.1e-4 --repeats 2 --campaign '" +
                            campaign.string() + "' -- " + kTiny;
  REQUIRE(demcal_run(sweep, dir / "first.log") == 0);
  const auto report = nlohmann::json::parse(demcal::test::read_file(campaign / "vibration.json"));
  REQUIRE(report["cells"].size() == 2);
  CHECK(report["complete"] == true);  // (a stopped sweep's report says stopped, with the runs finished)
  CHECK(report["runs_finished"] == 4);
  for (const auto& cell : report["cells"]) {
    CHECK(cell["n"] == 2);
    CHECK(cell["rate_mean_g_s"].get<double>() > 0);
  }
  CHECK(report["cells"][1]["peak_acceleration_g"].get<double>() == Approx(1.1e-4 * std::pow(2 * M_PI * 100, 2) / 9.81));
  // the still and the vibrating runs differ; the two seeds of one cell differ
  CHECK(report["runs"][0]["rate_g_s"] != report["runs"][1]["rate_g_s"]);
  CHECK(report["runs"][0]["rate_g_s"] != report["runs"][2]["rate_g_s"]);
  const auto stamp = fs::last_write_time(campaign / "runs" / "theta45_f100_seed2" / "summary.json");
  REQUIRE(demcal_run(sweep, dir / "again.log") == 0);
  CHECK(fs::last_write_time(campaign / "runs" / "theta45_f100_seed2" / "summary.json") == stamp);
  CHECK_THAT(demcal::test::read_file(dir / "again.log"), !Catch::Matchers::Contains("[1/"));
  // the same directory with other settings (another amplitude) is refused, and left as it was
  CHECK(demcal_run("vibration --theta 45 --frequency 0,50 --amplitude 1.2e-4 --repeats 2 --campaign '" +
                       campaign.string() + "' -- " + kTiny,
                   dir / "other.log") == 2);
  CHECK_THAT(demcal::test::read_file(dir / "other.log"), Catch::Matchers::Contains("other settings"));
  CHECK_FALSE(fs::exists(campaign / "runs" / "theta45_f50_seed1"));
  // a grown grid is the same campaign: a third seed runs its two runs only, the first two seeds' are reused
  const std::string grown = "vibration --theta 45 --frequency 0,100 --amplitude 1.1e-4 --repeats 3 --campaign '" +
                            campaign.string() + "' -- " + kTiny;
  REQUIRE(demcal_run(grown, dir / "grown.log") == 0);
  CHECK(fs::last_write_time(campaign / "runs" / "theta45_f100_seed2" / "summary.json") == stamp);
  CHECK(fs::exists(campaign / "runs" / "theta45_f100_seed3" / "summary.json"));
  // (the progress counts the planned runs: only the 5th and 6th of 6 are started)
  CHECK_THAT(demcal::test::read_file(dir / "grown.log"), Catch::Matchers::Contains("[5/6] theta45_f0_seed3") &&
                                                             Catch::Matchers::Contains("[6/6] theta45_f100_seed3") &&
                                                             !Catch::Matchers::Contains("[4/6]"));
  const auto grown_report = nlohmann::json::parse(demcal::test::read_file(campaign / "vibration.json"));
  CHECK(grown_report["cells"][1]["rate_change_paired"]["pairs"] == 3);
  // the cells carry the outlet's density and speed
  CHECK(report["cells"][0]["outlet_solid_density_mean_kg_m3"].get<double>() > 0);
  CHECK(report["cells"][0]["outlet_downward_speed_mean_m_s"].get<double>() > 0);
  // the vibrating cell's change against the still runs of the same seeds, pair by pair
  double still[2] = {0, 0}, shaken[2] = {0, 0};
  for (const auto& run : report["runs"])
    (run["frequency_hz"] == 0 ? still : shaken)[run["seed"].get<int>() - 1] = run["rate_g_s"].get<double>();
  const double change1 = 100 * (shaken[0] / still[0] - 1), change2 = 100 * (shaken[1] / still[1] - 1);
  const auto& paired = report["cells"][1]["rate_change_paired"];
  CHECK(paired["pairs"] == 2);
  CHECK(paired["mean_pct"].get<double>() == Approx((change1 + change2) / 2));
  CHECK(paired["se_pct"].get<double>() == Approx(std::abs(change1 - change2) / 2));
  CHECK(report["cells"][0]["rate_change_paired"]["pairs"] == 0);  // the still cell is the reference
  CHECK(report["cells"][1]["outlet_speed_change_paired"]["pairs"] == 2);
  // a run's summary damaged by hand stops the report naming the file, and the report is left as it was: an edit
  // breaks the summary's seal; an edit sealed again (a writer's bug, not a flipped byte) is caught by the field check
  const fs::path summary = campaign / "runs" / "theta45_f100_seed2" / "summary.json";
  const std::string sealed = demcal::test::read_file(summary);
  auto damaged = nlohmann::json::parse(demcal::orchestrator::unsealed_result_text(sealed));
  damaged["outlet_flow"]["solid_density_kg_m3"] = "dense";
  const std::string before = demcal::test::read_file(campaign / "vibration.json");
  std::string flipped = sealed;
  flipped[flipped.find("\"grains\": ") + 10] ^= 1;  // one bit of the grain count
  for (const auto& [text, expect] :
       {std::pair{flipped, std::string("does not match its SHA-256")},
        std::pair{damaged.dump(), std::string("schema demcal.silo_summary/1 without its SHA-256 seal")},
        std::pair{demcal::orchestrator::sealed_result_text(damaged.dump()),
                  std::string("outlet_flow/solid_density_kg_m3 = \"dense\": not a number")}}) {
    INFO(expect);
    std::ofstream(summary) << text;
    CHECK(demcal_run(sweep, dir / "damaged.log") == 2);
    CHECK_THAT(demcal::test::read_file(dir / "damaged.log"),
               Catch::Matchers::Contains(summary.string()) && Catch::Matchers::Contains(expect));
    CHECK(demcal::test::read_file(campaign / "vibration.json") == before);
  }
  // a whole, sealed summary of another cell (the still run of the same seed) in this cell's folder
  fs::copy_file(campaign / "runs" / "theta45_f0_seed2" / "summary.json", summary,
                fs::copy_options::overwrite_existing);
  CHECK(demcal_run(sweep, dir / "foreign.log") == 2);
  CHECK_THAT(demcal::test::read_file(dir / "foreign.log"),
             Catch::Matchers::Contains("vibration/frequency_hz = 0") &&
                 Catch::Matchers::Contains("not this cell's run"));
  // a whole run folder of another campaign (another amplitude) copied into this one, summary and all (probe 59b):
  // refused by its run.json, before anything is read or written
  const fs::path other = dir / "other-amplitude";
  REQUIRE(demcal_run("vibration --theta 45 --frequency 100 --amplitude 2.2e-4 --repeats 1 --campaign '" +
                         other.string() + "' -- " + kTiny,
                     dir / "other-amplitude.log") == 0);
  fs::remove_all(campaign / "runs" / "theta45_f100_seed1");
  fs::copy(other / "runs" / "theta45_f100_seed1", campaign / "runs" / "theta45_f100_seed1", fs::copy_options::recursive);
  const std::string report_before = demcal::test::read_file(campaign / "vibration.json");
  CHECK(demcal_run(grown, dir / "copied.log") == 2);
  CHECK_THAT(demcal::test::read_file(dir / "copied.log"),
             Catch::Matchers::Contains("theta45_f100_seed1 holds a run of other settings") &&
                 Catch::Matchers::Contains("0.00022") && Catch::Matchers::Contains("remove it"));
  CHECK(demcal::test::read_file(campaign / "vibration.json") == report_before);
  // a suspended run's folder without run.json (a direct `silo --out` run copied in): its checkpoint cannot be told
  // from this campaign's run, and was resumed as it (held-back suite: a 1000-grain run in a 300-grain sweep)
  fs::remove_all(campaign / "runs" / "theta45_f100_seed1");
  fs::create_directories(campaign / "runs" / "theta45_f100_seed1");
  std::ofstream(campaign / "runs" / "theta45_f100_seed1" / "checkpoint.bin") << "a checkpoint of some other run";
  CHECK(demcal_run(grown, dir / "checkpoint.log") == 2);
  CHECK_THAT(demcal::test::read_file(dir / "checkpoint.log"),
             Catch::Matchers::Contains("holds a checkpoint but no run.json"));
  CHECK(demcal::test::read_file(campaign / "vibration.json") == report_before);
  fs::remove_all(dir);
}

TEST_CASE("demcal vibration: bad input exits 2 naming it before anything is written", "[silo][vibration][cli]") {
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-vibration-bad-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string campaign = " --campaign '" + (dir / "never").string() + "'";
  const std::pair<std::string, std::string> cases[] = {
      {"--theta 45 --frequency 100" + campaign + " -- " + kTiny, "--amplitude"},
      {"--theta 45 --frequency 0,100 --amplitude 1e-4" + campaign + " -- " + kTiny + " --seed 3", "--seed"},
      {"--theta 45 --frequency 0,100 --amplitude 1e-4" + campaign + " -- " + kTiny + " --stop-fraction 7",
       "--stop-fraction = 7"},
      {"--theta 95 --frequency 0" + campaign + " -- " + kTiny, "--theta"},
      {"--theta 45 --frequency 0,-5 --amplitude 1e-4" + campaign, "--frequency"},
      {"--theta 45 --frequency 100 --amplitude 1e-4 --direction y" + campaign, "--direction"},
      {"--theta 45 --frequency 100 --amplitude 1e-4 --part body" + campaign, "--part = 'body'"},
      {"--theta 45 --frequency 100 --amplitude 1e-4 --repeats 0" + campaign, "--repeats"},
      // one run's output for every run: each overwrote the last's bed; the second run's snapshots were refused
      {"--theta 45 --frequency 0,100 --amplitude 1e-4" + campaign + " -- " + kTiny + " --export-bed bed.json",
       "--export-bed after --: demcal vibration would give every run the same output path"},
      {"--theta 45 --frequency 0,100 --amplitude 1e-4" + campaign + " -- " + kTiny + " --vtk=snapshots",
       "--vtk=snapshots after --"}};
  for (const auto& [args, expect] : cases) {
    INFO(args);
    CHECK(demcal_run("vibration " + args, dir / "log") == 2);
    CHECK_THAT(demcal::test::read_file(dir / "log"), Catch::Matchers::Contains(expect));
    CHECK_FALSE(fs::exists(dir / "never"));
  }
  fs::remove_all(dir);
}

TEST_CASE("demcal vibration --executor slurm: the sweep's runs as SLURM array tasks give the local sweep's rates",
          "[silo][vibration][slurm]") {
  if (::geteuid() != 0) {
    WARN("not root: cannot start SLURM daemons here, skipped");
    return;
  }
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-vibration-slurm-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string sweep = "vibration --theta 45 --frequency 0,100 --amplitude 1.1e-4 --repeats 1 ";
  REQUIRE(demcal_run(sweep + "--campaign '" + (dir / "local").string() + "' -- " + kTiny, dir / "local.log") == 0);
  demcal::test::SlurmForTest cluster;
  REQUIRE(cluster.up());
  const int rc = demcal_run(sweep + "--executor slurm --jobs 2 --campaign '" + (dir / "slurm").string() + "' -- " + kTiny,
                            dir / "slurm.log");
  cluster.stop();
  INFO(demcal::test::read_file(dir / "slurm.log"));
  REQUIRE(rc == 0);
  CHECK_THAT(demcal::test::read_file(dir / "slurm.log"), Catch::Matchers::Contains("SLURM task"));
  const auto local = nlohmann::json::parse(demcal::test::read_file(dir / "local" / "vibration.json"));
  const auto slurm = nlohmann::json::parse(demcal::test::read_file(dir / "slurm" / "vibration.json"));
  REQUIRE(slurm["runs"].size() == 2);
  CHECK(slurm["runs"] == local["runs"]);  // the same runs, bit for bit, wherever they ran
  // each task ran the program pinned in the campaign, its log in the run folder
  CHECK(fs::exists(dir / "slurm" / ".program" / "demcal"));
  CHECK(fs::exists(dir / "slurm" / "runs" / "theta45_f100_seed1" / "stdout.log"));
  fs::remove_all(dir);
}

TEST_CASE("demcal vibration: a sweep in which no run's rate is determined ends with exit 1, saying so",
          "[silo][vibration][cli]") {
  // every cell n = 0 and "rate mean -" ended with exit 0
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-vibration-none-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string sweep = "vibration --theta 30 --frequency 0 --repeats 1 --campaign '" + (dir / "v").string() +
                            "' -- --particles 50 --fill-time 0.02 --max-time 0.02 --no-plots --threads 1";
  CHECK(demcal_run(sweep, dir / "run.log") == 1);
  CHECK_THAT(demcal::test::read_file(dir / "run.log"), Catch::Matchers::Contains("no cell has a rate"));
  CHECK(fs::exists(dir / "v" / "vibration.json"));  // the table is still written
  // the same silo options in another spelling continue the campaign (probe 61: order, --opt=value, 2e-2 for 0.02
  // were "other settings", exit 2); another value is still refused, by its option
  const std::string respelled = "vibration --theta 30 --frequency 0 --repeats 1 --campaign '" + (dir / "v").string() +
                                "' -- --threads=1 --max-time 2e-2 --no-plots --fill-time 0.020 --particles 50";
  CHECK(demcal_run(respelled, dir / "again.log") == 1);
  CHECK_THAT(demcal::test::read_file(dir / "again.log"), Catch::Matchers::Contains("no cell has a rate"));
  CHECK(demcal_run(respelled + " --skin 0.0005", dir / "other.log") == 2);
  CHECK_THAT(demcal::test::read_file(dir / "other.log"), Catch::Matchers::Contains("--skin given now, not before"));
  fs::remove_all(dir);
}
