// The SLURM executor against a real single-node SLURM that this test starts (scripts/slurm/slurm_up.sh) and stops.
#include "slurm_for_test.hpp"
#include "campaign_test_support.hpp"
#include "orchestrator/slurm_executor.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <unistd.h>

using namespace demcal;
namespace fs = std::filesystem;

TEST_CASE("a tiny shear campaign runs as a SLURM job array", "[yade][slurm]") {
    if (::geteuid() != 0) {
        WARN("not root: cannot start SLURM daemons here, skipped");
        return;
    }
    // a cluster that takes arrays of 2 tasks at most: the 3 runs must go as two arrays (sbatch refuses a larger one)
    ::setenv("SLURM_MAX_ARRAY_SIZE", "2", 1);
    test::SlurmForTest cluster;
    ::unsetenv("SLURM_MAX_ARRAY_SIZE");
    REQUIRE(cluster.up());
    const fs::path dir = test::fresh_test_dir("slurm-campaign");
    REQUIRE(std::system(("scontrol show config > '" + (dir / "config.txt").string() + "'").c_str()) == 0);
    const long max_array_size = orchestrator::parse_max_array_size(test::read_file(dir / "config.txt"));
    const int code = test::run_demcal({"shear", test::source_path("examples/materials/sand-tiny.json").string(),
                                       "--normal-stress", "2e3,4e3,6e3", "--executor", "slurm", "--jobs", "2",
                                       "--timeout", "600", "--campaign", dir.string()},
                                      dir / "run.log");
    const std::string log = test::read_file(dir / "run.log");
    cluster.stop();
    INFO(log);
    REQUIRE(code == 0);
    orchestrator::CampaignStore store(dir / "campaign.sqlite");
    const auto runs = test::stored_runs(dir);
    REQUIRE(runs.size() == 3);
    for (const auto& r : runs) {
        CHECK(r.state == orchestrator::RunState::done);
        CHECK(std::isfinite(r.result.at("peak_shear_stress").get<double>()));
        CHECK(r.cpu_s > 0);
        const auto attempts = store.attempts(r.hash);
        REQUIRE(attempts.size() == 1);
        CHECK(attempts[0].executor == "slurm");
    }
    CHECK(log.find("Peak failure line") != std::string::npos);
    int arrays = 0;
    for (const auto& f : fs::directory_iterator(dir / "slurm")) arrays += f.path().extension() == ".sbatch";
    CHECK(arrays == (3 + max_array_size - 1) / max_array_size);
    fs::remove_all(dir);
}
