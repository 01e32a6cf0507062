// A command whose disk fills up part way (issue 23: "nothing is lost or half-written"). The disk is made to fill by a
// limit on the size of every file the command and its children write (`ulimit -f`, SIGXFSZ ignored, so a write
// fails with EFBIG as it would with ENOSPC on a full disk): no root and no mount needed. Each case asserts a failure
// (exit 1, not the exit 2 of bad input) that names the file and the reason, no part of the result left behind, and
// the same command finishing once the limit is gone. scripts/probe/probe_disk_full.py runs the same on a real full
// tmpfs for every writing command.
#include "campaign_test_support.hpp"
#include "demcal_cli.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace demcal;
using Catch::Matchers::Contains;

namespace {

// demcal ARGS with no file larger than `kib` KiB (dash's ulimit -f counts 512-byte blocks).
int run_with_file_limit(int kib, const std::string& args, const fs::path& log) {
    const std::string inner = "trap '' XFSZ; ulimit -f " + std::to_string(2 * kib) + "; exec '" + DEMCAL_BINARY +
                              "' " + args;
    const std::string cmd = "sh -c \"" + inner + "\" > '" + log.string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<std::string> names_in(const fs::path& dir) {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

TEST_CASE("a report whose plot cannot be finished leaves none of its files, and the retry writes them all",
          "[cli][partial]") {
    // Before: gnuplot's PNG was cut short with gnuplot's exit 0; when the report itself failed, its plot data stayed
    // behind, and the retry was refused because a side file "is already there" without its report.
    const fs::path dir = test::fresh_test_dir("partial-report");
    const fs::path out = dir / "out", log = dir / "log.txt";
    fs::create_directories(out);
    const std::string args = "diagnose --model oldal --data '" +
                             test::source_path("examples/diagnose/oldal_clean.csv").string() + "' --report '" +
                             (out / "r.md").string() + "'";
    // 8 KiB: the residual table and the plot scripts fit, the first PNG (about 30 kB) does not
    const int rc = run_with_file_limit(8, args, log);
    const std::string text = test::read_file(log);
    INFO(text);
    CHECK(rc == 1);
    CHECK_THAT(text, Contains("r_residuals_before.png") && Contains("is the disk full?"));
    CHECK_THAT(text, Contains("removed the") && Contains("result files this command had begun"));
    CHECK(names_in(out).empty());

    REQUIRE(test::run_demcal_command(args, log) == 0);
    const std::vector<std::string> expected{"r.md",
                                            "r_residuals.dat",
                                            "r_residuals_after.png",
                                            "r_residuals_after.png.gp",
                                            "r_residuals_before.png",
                                            "r_residuals_before.png.gp"};  // (gnuplot's empty logs removed)
    CHECK(names_in(out) == expected);
    // the PNGs are whole: they end with the IEND chunk
    for (const char* png : {"r_residuals_before.png", "r_residuals_after.png"}) {
        const std::string bytes = test::read_file(out / png);
        REQUIRE(bytes.size() > 12);
        CHECK(bytes.compare(bytes.size() - 8, 4, "IEND") == 0);
    }
}

TEST_CASE("a JSON result the disk cannot take is a failure (exit 1) that names the file, not bad input",
          "[cli][partial]") {
    // Before: diagnose said "cannot write F: cannot write F (No space left on device)" with exit 2, the exit of a
    // refused input.
    const fs::path dir = test::fresh_test_dir("partial-json");
    const fs::path json = dir / "r.json", log = dir / "log.txt";
    const int rc = run_with_file_limit(1,
                                       "diagnose --model oldal --data '" +
                                           test::source_path("examples/diagnose/oldal_clean.csv").string() +
                                           "' --json '" + json.string() + "'",
                                       log);
    const std::string text = test::read_file(log);
    INFO(text);
    CHECK(rc == 1);
    CHECK_THAT(text, Contains("demcal: failed: cannot write " + json.string() + " (File too large)"));
    CHECK(!fs::exists(json));
    CHECK(names_in(dir) == std::vector<std::string>{"log.txt"});  // no temporary file either
}

TEST_CASE("a campaign store that cannot be made is named with the system's reason, and nothing of it stays",
          "[cli][partial]") {
    // Before: "store .../campaign.sqlite.new-PID: disk I/O error", the temporary name and no reason
    const fs::path dir = test::fresh_test_dir("partial-store");
    const fs::path camp = dir / "camp", log = dir / "log.txt";
    const int rc = run_with_file_limit(
        4, "shear '" + test::source_path("examples/materials/sand-tiny.json").string() +
               "' --normal-stress 5e3,1e4,2e4 --replicates 1 --campaign '" + camp.string() + "'",
        log);
    const std::string text = test::read_file(log);
    INFO(text);
    CHECK(rc == 1);
    CHECK_THAT(text, Contains("cannot create the campaign store " + (camp / "campaign.sqlite").string() + ": "));
    CHECK_THAT(text, Contains("(File too large)"));
    CHECK_THAT(text, !Contains(".new-"));
    REQUIRE(fs::is_directory(camp));
    CHECK(names_in(camp).empty());
}

TEST_CASE("a silo run that cannot write its results is not marked failed: the campaign stops and the rerun does it",
          "[cli][partial]") {
    // Before: the run exited 1, the campaign wrote its `failed` marker, and every later command reported it failed
    // ("0 runs finished, 2 failed") although nothing was wrong with the run: only the disk had been full.
    const fs::path dir = test::fresh_test_dir("partial-silo-campaign");
    const fs::path camp = dir / "vib", log = dir / "log.txt";
    const std::string args = "vibration --theta 70 --frequency 0,100 --amplitude 1e-4 --repeats 1 --jobs 2 "
                             "--campaign '" + camp.string() + "' -- --geometry '" +
                             test::source_path("examples/silo/reduced_conical_70deg.json").string() +
                             "' --particles 300 --stiffness-scale 0.001 --fill-time 0.1 --max-time 0.2 --threads 1 "
                             "--no-plots";
    // 4 KiB: the campaign's own files fit, a run's summary.json (about 5.6 kB) does not
    const int rc = run_with_file_limit(4, args, log);
    const std::string text = test::read_file(log);
    INFO(text);
    CHECK(rc == 75);  // stopped: the same command continues
    CHECK_THAT(text, Contains("could not write its results") && Contains("the same command runs it again"));
    for (const char* run : {"theta70_f0_seed1", "theta70_f100_seed1"}) {
        CHECK_FALSE(fs::exists(camp / "runs" / run / "failed"));
        CHECK_FALSE(fs::exists(camp / "runs" / run / "summary.json"));
    }
    REQUIRE(test::run_demcal_command(args, log) == 0);
    const std::string again = test::read_file(log);
    INFO(again);
    CHECK_THAT(again, Contains("2 runs finished, 0 failed"));
}

TEST_CASE("a stop signal while gnuplot draws ends both, with no half plot under the plot's name", "[cli][partial]") {
    // Before (probe 64 D2): gnuplot wrote straight into the plot's name, and a stop signal in a report's drawing
    // ended demcal at once: half a PNG stayed, and gnuplot went on drawing as an orphan. A slow gnuplot stands in for a
    // large plot (the real one draws diagnose's plots in a blink): it writes half a file where it is told, then waits.
    const fs::path dir = test::fresh_test_dir("signal-while-drawing");
    const fs::path out = dir / "out", log = dir / "log.txt", bin = dir / "bin", pid_file = dir / "gnuplot.pid";
    fs::create_directories(out);
    fs::create_directories(bin);
    std::ofstream(bin / "gnuplot") << "#!/bin/sh\necho $$ > '" << pid_file.string()
                                   << "'\nout=$(sed -n \"s/^set output '\\(.*\\)'$/\\1/p\" \"$1\")\n"
                                      "printf 'half a plot' > \"$out\"\nexec sleep 120\n";
    fs::permissions(bin / "gnuplot", fs::perms::owner_all);
    const std::string old_path = std::getenv("PATH");
    ::setenv("PATH", (bin.string() + ":" + old_path).c_str(), 1);
    const pid_t demcal = test::spawn_demcal({"diagnose", "--model", "oldal", "--data",
                                            test::source_path("examples/diagnose/oldal_clean.csv").string(), "--report",
                                            (out / "r.md").string()},
                                           log);
    ::setenv("PATH", old_path.c_str(), 1);
    for (int i = 0; i < 600 && !fs::exists(pid_file); ++i) ::usleep(50'000);
    REQUIRE(fs::exists(pid_file));
    ::usleep(200'000);  // the stand-in has written its half file
    const pid_t gnuplot = std::stoi(test::read_file(pid_file));
    ::kill(demcal, SIGINT);
    int status = 0;
    REQUIRE(::waitpid(demcal, &status, 0) == demcal);
    INFO(test::read_file(log));
    CHECK(WIFSIGNALED(status));  // ended as Ctrl-C ends a program, not as a failure of its own
    CHECK((WIFSIGNALED(status) && WTERMSIG(status) == SIGINT));
    CHECK(::kill(gnuplot, 0) != 0);  // no gnuplot left drawing
    CHECK_THAT(test::read_file(log), Contains("stopped by SIGINT while gnuplot drew"));
    CHECK(names_in(out).empty());  // neither the half plot nor the report's other files it had begun
}
