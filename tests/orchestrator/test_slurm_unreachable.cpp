// A SLURM controller that does not answer: sbatch refuses every batch. The campaign stops for a resume (exit 75),
// its runs as they were (pending), no batch file left behind, and a resume on the local pool finishes it. The sbatch
// here is SLURM's real client, pointed by SLURM_CONF at a controller port nothing listens on.
#include "campaign_test_support.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>

using namespace demcal;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

TEST_CASE("an unreachable SLURM controller stops a campaign for a resume, its runs pending", "[cli][store]") {
    if (std::system("command -v sbatch > /dev/null 2>&1") != 0) {
        WARN("sbatch is not installed here (scripts/setup.sh installs it), skipped");
        return;
    }
    const fs::path dir = test::fresh_test_dir("slurm-unreachable");
    const fs::path campaign = dir / "campaign";
    std::ofstream(dir / "slurm.conf") << "ClusterName=nowhere\nSlurmctldHost=localhost\nSlurmctldPort=9\n"
                                         "MessageTimeout=2\n";
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    ::setenv("SLURM_CONF", (dir / "slurm.conf").c_str(), 1);
    const int rc = test::run_demcal({"shear", tiny, "-s", "5e3,1e4,2e4", "--engine", "kernel", "--executor", "slurm",
                                     "--campaign", campaign.string()},
                                    dir / "out.log");
    ::unsetenv("SLURM_CONF");
    const std::string log = test::read_file(dir / "out.log");
    INFO(log);
    CHECK(rc == 75);
    CHECK_THAT(log, Contains("SLURM did not take the runs (sbatch exit 1") &&
                        Contains("resume once sbatch works, or run them with --executor local"));
    CHECK(log.find("\\n") == std::string::npos);  // sbatch's final newline was shown as a literal "\n"
    const auto runs = test::stored_runs(campaign);
    CHECK(runs.size() == 3);
    for (const auto& r : runs) {
        CHECK(r.state == orchestrator::RunState::pending);
        CHECK(r.attempts == 0);
    }
    for (const auto& f : fs::directory_iterator(campaign / "slurm")) {  // what sbatch never took is not left about
        INFO(f.path());
        CHECK((f.path().extension() != ".sbatch" && f.path().extension() != ".tasks"));
    }
    CHECK(test::run_demcal({"resume", campaign.string(), "--executor", "local"}, dir / "resume.log") == 0);
    INFO(test::read_file(dir / "resume.log"));
    for (const auto& r : test::stored_runs(campaign)) CHECK(r.state == orchestrator::RunState::done);
    fs::remove_all(dir);
}

TEST_CASE("the SLURM executor asked for without sbatch on PATH is refused before a campaign is written", "[cli]") {
    // probe 60: the refusal came after the store, the run folders and a 6.5 MB program copy had been written
    const fs::path dir = test::fresh_test_dir("slurm-absent");
    fs::create_directories(dir / "empty-path");
    const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
    ::setenv("PATH", (dir / "empty-path").c_str(), 1);
    const int rc = test::run_demcal({"shear", test::source_path("examples/materials/sand-tiny.json").string(), "-s",
                                     "5e3,1e4,2e4", "--engine", "kernel", "--executor", "slurm", "--campaign",
                                     (dir / "campaign").string()},
                                    dir / "out.log");
    ::setenv("PATH", path.c_str(), 1);
    INFO(test::read_file(dir / "out.log"));
    CHECK(rc == 2);
    CHECK_THAT(test::read_file(dir / "out.log"), Contains("--executor slurm: sbatch is not on PATH"));
    CHECK_FALSE(fs::exists(dir / "campaign"));
    fs::remove_all(dir);
}
