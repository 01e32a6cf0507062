// demcal silo end to end: bad input exits 2 naming the field and the value, before anything is written; a tiny run
// writes discharge.csv and summary.json; a run killed with -9, resumed, stopped by its wall limit, by SIGTERM and by
// SIGHUP, then finished under nohup (a hang-up ignored) writes the same discharge.csv as an uninterrupted one. Needs
// the demcal binary (built with the project: CI builds everything).
#include "test_files.hpp"

#include <catch2/catch.hpp>

#include "kernel/silo/discharge_end.hpp"
#include "orchestrator/folder_lock.hpp"
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using demcal::test::read_file;

struct Run {
    int rc;
    std::string err;
};

Run run_silo(const std::string& args, const fs::path& dir) {
    fs::create_directories(dir);
    const std::string cmd = std::string("'") + DEMCAL_BINARY + "' silo " + args + " > '" + (dir / "out.log").string() +
                            "' 2> '" + (dir / "err.log").string() + "'";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(dir / "err.log")};
}

// Starts `demcal silo ARGS` in the background (exec'd by sh, so that a signal reaches demcal itself), output to LOG.
pid_t spawn_demcal(const std::string& args, const fs::path& log) {
    const std::string cmd = std::string("exec '") + DEMCAL_BINARY + "' silo " + args + " > '" + log.string() + "' 2>&1";
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    return pid;
}

// Waits until `ready` holds or the process ends; true when it has ended (its wait status in `status`).
template <class Ready>
bool wait_until(pid_t pid, Ready ready, int& status) {
    while (!ready()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        if (::waitpid(pid, &status, WNOHANG) == pid) return true;
    }
    return false;
}

void require_demcal() {
    INFO("the demcal binary is built with the project (cmake --build build); test_kernel runs it");
    REQUIRE(fs::exists(DEMCAL_BINARY));
}

}  // namespace

TEST_CASE("demcal silo: bad input exits 2 naming the field and the value", "[silo][cli]") {
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_bad";
    fs::remove_all(dir);
    const fs::path out = dir / "never";
    struct Case {
        std::string args, expect;
    };
    for (const Case& c : {Case{"--theta 95", "theta = 95"}, Case{"--theta 0", "theta = 0"},
                          Case{"--theta 30 --outlet 0.01", "outlet = 0.01"},
                          Case{"--theta 30 --diameter 0.02", "diameter = 0.02"},
                          Case{"--theta 30 --rect --c 0.02", "--c = 0.02 with a (outlet width) = 0.03: the silo width c"},
                          Case{"--theta 30 --rect --b 0.01", "--b = 0.01: the slot spans the depth b"},
                          Case{"--theta 30 --particles 0", "particles = 0"},
                          Case{"--theta 30 --stiffness-scale -1", "--stiffness-scale = -1"},
                          Case{"--theta 30 --stop-fraction 2", "--stop-fraction = 2"},
                          Case{"--theta 30 --b 0.05", "--b = 0.05: applies to a rectangular hopper"},
                          Case{"--theta 30 --wall-limit 60 --no-checkpoint", "--wall-limit 60 needs the checkpoint"},
                          Case{"", "--theta: missing"},
                          // a value that once meant "not given" is a value like any other
                          Case{"--theta 30 --outlet -1", "outlet = -1"},
                          Case{"--theta 30 --rect --outlet -1", "--outlet = -1: must be positive"},
                          Case{"--theta 30 --seed -1", "--seed = -1"},
                          Case{"--theta 30 --a 0.02", "--a = 0.02: applies to a rectangular hopper"},
                          Case{"--theta 30 --checkpoint-every nan", "--checkpoint-every: 'nan' is not a number"},
                          Case{"--theta 30 --wall-limit -5", "wall-limit = -5"},
                          Case{"--theta 30 --vtk /dev/null/x", "vtk = '/dev/null/x'"},
                          Case{"--theta 30 --vtk-every 0.1", "--vtk-every applies to the VTK snapshots"},
                          Case{"--theta 30 --fill-mass 1e9", "--fill-mass = 1e+09"},
                          // the grains of a 30 m column in a 0.5 m silo: they passed --check
                          Case{"--theta 30 --particles 5000000", "--particles = 5e+06: the bed does not fit the silo"},
                          Case{"--theta 30 --fill-mass 20", "--fill-mass = 20: the bed does not fit the silo"},
                          // a bed for YADE's conical silo script, from a rectangular silo
                          Case{"--theta 30 --rect --export-bed bed.json", "--export-bed = 'bed.json': the bed files "
                                                                          "are for YADE's silo"},
                          Case{"--theta 30 --rect --export-cloud c.json", "--export-cloud = 'c.json'"},
                          Case{"--theta 30 --dt 1e-4", "dt = 0.0001: larger than the Rayleigh time step"},
                          // the bin's vibration: both numbers or none, ranges, no subnormals
                          Case{"--theta 30 --vibration-frequency 100",
                               "--vibration-frequency 100 needs --vibration-amplitude"},
                          Case{"--theta 30 --vibration-amplitude 1e-4",
                               "--vibration-amplitude 0.0001 needs --vibration-frequency"},
                          Case{"--theta 30 --vibration-start 0.1", "--vibration-start applies to a vibrating bin"},
                          Case{"--theta 30 --vibration-direction z",
                               "--vibration-direction applies to a vibrating bin"},
                          Case{"--theta 30 --vibration-part hopper", "--vibration-part applies to a vibrating bin"},
                          Case{"--theta 30 --vibration-frequency 1500 --vibration-amplitude 1e-4",
                               "--vibration-frequency = 1500"},
                          Case{"--theta 30 --vibration-frequency -5 --vibration-amplitude 1e-4",
                               "--vibration-frequency = -5"},
                          Case{"--theta 30 --vibration-frequency inf --vibration-amplitude 1e-4",
                               "--vibration-frequency: 'inf' is not finite"},
                          Case{"--theta 30 --vibration-frequency 100 --vibration-amplitude 0.05",
                               "--vibration-amplitude = 0.05"},
                          Case{"--theta 30 --vibration-frequency 100 --vibration-amplitude nan",
                               "--vibration-amplitude: 'nan' is not a number"},
                          Case{"--theta 30 --vibration-frequency 100 --vibration-amplitude 1e-310",
                               "--vibration-amplitude: '1e-310' is subnormal"},
                          Case{"--theta 30 --vibration-frequency 100 --vibration-amplitude 1e-4 --vibration-direction y",
                               "vibration-direction = 'y'"},
                          Case{"--theta 30 --vibration-frequency 100 --vibration-amplitude 1e-4 --vibration-part cone",
                               "vibration-part = 'cone'"},
                          Case{"--theta 30 --vibration-frequency 100 --vibration-amplitude 1e-4 --vibration-start -1",
                               "--vibration-start = -1"},
                          Case{"--theta 30 --vibration-frequency 1000 --vibration-amplitude 1e-4 "
                               "--stiffness-scale 0.001",
                               "--vibration-frequency = 1000: a period is only"},
                          // the command-line parser's own refusals exit 2 as well
                          Case{"--theta abc", "--theta: 'abc' is not a number"},
                          Case{"--theta 30 --thetaa 3", "'--thetaa' is not an option"}}) {
        INFO(c.args);
        const Run r = run_silo(c.args + " --out '" + out.string() + "'", dir);
        CHECK(r.rc == 2);
        CHECK_THAT(r.err, Catch::Matchers::Contains(c.expect));
        CHECK_FALSE(fs::exists(out));
    }
    // a geometry file: the same rules as the options, the file and its key named (as an option is by its name)
    struct GeometryCase {
        std::string json, options, expect;
    };
    for (const GeometryCase& c :
         {GeometryCase{R"({"shape": "conical", "theta_deg": 30, "outlet_mm": 35})", "", "unknown key 'outlet_mm'"},
          GeometryCase{R"({"theta_deg": -1})", "", "g.json: theta_deg = -1: the hopper half angle"},
          GeometryCase{R"({"theta_deg": 30, "a_m": 0.02})", "", "a_m = 0.02: applies to a rectangular hopper"},
          GeometryCase{R"({"shape": "rectangular", "theta_deg": 30, "D_m": 0.2})", "", "D_m = 0.2: the diameter"},
          GeometryCase{R"({"shape": "rectangular", "theta_deg": 30, "outlet_m": 0.03, "a_m": 0.02})", "",
                       "both set the outlet (slot) width"},
          GeometryCase{R"({"theta_deg": "30"})", "", R"(theta_deg = "30": must be a number)"},
          // --rect over a conical file: its D_m was dropped and its circular outlet run as a slot (probe 58b)
          GeometryCase{R"({"theta_deg": 30, "D_m": 0.105})", "--rect --c 0.1",
                       "--rect: the --geometry file gives the diameter of a conical silo"},
          GeometryCase{R"({"shape": "conical", "theta_deg": 30})", "--rect", "--rect: the --geometry file is a conical"},
          // a file of neither shape's own keys takes --rect, and the rest of the rules stand
          GeometryCase{R"({"theta_deg": 30})", "--rect --c 0.02", "--c = 0.02 with a (outlet width) = 0.03: the silo width c"}}) {
        INFO(c.json + " " + c.options);
        std::ofstream(dir / "g.json") << c.json;
        const Run r = run_silo("--geometry '" + (dir / "g.json").string() + "' " + c.options + " --out '" +
                                   out.string() + "'",
                               dir);
        CHECK(r.rc == 2);
        CHECK_THAT(r.err, Catch::Matchers::Contains(c.expect));
        CHECK_FALSE(fs::exists(out));
    }
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: a tiny run writes discharge.csv and summary.json", "[silo][cli]") {
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_run";
    fs::remove_all(dir);
    const Run r = run_silo("--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                             "/examples/silo/reduced_conical_70deg.json' --theta 45 --particles 300 "
                             "--stiffness-scale 0.001 --fill-time 0.3 --max-time 0.2 --threads 1 --no-plots --out '" +
                             (dir / "out").string() + "'",
                         dir);
    INFO(r.err);
    REQUIRE(r.rc == 0);
    CHECK(fs::exists(dir / "out" / "discharge.csv"));
    const std::string summary = read_file(dir / "out" / "summary.json");
    CHECK_THAT(summary, Catch::Matchers::Contains("\"wall_to_axis_velocity_ratio\""));
    CHECK_THAT(summary, Catch::Matchers::Contains("\"grains\": 300"));
    // a new run into the finished folder is refused (it left the old results beside its own checkpoint until its end)
    const Run again = run_silo("--theta 40 --particles 300 --threads 1 --no-plots --out '" + (dir / "out").string() +
                                   "'",
                               dir);
    CHECK(again.rc == 2);
    CHECK_THAT(again.err, Catch::Matchers::Contains("holds the results of a finished run"));
    CHECK(read_file(dir / "out" / "summary.json") == summary);
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: an output folder another demcal holds is refused at once, and so is a silo campaign's",
          "[silo][cli]") {
    // two `silo --resume D` resumed one checkpoint together, two vibration sweeps ran the same runs into one folder
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_lock";
    fs::remove_all(dir);
    fs::create_directories(dir / "out");
    fs::create_directories(dir / "camp");
    {
        const demcal::orchestrator::FolderLock held(dir / "out", "test");
        const Run r = run_silo("--theta 40 --particles 300 --threads 1 --no-plots --out '" + (dir / "out").string() +
                                   "'",
                               dir);
        CHECK(r.rc == 2);
        CHECK_THAT(r.err, Catch::Matchers::Contains("silo output folder") &&
                              Catch::Matchers::Contains("is in use by another demcal process"));
        const demcal::orchestrator::FolderLock campaign(dir / "camp", "test");
        const std::string sweep = "'" + std::string(DEMCAL_BINARY) + "' vibration --theta 40 --frequency 0 "
                                  "--campaign '" + (dir / "camp").string() + "' -- --particles 300 --no-plots "
                                  "--threads 1 > '" + (dir / "sweep.log").string() + "' 2>&1";
        CHECK(WEXITSTATUS(std::system(sweep.c_str())) == 2);
        CHECK_THAT(read_file(dir / "sweep.log"), Catch::Matchers::Contains("is in use by another demcal process"));
        // a shear campaign in a held folder: the same refusal and exit code (it exited 1, "failed")
        fs::create_directories(dir / "shear");
        const demcal::orchestrator::FolderLock shear_campaign(dir / "shear", "test");
        const std::string shear = "'" + std::string(DEMCAL_BINARY) + "' shear '" + std::string(DEMCAL_SOURCE_DIR) +
                                  "/examples/materials/sand-tiny.json' -s 3e3,5e3 -r 2 --engine kernel --campaign '" +
                                  (dir / "shear").string() + "' > '" + (dir / "shear.log").string() + "' 2>&1";
        CHECK(WEXITSTATUS(std::system(shear.c_str())) == 2);
        CHECK_THAT(read_file(dir / "shear.log"), Catch::Matchers::Contains("demcal: error: ") &&
                                                     Catch::Matchers::Contains("is in use by another demcal process"));
    }
    CHECK_FALSE(fs::exists(dir / "out" / "summary.json"));
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: a tiny vibrating run records the vibration and its peak acceleration", "[silo][cli]") {
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_vibration";
    fs::remove_all(dir);
    const Run r = run_silo("--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                               "/examples/silo/reduced_conical_70deg.json' --theta 45 --particles 300 "
                               "--stiffness-scale 0.001 --fill-time 0.3 --max-time 0.1 --threads 1 --no-plots "
                               "--vibration-frequency 100 --vibration-amplitude 1.1e-4 --vibration-start 0.01 --out '" +
                               (dir / "out").string() + "'",
                           dir);
    INFO(r.err);
    REQUIRE(r.rc == 0);
    const std::string summary = read_file(dir / "out" / "summary.json");
    INFO(summary);
    CHECK_THAT(summary, Catch::Matchers::Contains("\"vibrates\": true"));
    CHECK_THAT(summary, Catch::Matchers::Contains("\"frequency_hz\": 100.0"));
    CHECK_THAT(summary, Catch::Matchers::Contains("\"amplitude_m\": 0.00011"));
    CHECK_THAT(summary, Catch::Matchers::Contains("\"direction\": \"x\""));
    CHECK_THAT(summary, Catch::Matchers::Contains("\"start_after_opening_s\": 0.01"));
    // A (2 pi f)^2 / g = 1.1e-4 (628.3)^2 / 9.81 = 4.427
    CHECK_THAT(summary, Catch::Matchers::Contains("\"peak_acceleration_g\": 4.42"));
    CHECK_THAT(read_file(dir / "out.log"), Catch::Matchers::Contains("vibration: 100 Hz, 0.11 mm along x"));
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: a vibration that starts after the discharge ended is recorded as none, and warned",
          "[silo][cli]") {
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_vibration_late";
    fs::remove_all(dir);
    // 300 grains leave a 30 mm outlet in about 0.1 s; the vibration would start 0.3 s after the opening
    const Run r = run_silo("--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                               "/examples/silo/reduced_conical_70deg.json' --theta 30 --particles 300 "
                               "--stiffness-scale 0.001 --fill-time 0.3 --max-time 1 --threads 1 --no-plots "
                               "--vibration-frequency 100 --vibration-amplitude 1.1e-4 --vibration-start 0.3 --out '" +
                               (dir / "out").string() + "'",
                           dir);
    INFO(r.err);
    REQUIRE(r.rc == 0);
    const auto summary = nlohmann::json::parse(read_file(dir / "out" / "summary.json"));
    INFO(summary.dump(1));
    REQUIRE(summary["discharge"]["time_s"].get<double>() < 0.3);
    // held-back suite: "vibrates": true for a still discharge
    CHECK(summary["vibration"]["vibrates"] == false);
    CHECK(summary["vibration"]["vibration_requested"] == true);
    CHECK(summary["vibration"]["vibrated_s"] == 0.0);
    CHECK_THAT(r.err, Catch::Matchers::Contains("the bin never vibrated"));
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: a bed arched before a late vibration starts is not stopped before it is shaken",
          "[silo][cli]") {
    // meal arches over the outlet at 50 deg: nothing leaves in the first 0.5 s. The run used to end there ("flow
    // stopped") with the vibration set to start at 0.6 s never run, and the summary still reported a 400 Hz bin.
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_late_vibration";
    fs::remove_all(dir);
    const Run r = run_silo("--material '" + std::string(DEMCAL_SOURCE_DIR) +
                               "/examples/materials/silo_meal.json' --theta 50 --particles 600 --stiffness-scale 0.01 "
                               "--vibration-frequency 400 --vibration-amplitude 1.1e-4 --vibration-start 0.6 "
                               "--max-time 1.5 --threads 1 --no-plots --out '" + (dir / "out").string() + "'",
                           dir);
    INFO(r.err);
    REQUIRE(r.rc == 0);
    const auto summary = nlohmann::json::parse(read_file(dir / "out" / "summary.json"));
    const auto& discharge = summary.at("discharge");
    INFO(discharge.dump());
    CHECK(discharge.at("time_s").get<double>() > 0.6);  // ran into the vibration
    CHECK(discharge.at("discharged_mass_kg").get<double>() > 0);
    // how it ended, as a state a search reads (not the stop reason's words)
    const auto end = demcal::kernel::silo::discharge_end_from_name(discharge.at("end").get<std::string>());
    REQUIRE(end);
    CHECK((*end == demcal::kernel::silo::DischargeEnd::time_limit || *end == demcal::kernel::silo::DischargeEnd::emptied ||
           *end == demcal::kernel::silo::DischargeEnd::flow_stopped));
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: results that cannot be written keep the checkpoint, and resuming writes them",
          "[silo][cli]") {
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_unwritable";
    fs::remove_all(dir);
    const fs::path out = dir / "out";
    fs::create_directories(out / "summary.json" / "in_the_way");  // a directory where summary.json must go
    const Run r = run_silo("--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                               "/examples/silo/reduced_conical_70deg.json' --theta 45 --particles 300 "
                               "--stiffness-scale 0.001 --fill-time 0.3 --max-time 0.2 --threads 1 --no-plots "
                               "--checkpoint-every 0.001 --out '" + out.string() + "'",
                           dir);
    INFO(r.err);
    CHECK(r.rc == 74);  // kExitResultsNotWritten: not the run's failure (a campaign runs it again)
    CHECK_THAT(r.err, Catch::Matchers::Contains("the results are not written"));
    CHECK_THAT(r.err, Catch::Matchers::Contains("the checkpoint is kept"));
    CHECK_FALSE(fs::exists(out / "discharge.csv"));  // no table without its summary
    REQUIRE(fs::exists(out / "checkpoint.bin"));
    fs::remove_all(out / "summary.json");
    const Run resumed = run_silo("--resume '" + out.string() + "' --threads 1", dir);
    INFO(resumed.err);
    CHECK(resumed.rc == 0);
    CHECK_THAT(read_file(out / "summary.json"), Catch::Matchers::Contains("\"grains\": 300"));
    CHECK_FALSE(fs::exists(out / "checkpoint.bin"));
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: a run killed with -9 or stopped by SIGTERM or SIGHUP resumes to the uninterrupted result",
          "[silo][cli]") {
    require_demcal();
    const fs::path dir = fs::temp_directory_path() / ("demcal_test_silo_cli_resume_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const std::string case_args = "--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                                  "/examples/silo/reduced_conical_70deg.json' --theta 45 --particles 600 "
                                  "--stiffness-scale 0.001 --fill-time 0.3 --max-time 0.4 --no-plots ";
    const Run whole = run_silo(case_args + "--threads 1 --no-checkpoint --out '" + (dir / "whole").string() + "'", dir);
    INFO(whole.err);
    REQUIRE(whole.rc == 0);

    // the same run, checkpointing every 0.1 s of wall time, killed with -9 once its first checkpoint is written
    const fs::path out = dir / "killed", ckpt = out / "checkpoint.bin";
    const pid_t pid =
        spawn_demcal(case_args + "--threads 1 --checkpoint-every 0.1 --out '" + out.string() + "'", dir / "killed.log");
    REQUIRE(pid > 0);
    int status = 0;
    const bool finished = wait_until(pid, [&] { return fs::exists(ckpt); }, status);
    if (!finished) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
    }
    INFO(read_file(dir / "killed.log"));
    REQUIRE_FALSE(finished);  // killed mid-run (the run takes seconds, the first checkpoint comes after 0.1 s)
    REQUIRE(fs::exists(ckpt));
    CHECK_FALSE(fs::exists(out / "summary.json"));

    // a new run into that directory would overwrite the checkpoint: refused
    const Run again = run_silo(case_args + "--out '" + out.string() + "'", dir);
    CHECK(again.rc == 2);
    CHECK_THAT(again.err, Catch::Matchers::Contains("holds the checkpoint of an unfinished run"));
    // a damaged checkpoint (cut short in the run's state) is bad input: exit 2, the file left as it was
    const std::string bytes = read_file(ckpt);
    fs::create_directories(dir / "cut");
    std::ofstream(dir / "cut" / "checkpoint.bin", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    const Run damaged = run_silo("--resume '" + (dir / "cut").string() + "' --threads 1", dir);
    CHECK(damaged.rc == 2);
    CHECK_THAT(damaged.err, Catch::Matchers::Contains("checkpoint"));
    CHECK(read_file(dir / "cut" / "checkpoint.bin") == bytes.substr(0, bytes.size() / 2));
    CHECK(std::distance(fs::directory_iterator(dir / "cut"), fs::directory_iterator()) == 1);  // nor a .lock added
    // a resumed run keeps its stored settings
    const Run mixed = run_silo("--resume '" + out.string() + "' --theta 30", dir);
    CHECK(mixed.rc == 2);
    CHECK_THAT(mixed.err, Catch::Matchers::Contains("--theta cannot be combined with --resume"));

    // a session with a wall limit stops itself after one record interval: exit 75, checkpoint kept, no outputs
    const Run limited = run_silo("--resume '" + out.string() + "' --threads 1 --wall-limit 0.001", dir);
    CHECK(limited.rc == 75);
    CHECK(fs::exists(ckpt));
    CHECK_FALSE(fs::exists(out / "summary.json"));
    CHECK_THAT(read_file(dir / "out.log"), Catch::Matchers::Contains("suspended: wall limit"));
    // a resume without session options runs with the run's own (session.json): one thread, no plots, checkpoints
    // every 0.1 s, where it ran on every core and drew plots (probe 60)
    const Run own = run_silo("--resume '" + out.string() + "' --wall-limit 0.001", dir);
    CHECK(own.rc == 75);
    CHECK_THAT(read_file(dir / "out.log"), Catch::Matchers::Contains("\n  1 thread(s)"));
    // a session file holding what --threads refuses (100000 threads crashed the resume) or no JSON at all is said and
    // left aside, in a copy of the run: a side file never stops a resumable run
    for (const std::string text : {"{\"threads\": 100000, \"checkpoint_every\": 7, \"no_plots\": true}", "garbage"}) {
        INFO(text);
        fs::remove_all(dir / "copy");
        fs::copy(out, dir / "copy", fs::copy_options::recursive);
        std::ofstream(dir / "copy" / "session.json") << text;
        const Run aside = run_silo("--resume '" + (dir / "copy").string() + "' --no-plots --wall-limit 0.001", dir);
        CHECK(aside.rc == 75);
        CHECK_THAT(aside.err, Catch::Matchers::Contains("is not the run's session options"));
    }
    fs::remove_all(dir / "copy");

    // a session stopped by a signal once it steps: SIGTERM (a batch system's time limit, scancel) and SIGHUP (the
    // terminal or the ssh session closed) make the same clean stop as the wall limit
    auto stop_session_with = [&](int sig, const std::string& name) {
        const fs::path log = dir / (name + ".log");
        const pid_t pid = spawn_demcal("--resume '" + out.string() + "' --threads 1", log);
        REQUIRE(pid > 0);
        int st = 0;
        const bool ended = wait_until(pid, [&] { return read_file(log).find("resumed") != std::string::npos; }, st);
        if (!ended) {
            ::kill(pid, sig);
            ::waitpid(pid, &st, 0);
        }
        INFO(read_file(log));
        REQUIRE_FALSE(ended);
        CHECK(WIFEXITED(st));
        CHECK(WEXITSTATUS(st) == 75);
        CHECK(fs::exists(ckpt));
        CHECK_FALSE(fs::exists(out / "summary.json"));
        CHECK_THAT(read_file(log), Catch::Matchers::Contains("suspended: " + name + " received"));
    };
    stop_session_with(SIGTERM, "SIGTERM");
    stop_session_with(SIGHUP, "SIGHUP");

    // under nohup (SIGHUP ignored when the run starts) a hang-up does not stop the run: it finishes
    struct sigaction ignore {}, previous {};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGHUP, &ignore, &previous);
    const pid_t nohup_pid = spawn_demcal("--resume '" + out.string() + "' --threads 2", dir / "nohup.log");
    ::sigaction(SIGHUP, &previous, nullptr);
    REQUIRE(nohup_pid > 0);
    int nohup_status = 0;
    const bool ended_early = wait_until(
        nohup_pid, [&] { return read_file(dir / "nohup.log").find("resumed") != std::string::npos; }, nohup_status);
    if (!ended_early) {
        ::kill(nohup_pid, SIGHUP);
        ::waitpid(nohup_pid, &nohup_status, 0);
    }
    INFO(read_file(dir / "nohup.log"));
    REQUIRE_FALSE(ended_early);
    REQUIRE(WIFEXITED(nohup_status));
    REQUIRE(WEXITSTATUS(nohup_status) == 0);
    CHECK(read_file(out / "discharge.csv") == read_file(dir / "whole" / "discharge.csv"));
    const std::string summary = read_file(out / "summary.json");
    // the first, the wall-limited one, the one on its own session options, SIGTERM's, SIGHUP's and nohup's
    CHECK_THAT(summary, Catch::Matchers::Contains("\"sessions\": 6"));
    CHECK_THAT(summary, Catch::Matchers::Contains("\"cpu_sessions\": 6"));
    // the CPU split at the opening survives the sessions: the filling's part from the checkpoint
    const auto j = nlohmann::json::parse(summary);
    const double fill_cpu = j["fill"]["cpu_s"].get<double>(), discharge_cpu = j["discharge"]["cpu_s"].get<double>();
    CHECK(fill_cpu > 0);
    CHECK(discharge_cpu > 0);
    CHECK(fill_cpu + discharge_cpu == Approx(j["cpu_s"].get<double>()).epsilon(1e-12));
    CHECK_FALSE(fs::exists(ckpt));  // removed once the outputs are written
    const Run finished_run = run_silo("--resume '" + out.string() + "'", dir);
    CHECK(finished_run.rc == 2);
    CHECK_THAT(finished_run.err, Catch::Matchers::Contains("that run has finished"));
    fs::remove_all(dir);
}
