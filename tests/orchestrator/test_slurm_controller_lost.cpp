// A campaign on a real single-node SLURM (started by the test) whose controller dies after the runs were submitted:
// squeue no longer answers, so no cancelled task is ever confirmed ended. SIGTERM must still stop the campaign
// within the cancel grace (exit 75, the runs not finished back to pending), where it waited for squeue forever and
// only kill -9 ended it (probe 60).
#include "slurm_for_test.hpp"
#include "campaign_test_support.hpp"

#include <catch2/catch.hpp>

#include <csignal>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

using namespace demcal;
namespace fs = std::filesystem;

TEST_CASE("a SLURM campaign whose controller is gone stops on SIGTERM within the cancel grace", "[slurm]") {
    if (::geteuid() != 0) {
        WARN("not root: cannot start SLURM daemons here, skipped");
        return;
    }
    test::SlurmForTest cluster;
    REQUIRE(cluster.up());
    const fs::path dir = test::fresh_test_dir("slurm-controller-lost");
    const fs::path camp = dir / "camp";
    // YADE runs of about 4 s, one at a time: the array's other tasks wait in SLURM's queue
    const int pid = test::spawn_demcal({"shear", test::source_path("examples/materials/sand-tiny.json").string(), "-s",
                                        "5e3,1e4,2e4", "--executor", "slurm", "--jobs", "1", "--campaign",
                                        camp.string()},
                                       dir / "run.log");
    REQUIRE(pid > 0);
    bool submitted = false;
    for (int i = 0; i < 600 && !submitted; ++i) {
        std::error_code ec;
        for (fs::directory_iterator it(camp / "slurm", ec), end; !ec && it != end; it.increment(ec))
            submitted = submitted || it->path().extension() == ".sbatch";
        if (!submitted) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    REQUIRE(submitted);
    std::this_thread::sleep_for(std::chrono::seconds(1));
    std::string controller;
    std::ifstream("/run/slurm/slurmctld.pid") >> controller;
    REQUIRE_FALSE(controller.empty());
    REQUIRE(::kill(std::stoi(controller), SIGKILL) == 0);
    const auto stop_sent = std::chrono::steady_clock::now();
    ::kill(pid, SIGTERM);
    int status = 0;
    bool ended = false;
    while (!ended && std::chrono::steady_clock::now() - stop_sent < std::chrono::seconds(120)) {
        ended = ::waitpid(pid, &status, WNOHANG) == pid;
        if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    if (!ended) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - stop_sent).count();
    cluster.stop();
    INFO(test::read_file(dir / "run.log"));
    REQUIRE(ended);
    // the cancel grace is 30 s, and each squeue or scancel waits about 10 s on a controller that is gone
    CHECK(seconds < 90);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 75);
    for (const auto& r : test::stored_runs(camp))
        CHECK((r.state == orchestrator::RunState::pending || r.state == orchestrator::RunState::done));
    fs::remove_all(dir);
}
