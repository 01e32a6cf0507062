// examples/silo/silo_slurm.sbatch against a real single-node SLURM that this test starts (scripts/slurm/slurm_up.sh)
// and stops: a tiny silo case stopped by SIGTERM to its batch shell (as SLURM's --signal=B:TERM@120 sends it before
// the time limit) suspends with its checkpoint, submits the next job, and the chain ends with the discharge.csv of an
// uninterrupted run. Needs root (the SLURM daemons) and the demcal binary.
#include "slurm_for_test.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

using demcal::test::read_file;

// Runs a shell command; its standard output, trailing newline removed.
std::string shell_output(const std::string& cmd) {
    std::string out;
    if (FILE* p = ::popen(cmd.c_str(), "r")) {
        char buf[256];
        while (std::fgets(buf, sizeof buf, p)) out += buf;
        ::pclose(p);
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out;
}

// Polls `ready` every 50 ms for at most `limit`; whether it came true.
template <class Ready>
bool poll_until(Ready ready, std::chrono::seconds limit) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (!ready()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return true;
}

// Every job log of the chain, in job order.
std::string chain_logs(const fs::path& dir) {
    std::vector<fs::path> logs;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().rfind("demcal-silo-", 0) == 0) logs.push_back(e.path());
    std::sort(logs.begin(), logs.end());
    std::string all;
    for (const auto& l : logs) all += "== " + l.filename().string() + "\n" + read_file(l);
    return all;
}

}  // namespace

TEST_CASE("silo_slurm.sbatch: a job stopped by SIGTERM resubmits itself and the chain ends with the whole run",
          "[silo][slurm]") {
    if (::geteuid() != 0) {
        WARN("not root: cannot start SLURM daemons here, skipped");
        return;
    }
    REQUIRE(fs::exists(DEMCAL_BINARY));
    const std::string source = DEMCAL_SOURCE_DIR;
    const fs::path dir = fs::temp_directory_path() / ("demcal_test_silo_slurm_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string case_args = "--geometry " + source + "/examples/silo/reduced_conical_70deg.json --theta 45 "
                                  "--particles 600 --stiffness-scale 0.001 --fill-time 0.3 --max-time 0.4";
    const std::string whole_cmd = std::string("'") + DEMCAL_BINARY + "' silo " + case_args +
                                  " --no-plots --no-checkpoint --threads 2 --out '" + (dir / "whole").string() +
                                  "' > '" + (dir / "whole.log").string() + "' 2>&1";
    REQUIRE(std::system(whole_cmd.c_str()) == 0);

    demcal::test::SlurmForTest cluster;
    REQUIRE(cluster.up());
    const fs::path out = dir / "chain";
    const std::string submit = "cd '" + dir.string() + "' && SILO_OUT='" + out.string() + "' SILO_ARGS='" +
                               case_args + "' SILO_JOB_ARGS='--no-plots --checkpoint-every 0.05' DEMCAL='" +
                               DEMCAL_BINARY + "' sbatch --parsable " + source + "/examples/silo/silo_slurm.sbatch";
    const std::string first_job = shell_output(submit);
    INFO("first job: " << first_job);
    // the first job runs; once its first checkpoint is written, SIGTERM to its batch shell only (as --signal=B:TERM)
    const bool checkpointed = poll_until([&] { return fs::exists(out / "checkpoint.bin"); }, std::chrono::seconds(60));
    if (checkpointed) std::system(("scancel --batch --signal=TERM " + first_job).c_str());
    // the chain ends when the outputs are written and no job of it is left in the queue
    const bool ended = poll_until(
        [&] {
            return fs::exists(out / "summary.json") &&
                   shell_output("squeue -h -n demcal-silo -o %i | wc -l") == "0";
        },
        std::chrono::seconds(180));
    if (!ended) std::system("scancel -n demcal-silo");
    const std::string logs = chain_logs(dir);
    cluster.stop();
    INFO(logs);
    REQUIRE(!first_job.empty());
    REQUIRE(checkpointed);
    REQUIRE(ended);
    CHECK_THAT(logs, Catch::Matchers::Contains("suspended: SIGTERM received"));
    CHECK_THAT(logs, Catch::Matchers::Contains("continues the run in " + out.string()));
    CHECK_THAT(logs, Catch::Matchers::Contains("--resume " + out.string()));
    CHECK(read_file(out / "discharge.csv") == read_file(dir / "whole" / "discharge.csv"));
    CHECK_THAT(read_file(out / "summary.json"), Catch::Matchers::Contains("\"sessions\": 2"));
    CHECK_FALSE(fs::exists(out / "checkpoint.bin"));
    fs::remove_all(dir);
}
