// The file-size limit on a real single-node SLURM (started by the test): a task whose output runs away is stopped by
// run.sh's `ulimit -f`, recorded as an output limit (not a crash to retry) and its log cut to the tail, as the local
// executor does (test_local_executor_limits.cpp tests the rules without a cluster).
#include "slurm_for_test.hpp"
#include "campaign_test_support.hpp"
#include "orchestrator/slurm_executor.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

using namespace demcal::orchestrator;
namespace fs = std::filesystem;

TEST_CASE("a SLURM task whose log runs away is stopped at its file-size limit", "[slurm]") {
    if (::geteuid() != 0) {
        WARN("not root: cannot start SLURM daemons here, skipped");
        return;
    }
    demcal::test::SlurmForTest cluster;
    REQUIRE(cluster.up());
    const fs::path d = demcal::test::fresh_test_dir("slurm-runaway");
    Job job{"runaway", d / "run", {"sh", "-c", "echo start; while :; do echo 'the same line again'; done"}, 300};
    job.max_file_bytes = 1 << 20;
    fs::create_directories(job.dir);  // a campaign writes the run's folder before it starts the run
    const auto executor = make_executor("slurm", 1, d / "slurm");
    bool given = false;
    std::optional<JobOutcome> outcome;
    executor->run(
        [&]() -> std::optional<Job> {
            if (given) return std::nullopt;
            given = true;
            return job;
        },
        {nullptr, [&](const Job&, const JobOutcome& o) { outcome = o; }});
    cluster.stop();
    REQUIRE(outcome.has_value());
    INFO(outcome->message);
    CHECK_FALSE(outcome->succeeded());
    CHECK_FALSE(outcome->timed_out);
    CHECK(outcome->failure_cause == kOutputLimitCause);
    CHECK_THAT(outcome->message, Catch::Contains("1048576 bytes") && Catch::Contains("stdout.log"));
    const auto size = fs::file_size(job.dir / "stdout.log");
    CHECK(size < 70 * 1024);  // the tail kept, 64 KiB and one line
    std::ifstream log(job.dir / "stdout.log");
    std::string first;
    std::getline(log, first);
    CHECK_THAT(first, Catch::Contains("passed the limit of 1048576 bytes"));
    fs::remove_all(d);
}
