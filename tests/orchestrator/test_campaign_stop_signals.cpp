// A shear campaign asked to stop by a signal (orchestrator/stop_signals.hpp): SIGTERM (kill, scancel) and SIGHUP
// (the terminal or ssh session that started it closed) stop its runs, record them, and leave a campaign that resume
// finishes; nothing it started is left running. Kernel engine: seconds per run, no YADE needed.
#include <catch2/catch.hpp>

#include "campaign_test_support.hpp"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <sys/wait.h>
#include <thread>

namespace fs = std::filesystem;
using namespace demcal;

TEST_CASE("a shear campaign stopped by SIGTERM or SIGHUP stops its runs, and resume finishes it",
          "[kernel_engine][signals]") {
    const auto [sig, name] = GENERATE(std::pair<int, const char*>{SIGTERM, "sigterm"},
                                      std::pair<int, const char*>{SIGHUP, "sighup"});
    const fs::path dir = test::fresh_test_dir(std::string("campaign-stop-") + name);
    const fs::path camp = dir / "camp", log = dir / "stopped.log";
    const int pid = test::spawn_demcal({"shear", test::source_path("examples/materials/sand-tiny.json").string(),
                                        "--normal-stress", "3e3,5e3,7e3", "--replicates", "2", "--engine", "kernel",
                                        "--jobs", "1", "--campaign", camp.string()},
                                       log);
    REQUIRE(pid > 0);
    // once a run is under way (one of six, about a second each)
    int status = 0;
    bool ended = false;
    for (int i = 0; i < 6000 && !ended; ++i) {
        if (!test::processes_under(camp / "runs").empty()) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ended = ::waitpid(pid, &status, WNOHANG) == pid;
    }
    REQUIRE_FALSE(ended);
    ::kill(pid, sig);
    ::waitpid(pid, &status, 0);
    INFO(test::read_file(log));
    REQUIRE(WIFEXITED(status));  // stopped, not killed by the signal
    CHECK(WEXITSTATUS(status) == 75);  // EX_TEMPFAIL: resume it, as every campaign command
    CHECK_THAT(test::read_file(log), Catch::Matchers::Contains("interrupted: continue with `demcal resume"));
    CHECK(test::processes_under(camp).empty());
    REQUIRE(test::run_demcal({"status", camp.string()}, dir / "status.log") == 0);
    CHECK_THAT(test::read_file(dir / "status.log"), Catch::Matchers::Contains("[interrupted]"));
    // YADE's launcher on a resume of kernel campaigns is a void option (it was ignored, exit 0)
    CHECK(test::run_demcal({"resume", camp.string(), "--yade", "/usr/bin/yade"}, dir / "yade.log") == 2);
    CHECK_THAT(test::read_file(dir / "yade.log"), Catch::Matchers::Contains("run on the kernel engine; omit it"));
    // --max-runs bounds the runs left (it was accepted and ignored): at least five of six are not done
    CHECK(test::run_demcal({"resume", camp.string(), "--max-runs", "1"}, dir / "max.log") == 2);
    CHECK_THAT(test::read_file(dir / "max.log"), Catch::Matchers::Contains("--max-runs = 1: the campaigns of") &&
                                                     Catch::Matchers::Contains("runs not done"));
    REQUIRE(test::run_demcal({"resume", camp.string()}, dir / "resume.log") == 0);
    CHECK_FALSE(test::find_file(camp, "failure_line_", ".json").empty());
    fs::remove_all(dir);
}

TEST_CASE("a silo sweep killed with -9 takes its runs with it, and the same command then resumes them",
          "[kernel_engine][signals]") {
    // probe 60: the run went on as an orphan; the sweep run again found its folder busy and marked it failed for good
    const fs::path dir = test::fresh_test_dir("sweep-kill9");
    const fs::path camp = dir / "sweep";
    const std::vector<std::string> sweep{
        "vibration", "--theta", "70", "--frequency", "0", "--repeats", "1", "--jobs", "1", "--campaign", camp.string(),
        "--", "--geometry", test::source_path("examples/silo/reduced_conical_70deg.json").string(), "--outlet",
        "0.018", "--particles", "2000", "--stiffness-scale", "0.001", "--fill-time", "0.3", "--max-time", "0.4",
        "--threads", "1", "--no-plots"};
    // the sweep's runs: processes whose command line names the campaign (they run from the sweep's folder)
    const auto runs_of_sweep = [&] {
        std::vector<int> pids;
        for (const auto& e : fs::directory_iterator("/proc")) {
            const std::string name = e.path().filename().string();
            if (name.find_first_not_of("0123456789") != std::string::npos) continue;
            std::string cmdline = test::read_file(e.path() / "cmdline");
            std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
            if (cmdline.find(" silo ") != std::string::npos && cmdline.find(camp.string()) != std::string::npos)
                pids.push_back(std::stoi(name));
        }
        return pids;
    };
    const int pid = test::spawn_demcal(sweep, dir / "killed.log");
    REQUIRE(pid > 0);
    int status = 0;
    bool ended = false;
    for (int i = 0; i < 6000 && !ended; ++i) {  // once its run is under way
        if (!runs_of_sweep().empty()) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ended = ::waitpid(pid, &status, WNOHANG) == pid;
    }
    REQUIRE_FALSE(ended);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    // the run got SIGTERM with its parent's death: it checkpoints and ends within seconds
    bool gone = false;
    for (int i = 0; i < 300 && !gone; ++i) {
        gone = runs_of_sweep().empty();
        if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    CHECK(gone);
    REQUIRE(test::run_demcal(sweep, dir / "again.log") == 0);
    INFO(test::read_file(dir / "again.log"));
    CHECK(fs::exists(camp / "runs" / "theta70_f0_seed1" / "summary.json"));
    CHECK_FALSE(fs::exists(camp / "runs" / "theta70_f0_seed1" / "failed"));
    fs::remove_all(dir);
}

TEST_CASE("the small hopper's cut-off search stopped by SIGTERM ends its run and exits 75, saying so",
          "[kernel_engine][signals]") {
    // held-back suite: SIGTERM killed the search (exit 143), no word, nothing kept
    const fs::path dir = test::fresh_test_dir("cutoff-sigterm");
    const int pid = test::spawn_demcal({"cutoff", "--grains", "200", "--tol", "50", "--window", "1", "--json",
                                        (dir / "hop.json").string()},
                                       dir / "cutoff.log");
    REQUIRE(pid > 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    int status = 0;
    REQUIRE(::waitpid(pid, &status, WNOHANG) == 0);  // still searching
    ::kill(pid, SIGTERM);
    ::waitpid(pid, &status, 0);
    INFO(test::read_file(dir / "cutoff.log"));
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 75);
    CHECK_THAT(test::read_file(dir / "cutoff.log"),
               Catch::Matchers::Contains("interrupted after") && Catch::Matchers::Contains("run the same command again"));
    CHECK_FALSE(fs::exists(dir / "hop.json"));  // no result of a search not ended
    fs::remove_all(dir);
}

TEST_CASE("a shear campaign stopped while it writes its report exits 75 with no part of the report, and resume writes "
          "it",
          "[kernel_engine][signals]") {
    // Before (held-back probe 65): a SIGINT just after the last run ended demcal silently by the signal, outside every
    // handler. A slow gnuplot stands in for a report's drawing, so that the signal lands in it: it draws nothing whole.
    const fs::path dir = test::fresh_test_dir("campaign-stop-report");
    const fs::path camp = dir / "camp", log = dir / "stopped.log", bin = dir / "bin", drawing = dir / "drawing";
    fs::create_directories(bin);
    std::ofstream(bin / "gnuplot") << "#!/bin/sh\ntouch '" << drawing.string() << "'\nsleep 2\n";
    fs::permissions(bin / "gnuplot", fs::perms::owner_all);
    const std::vector<std::string> args{"shear", test::source_path("examples/materials/sand-tiny.json").string(),
                                        "--normal-stress", "3e3,5e3,7e3", "--replicates", "1", "--engine", "kernel",
                                        "--jobs", "2", "--campaign", camp.string()};
    const std::string path = std::getenv("PATH");
    ::setenv("PATH", (bin.string() + ":" + path).c_str(), 1);
    const int pid = test::spawn_demcal(args, log);
    ::setenv("PATH", path.c_str(), 1);
    REQUIRE(pid > 0);
    int status = 0;
    bool ended = false;
    for (int i = 0; i < 12000 && !ended && !fs::exists(drawing); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ended = ::waitpid(pid, &status, WNOHANG) == pid;
    }
    REQUIRE_FALSE(ended);
    REQUIRE(fs::exists(drawing));
    ::kill(pid, SIGINT);
    ::waitpid(pid, &status, 0);
    const std::string text = test::read_file(log);
    INFO(text);
    REQUIRE(WIFEXITED(status));  // stopped, not killed by the signal
    CHECK(WEXITSTATUS(status) == 75);
    CHECK(text.find("writes the report again") != std::string::npos);
    CHECK(test::find_file(camp, "failure_line_", ".json").empty());
    CHECK(test::find_file(camp, "shear_curves_", "").empty());
    // resume (with the real gnuplot) writes the whole report from the store, running nothing again
    REQUIRE(test::run_demcal({"resume", camp.string()}, dir / "resume.log") == 0);
    CHECK(!test::find_file(camp, "failure_line_", ".json").empty());
    CHECK(!test::find_file(camp, "failure_line_", ".png").empty());
    for (const auto& r : test::stored_runs(camp)) CHECK(r.attempts == 1);
    fs::remove_all(dir);
}
