// The local executor's file-size limit: a job whose output runs away is stopped at its limit, recorded as such, and
// its log cut to its tail.
#include "campaign_test_support.hpp"
#include "orchestrator/executor.hpp"

#include <catch2/catch.hpp>

#include <csignal>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

using namespace demcal::orchestrator;
namespace fs = std::filesystem;

namespace {
JobOutcome run_one(const Job& job) {
    LocalExecutor executor(1);
    bool given = false;
    JobOutcome outcome;
    executor.run([&]() -> std::optional<Job> {
                     if (given) return std::nullopt;
                     given = true;
                     return job;
                 },
                 {nullptr, [&](const Job&, const JobOutcome& o) { outcome = o; }});
    return outcome;
}

std::string first_line(const fs::path& file) {
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    return line;
}
}  // namespace

TEST_CASE("a job whose log runs away is stopped at its file-size limit and its log cut to the tail", "[executor]") {
    const fs::path d = demcal::test::fresh_test_dir("executor-runaway");
    Job job{"runaway", d / "run", {"sh", "-c", "echo start; while :; do echo 'the same line again'; done"}, 60};
    job.max_file_bytes = 1 << 20;
    const JobOutcome o = run_one(job);
    CHECK_FALSE(o.succeeded());
    CHECK(o.term_signal == SIGXFSZ);
    CHECK(o.failure_cause == kOutputLimitCause);
    CHECK_THAT(o.message, Catch::Contains("1048576 bytes") && Catch::Contains("stdout.log"));
    const auto size = fs::file_size(job.dir / "stdout.log");
    CHECK(size < 70 * 1024);  // the tail kept, 64 KiB and one line
    CHECK_THAT(first_line(job.dir / "stdout.log"), Catch::Contains("passed the limit of 1048576 bytes"));
    CHECK_FALSE(fs::exists(job.dir / "stdout.log.cut"));
    fs::remove_all(d);
}

TEST_CASE("a job that writes large files below its limit is not touched by it", "[executor]") {
    const fs::path d = demcal::test::fresh_test_dir("executor-below-limit");
    Job job{"big", d / "run", {"sh", "-c", "head -c 2000000 /dev/zero > data.bin && echo written"}, 60};
    job.max_file_bytes = 4 << 20;
    const JobOutcome o = run_one(job);
    CHECK(o.succeeded());
    CHECK(o.failure_cause.empty());
    CHECK(fs::file_size(job.dir / "data.bin") == 2000000);
    fs::remove_all(d);
}

TEST_CASE("a shell's exit code 153 is an output limit only when a file reached the limit", "[executor]") {
    // what a SLURM task's run.sh reports: bash gives 128 + SIGXFSZ for a command the limit stopped
    const fs::path d = demcal::test::fresh_test_dir("executor-153");
    Job job{"slurm-like", d, {"true"}, 60};
    job.max_file_bytes = 1 << 20;
    JobOutcome own_code;
    own_code.exit_code = 153;
    note_file_size_limit(job, own_code);
    CHECK(own_code.failure_cause.empty());  // a program's own exit code 153
    {
        std::ofstream log(d / "stderr.log", std::ios::binary);
        log << std::string(1 << 20, 'x') << "\nlast words\n";
    }
    JobOutcome stopped;
    stopped.exit_code = 153;
    note_file_size_limit(job, stopped);
    CHECK(stopped.failure_cause == kOutputLimitCause);
    CHECK_THAT(stopped.message, Catch::Contains("stderr.log"));
    std::ifstream in(d / "stderr.log");
    const std::string kept((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK_THAT(kept, Catch::EndsWith("last words\n"));
    CHECK(kept.size() < 70 * 1024);
    fs::remove_all(d);
}
