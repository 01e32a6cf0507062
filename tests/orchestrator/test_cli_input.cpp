// Bad input to the campaign commands (shear, sensitivity, calibrate, enlarge) through the real demcal binary: exit 2
// with the field and the value named, before a campaign directory exists or a previous result is touched; each case
// stops before YADE would start. And `demcal enlarge` writing its laws and their plot.
#include "campaign_test_support.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

namespace fs = std::filesystem;
using namespace demcal;
using Catch::Matchers::Contains;

TEST_CASE("campaign commands refuse bad input before the campaign directory exists", "[cli]") {
    const fs::path dir = test::fresh_test_dir("cli-input");
    const fs::path campaign = dir / "never";
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    struct Case {
        std::vector<std::string> args;
        std::string expect;
    };
    const std::vector<Case> cases{
        // a run's own fields, checked for every stress and for the last replicate's seed
        {{"shear", tiny, "-s", "2e10"}, "'normal_stress' = 20000000000.0"},
        {{"shear", tiny, "-s", "5e3", "--seed", "2147483647", "-r", "2"}, "--seed = 2147483647 with replicates = 2"},
        // NaN passed CLI11's own range checks
        {{"shear", tiny, "-s", "5e3", "--timeout", "nan"}, "--timeout: 'nan' is not a number"},
        {{"sensitivity", tiny, "-s", "5e3,inf", "--params", "friction_coefficient"}, "--normal-stress: 'inf' is not finite"},
        // an empty value was read as 0, a subnormal called "not a number", a seed above 2^63 clamped to 2^63 - 1
        {{"shear", tiny, "-s", "5e3", "--replicates", ""}, "--replicates: an empty value"},
        {{"sensitivity", tiny, "-s", "5e3,1e4", "--levels", ""}, "--levels: an empty value"},
        // a required option has no default to omit it for (probe 62b); a vertical tab is a blank
        {{"shear", tiny, "-s", ""}, "--normal-stress: an empty value (this option has no default: give a value)"},
        {{"shear", tiny, "-s", "5e3", "--template", " "}, "--template: ' ': blanks only, an empty value"},  // probe 63
        {{"shear", tiny, "-s", "5e3,\v1e4,x"}, "--normal-stress: 'x' is not a number"},
        // the option named (probe 62b: "target mu_b = '' is not a number")
        {{"calibrate", "--start", tiny, "--target", "mu_b = "}, "--target: target mu_b = '' is not a number"},
        {{"shear", tiny, "-s", "5e3", "--timeout", "1e-320"}, "--timeout: '1e-320' is subnormal"},
        // 1e99 s passed, and a SLURM campaign's --time in minutes overflowed a long
        {{"shear", tiny, "-s", "5e3", "--timeout", "1e99"}, "--timeout: 1e99 is not a number of seconds from 1 to 1e+07"},
        {{"shear", tiny, "-s", "5e3", "--timeout", "0.001"}, "--timeout: 0.001 is not a number of seconds from 1 to"},
        {{"crosscheck", "silo", "--theta", "30", "--timeout", "2e7"}, "--timeout: 2e7 is not a number of seconds from 1 to"},
        {{"shear", tiny, "-s", "5e3,1e-320"}, "--normal-stress: '1e-320' is subnormal"},
        {{"shear", tiny, "-s", "5e3", "--seed", "9223372036854775808"},
         "--seed: '9223372036854775808' is not an integer between 0 and 2147483647"},
        // an output path that cannot be written was found only after the whole calibration
        {{"calibrate", "--start", tiny, "--target", "mu_b=1.3,tau_c=800", "-o", "/"}, "--output = '/' is a folder"},
        {{"calibrate", "--start", tiny, "--target", "mu_b=1.3,tau_c=800", "-o", "/no/such/folder/m.json"},
         "the folder /no/such/folder does not exist"},
        // limits, named with the flag that lifts them (an absurd level count started millions of runs)
        {{"sensitivity", tiny, "-s", "5e3,1e4", "--levels", "2000000000"},
         "--levels: '2000000000' is not an integer between 3 and 101"},
        {{"sensitivity", tiny, "-s", "5e3,1e4", "--levels", "101", "-r", "1000", "--params", "friction_coefficient"},
         "1 parameters x 101 levels x 2 normal stresses x 1000 replicates = 202000 simulations, more than the limit "
         "--max-runs = 10000"},
        {{"shear", tiny, "-s", "5e3,1e4", "-r", "600", "--max-runs", "1000"},
         "shear: 2 normal stresses x 600 replicates = 1200"},
        {{"shear", tiny, "-s", "5e3,1e4", "-r", "600", "--max-runs", "1e9"}, "--max-runs: '1e9' is not an integer"},
        // C's conversion read "010" as octal 8 (review of stop 61: --particles 0400 ran 256 grains)
        {{"shear", tiny, "-s", "5e3,1e4", "-r", "010"}, "--replicates: '010' has a leading zero"},
        // a negative cohesion target or negative measured stresses were calibrated against
        {{"calibrate", "--start", tiny, "--target", "mu_b=0.5,tau_c=-800"}, "target tau_c = -800: tau_c must be >= 0"},
        {{"calibrate", "--start", tiny, "--measured", "5e3:-7000,1e4:13000,2e4:25000"},
         "measured point 1 (5000:-7000) TAU: -7000 Pa is negative"},
        // a measured line the README's rules refuse elsewhere: stresses 5 % apart (tau_c = -37 kPa was calibrated
        // against), an intercept wholly below 0, a trailing empty item (taken as nothing)
        {{"calibrate", "--start", tiny, "--measured", "4e3:3e3,4.1e3:4e3,4.2e3:5e3"},
         "the measured failure line's normal stresses: 4000 to 4200 Pa"},
        {{"calibrate", "--start", tiny, "--measured", "5e3:1000,1e4:6000,2e4:16000,5e3:1100,1e4:6100,2e4:16100"},
         "Pa: below 0, no bulk solid's cohesion"},
        // probe 62: a line so scattered that its interval on mu_b holds 0 "converged" at the start, --strict or not
        {{"calibrate", "--start", tiny, "--measured", "4e3:6500,6e3:5000,8e3:8000"},
         "the measured failure line's mu_b = 0.375 +/- 8.2"},
        {{"calibrate", "--start", tiny, "--measured", "4e3:3e3,6e3:4e3,8e3:5e3,"},
         "--measured = '4e3:3e3,6e3:4e3,8e3:5e3,' has an empty item"},
        // a stress no shear cell reaches (kPa typed as Pa twice) was fitted as a line
        {{"calibrate", "--start", tiny, "--measured", "5e3:4e3,1e4:8e3,2e13:13000"},
         "measured point 3 (2e+13:13000) SIGMA: 2e+13 Pa is above 1e+09 Pa"},
        {{"sensitivity", tiny, "-s", "5e3,1e4", "--params", "friction_coefficient", "--alpha", "2"}, "alpha = 2"},
        {{"sensitivity", tiny, "-s", "5e3,1e4", "--params", "particle_form", "--range", "particle_form=1:3"},
         "sensitivity level particle_form = 1.5"},
        {{"calibrate", "--start", tiny, "--target", "mu_b=1.3,tau_c=800", "--max-evaluations", "0"},
         "max-evaluations = 0"},
        {{"calibrate", "--start", tiny, "--target", "mu_b=1.3,tau_c=800", "--controls", "friction_coefficient"},
         "--controls: 1 given for 2 targets"},
        // the option named, not the study's field it fills
        {{"calibrate", "--start", tiny, "--target", "mu_b=1.3,tau_c=800", "--controls", "1,2"},
         "--controls: '1' is not a micromechanical parameter"},
        {{"sensitivity", tiny, "-s", "5e3,1e4", "--params", "friction_coefficient,Young"},
         "--params: 'Young' is not a micromechanical parameter"},
        {{"calibrate", "--start", tiny, "--target", "mu_b=1.3,tau_c=800", "--bounds", "friction_coefficient=-5:50"},
         "'friction_coefficient' = -5"},
        {{"calibrate", "--start", tiny, "--measured", "5e3x:7000,1e4:13000,2e4:25000"}, "--measured: point '5e3x:7000'"},
        // one point was told its stresses were not 20 % apart (probe 63)
        {{"calibrate", "--start", tiny, "--measured", "4e3:6500"},
         "--measured: the measured failure line has 1 point(s): a line and its 95 % interval need at least 3"},
    };
    for (const auto& c : cases) {
        std::vector<std::string> args = c.args;
        args.insert(args.end(), {"--campaign", campaign.string()});
        INFO(args[0] + " ... " + c.expect);
        const int rc = test::run_demcal(args, dir / "out.log");
        const std::string log = test::read_file(dir / "out.log");
        INFO(log);
        CHECK(rc == 2);
        CHECK_THAT(log, Contains(c.expect));
        CHECK_FALSE(fs::exists(campaign));
    }
    fs::remove_all(dir);
}

TEST_CASE("a calibration refused for its options leaves the previous log as it was", "[cli]") {
    const fs::path dir = test::fresh_test_dir("cli-calibrate-log");
    const fs::path log = dir / "calibration_log_surrogate.jsonl";
    const std::string previous = "{\"evaluation\": 1, \"kept\": true}\n";
    std::ofstream(log) << previous;
    const int rc = test::run_demcal({"calibrate", "--start", test::source_path("examples/materials/sand-tiny.json"),
                                     "--target", "mu_b=1.3,tau_c=800", "--grid-points", "1", "--method", "grid",
                                     "--campaign", dir.string()},
                                    dir / "out.log");
    INFO(test::read_file(dir / "out.log"));
    CHECK(rc == 2);
    CHECK_THAT(test::read_file(dir / "out.log"), Contains("--grid-points: '1' is not an integer between 2"));
    CHECK(test::read_file(log) == previous);
    CHECK_FALSE(fs::exists(dir / "campaign.sqlite"));
    fs::remove_all(dir);
}

TEST_CASE("demcal enlarge fits both laws and draws them, and refuses an output it cannot write first", "[cli]") {
    const fs::path dir = test::fresh_test_dir("cli-enlarge");
    auto material = nlohmann::json::parse(test::read_file(test::source_path("examples/materials/sand.json")));
    std::vector<std::string> files;
    // E = A r + B with A = 1e10 Pa/m, B = 5e6 Pa; nu = 0.01 r^-0.5
    for (double r : {0.0025, 0.003, 0.0035}) {
        material["particle_radius"] = r;
        material["young_modulus"] = 1e10 * r + 5e6;
        material["poisson_ratio"] = 0.01 / std::sqrt(r);
        files.push_back((dir / ("r" + std::to_string(files.size()) + ".json")).string());
        std::ofstream(files.back()) << material.dump();
    }
    auto args = files;
    args.insert(args.begin(), "enlarge");
    auto missing = args;
    missing.insert(missing.end(), {"-o", (dir / "no_such_folder" / "e.json").string()});
    CHECK(test::run_demcal(missing, dir / "missing.log") == 2);
    CHECK_THAT(test::read_file(dir / "missing.log"), Contains("does not exist"));
    args.insert(args.end(), {"-o", (dir / "e.json").string()});
    const int rc = test::run_demcal(args, dir / "out.log");
    INFO(test::read_file(dir / "out.log"));
    REQUIRE(rc == 0);
    const auto result = nlohmann::json::parse(test::read_file(dir / "e.json"));
    INFO(result.dump(1));
    CHECK(result["young_modulus"]["params"]["A"]["value"].get<double>() == Approx(1e10).epsilon(1e-6));
    CHECK(result["poisson_ratio"]["params"]["D"]["value"].get<double>() == Approx(0.5).epsilon(1e-6));
    CHECK(fs::file_size(dir / "e.png") > 1000);
    CHECK(fs::exists(dir / "e.dat"));
    fs::remove_all(dir);
}

TEST_CASE("every JSON input goes through one reader: deep nesting, duplicates and subnormals end in exit 2",
          "[cli][input]") {
    const fs::path dir = test::fresh_test_dir("cli-json-input");
    const fs::path campaign = dir / "never";
    const std::string deep = "{\"density\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
    struct Case {
        std::string text;
        std::string expect;
    };
    const std::vector<Case> cases{
        {deep, "nests deeper than 64 levels"},  // was a segmentation fault
        {R"({"density": 2600, "density": 1})", "field 'density' appears twice"},
        {R"({"timestep_fraction": 1e-320})", "field 'timestep_fraction' = 1e-320 is subnormal"},
    };
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    for (const auto& c : cases) {
        std::ofstream(dir / "bad.json") << c.text;
        for (const std::vector<std::string>& args :
             {std::vector<std::string>{"shear", (dir / "bad.json").string(), "-s", "5e3"},
              std::vector<std::string>{"sensitivity", (dir / "bad.json").string(), "-s", "5e3,1e4"},
              std::vector<std::string>{"calibrate", "--start", tiny, "--target", "mu_b=1.3,tau_c=800", "--sensitivity",
                                       (dir / "bad.json").string()},
              std::vector<std::string>{"predict", (dir / "bad.json").string()}}) {
            auto full = args;
            full.insert(full.end(), {"--campaign", campaign.string()});
            if (args[0] == "predict") full.resize(2);
            INFO(args[0] + ": " + c.expect);
            const int rc = test::run_demcal(full, dir / "out.log");
            const std::string log = test::read_file(dir / "out.log");
            INFO(log.substr(0, 500));
            CHECK(rc == 2);
            CHECK_THAT(log, Contains(c.expect));
            CHECK(log.size() < 1000);
            CHECK_FALSE(fs::exists(campaign));
        }
    }
    fs::remove_all(dir);
}

TEST_CASE("status and resume refuse a file that is not a demcal store without writing to it", "[cli][store]") {
    const fs::path dir = test::fresh_test_dir("cli-foreign-store");
    std::ofstream(dir / "campaign.sqlite").close();  // zero bytes: status said "nothing to do" and wrote tables
    for (const std::string command : {"status", "resume"}) {
        INFO(command);
        CHECK(test::run_demcal({command, dir.string()}, dir / "out.log") == 2);
        const std::string log = test::read_file(dir / "out.log");
        CHECK_THAT(log, Contains((dir / "campaign.sqlite").string()) && Contains("is empty (0 bytes)"));
        CHECK(fs::file_size(dir / "campaign.sqlite") == 0);
        CHECK_FALSE(fs::exists(dir / ".lock"));  // the folder as it was found: not even the lock file is left
    }
    fs::remove_all(dir);
}

TEST_CASE("a YADE path that is a folder, empty or not executable is refused before anything is written", "[cli]") {
    const fs::path dir = test::fresh_test_dir("cli-bad-yade");
    const fs::path campaign = dir / "never";
    std::ofstream(dir / "not-executable") << "#!/bin/sh\n";
    // YADE's generated launcher names its build's precision; a long-double build ran every run to its end and then
    // failed to write the result
    std::ofstream(dir / "yade-longdouble") << "#!/usr/bin/python3\nif(True==True):\n\timport mpmath\n"
                                              "\tmpmath.mp.dps=(int(18)+1)\n";
    fs::permissions(dir / "yade-longdouble", fs::perms::owner_all);
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    const std::vector<std::pair<std::string, std::string>> cases{
        {dir.string(), "is a folder, not a program"}, {"", "--yade: an empty value"},
        {(dir / "not-executable").string(), "is not executable"}, {(dir / "none").string(), "does not exist"},
        {(dir / "yade-longdouble").string(), "is a YADE build of 18-digit reals"}};
    for (const auto& [yade, expect] : cases) {
        INFO(yade);
        CHECK(test::run_demcal({"shear", tiny, "-s", "5e3", "--yade", yade, "--campaign", campaign.string()},
                               dir / "out.log") == 2);
        CHECK_THAT(test::read_file(dir / "out.log"), Contains(expect));
        CHECK_FALSE(fs::exists(campaign));
    }
    fs::remove_all(dir);
}

TEST_CASE("a campaign folder holds one YADE build's results: another launcher is refused before anything is written",
          "[cli][store]") {
    const fs::path dir = test::fresh_test_dir("cli-yade-build");
    const fs::path campaign = dir / "campaign";
    const fs::path first = test::write_stand_in_yade(dir);
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "5e3,1e4,2e4", "--yade", first.string(), "--campaign",
                              campaign.string(), "--jobs", "1"},
                             dir / "first.log") == 0);
    // the same runs (same script, same parameters) with another build: it would have reused the first one's results
    fs::create_directories(dir / "other");
    fs::copy_file(first, dir / "other" / "stand-in-yade");
    std::ofstream(dir / "other" / "stand-in-yade", std::ios::app) << "# another build\n";
    const auto stored = [&] {  // each run's identity and state, and the run folders
        std::vector<std::string> seen;
        for (const auto& r : test::stored_runs(campaign)) seen.push_back(r.hash + " " + orchestrator::to_string(r.state));
        for (const auto& e : fs::directory_iterator(campaign / "runs")) seen.push_back(e.path().filename().string());
        std::sort(seen.begin(), seen.end());
        return seen;
    };
    const auto before = stored();
    REQUIRE(before.size() == 6);
    for (const auto& args : {std::vector<std::string>{"shear", tiny, "-s", "5e3,1e4,2e4,3e4", "--campaign",
                                                      campaign.string(), "--jobs", "1"},
                             std::vector<std::string>{"resume", campaign.string()}}) {
        auto a = args;
        a.insert(a.end(), {"--yade", (dir / "other" / "stand-in-yade").string()});
        INFO(a[0]);
        const int rc = test::run_demcal(a, dir / "other.log");
        INFO(test::read_file(dir / "other.log"));
        if (a[0] == "shear") {
            CHECK(rc == 2);
            CHECK_THAT(test::read_file(dir / "other.log"),
                       Contains("is another YADE build than the one this campaign folder's results came from") &&
                           Contains(first.string()) && Contains("--yade"));
        } else {
            CHECK(rc == 0);  // nothing to resume: the campaign is complete, so nothing of the other build runs
        }
        CHECK(stored() == before);
    }
    // the build the results came from extends the campaign
    CHECK(test::run_demcal({"shear", tiny, "-s", "5e3,1e4,2e4,3e4", "--yade", first.string(), "--campaign",
                            campaign.string(), "--jobs", "1"},
                           dir / "again.log") == 0);
    fs::remove_all(dir);
}

TEST_CASE("a simulator that cannot start leaves the runs pending, and a resume with a working one runs them",
          "[cli][store]") {
    const fs::path dir = test::fresh_test_dir("cli-yade-not-started");
    const fs::path campaign = dir / "campaign";
    // executable, but its interpreter does not exist: execvp fails, as for a launcher of a broken installation; or it
    // starts and exits before the run's script (no started marker), as YADE without HOME does (KeyError: 'HOME')
    const auto [launcher, text, expect] = GENERATE(
        std::tuple<const char*, const char*, const char*>{"broken-yade", "#!/nonexistent/interpreter\n",
                                                          "cannot start"},
        std::tuple<const char*, const char*, const char*>{
            "early-exit-yade", "#!/bin/sh\necho \"KeyError: 'HOME'\" >&2\nexit 1\n",
            "the simulator exited (code 1) before it started the run: KeyError: 'HOME'"});
    std::ofstream(dir / launcher) << text;
    fs::permissions(dir / launcher, fs::perms::owner_all);
    const fs::path stand_in = test::write_stand_in_yade(dir);
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    fs::remove_all(campaign);
    const int rc = test::run_demcal({"shear", tiny, "-s", "5e3,1e4,2e4", "--yade", (dir / launcher).string(),
                                     "--campaign", campaign.string(), "--retries", "0", "--jobs", "1"},
                                    dir / "out.log");
    INFO(test::read_file(dir / "out.log"));
    CHECK(rc == 75);
    CHECK_THAT(test::read_file(dir / "out.log"), Contains("could not be started") && Contains(expect));
    // what the campaign has (it said "fewer than 3 finished runs on 2 normal stresses" of 0 runs on 3)
    CHECK_THAT(test::read_file(dir / "out.log"), Contains("no failure line: 0 finished runs on 0 normal stresses"));
    const auto runs = test::stored_runs(campaign);
    for (const auto& r : runs) CHECK(r.state == orchestrator::RunState::pending);
    // the first run that did not start stops the campaign: no other run is tried
    CHECK(std::count_if(runs.begin(), runs.end(), [](const auto& r) { return r.attempts > 0; }) == 1);
    CHECK(test::run_demcal({"resume", campaign.string(), "--yade", stand_in.string()}, dir / "resume.log") == 0);
    INFO(test::read_file(dir / "resume.log"));
    for (const auto& r : test::stored_runs(campaign)) CHECK(r.state == orchestrator::RunState::done);
    fs::remove_all(dir);
}

TEST_CASE("a study stopped by a simulator that cannot start exits 75 as a shear campaign does, not as a failure",
          "[cli][store]") {
    const fs::path dir = test::fresh_test_dir("cli-study-not-started");
    std::ofstream(dir / "broken-yade") << "#!/nonexistent/interpreter\n";
    fs::permissions(dir / "broken-yade", fs::perms::owner_all);
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    const int rc = test::run_demcal({"sensitivity", tiny, "-s", "5e3,1e4,2e4", "--params", "friction_coefficient",
                                     "--levels", "3", "--yade", (dir / "broken-yade").string(), "--retries", "0",
                                     "--jobs", "1", "--campaign", (dir / "campaign").string()},
                                    dir / "out.log");
    INFO(test::read_file(dir / "out.log"));
    CHECK(rc == 75);  // was 1, "failed", for the same stop that a shear campaign reports as "resume later"
    CHECK_THAT(test::read_file(dir / "out.log"), Contains("demcal: stopped: the simulator could not be started"));
    for (const auto& r : test::stored_runs(dir / "campaign")) CHECK(r.state == orchestrator::RunState::pending);
    // a crosscheck exited 75 saying nothing of why (its report's line was its last word)
    CHECK(test::run_demcal({"crosscheck", "shear", tiny, "-s", "3e3,4e3,5e3", "-r", "1", "--yade",
                            (dir / "broken-yade").string(), "--retries", "0", "-j", "1", "-c",
                            (dir / "cross").string()},
                           dir / "cross.log") == 75);
    CHECK_THAT(test::read_file(dir / "cross.log"),
               Contains("the simulator could not be started") && Contains("run the same command again"));
    fs::remove_all(dir);
}

TEST_CASE("demcal enlarge refuses a radius given twice (one file twice was fitted exactly) and writes nothing", "[cli]") {
    const fs::path dir = test::fresh_test_dir("cli-enlarge-same-radius");
    auto material = nlohmann::json::parse(test::read_file(test::source_path("examples/materials/sand.json")));
    std::vector<std::string> args{"enlarge", "--no-plot", "-o", (dir / "e.json").string()};
    for (double r : {0.0025, 0.003}) {
        material["particle_radius"] = r;
        material["young_modulus"] = 1e10 * r + 5e6;
        material["poisson_ratio"] = 0.01 / std::sqrt(r);
        args.push_back((dir / ("r" + std::to_string(args.size()) + ".json")).string());
        std::ofstream(args.back()) << material.dump();
    }
    args.push_back(args.back());  // two radii, three points: reported R^2 1 and intervals of 1e-15
    CHECK(test::run_demcal(args, dir / "out.log") == 2);
    CHECK_THAT(test::read_file(dir / "out.log"), Contains("both have particle_radius = 0.003 m"));
    CHECK_FALSE(fs::exists(dir / "e.json"));
    fs::remove_all(dir);
}

TEST_CASE("demcal enlarge says when the points do not determine the power law and writes nothing unless asked", "[cli]") {
    const fs::path dir = test::fresh_test_dir("cli-enlarge-unconverged");
    auto material = nlohmann::json::parse(test::read_file(test::source_path("examples/materials/sand.json")));
    std::vector<std::string> args{"enlarge", "--no-plot", "-o", (dir / "e.json").string()};
    for (double r : {0.0025, 0.003, 0.0035}) {  // nu the same at every radius: the fit reported D = -0 with exit 0
        material["particle_radius"] = r;
        material["young_modulus"] = 1e10 * r + 5e6;
        material["poisson_ratio"] = 0.2;
        args.push_back((dir / ("r" + std::to_string(args.size()) + ".json")).string());
        std::ofstream(args.back()) << material.dump();
    }
    CHECK(test::run_demcal(args, dir / "out.log") == 1);
    CHECK_THAT(test::read_file(dir / "out.log"), Contains("not determined") && Contains("the same value at every radius"));
    CHECK_FALSE(fs::exists(dir / "e.json"));
    args.push_back("--allow-unconverged");
    CHECK(test::run_demcal(args, dir / "out.log") == 0);
    CHECK_THAT(test::read_file(dir / "out.log"), !Contains("-0 "));
    CHECK(fs::exists(dir / "e.json"));
    fs::remove_all(dir);
}

TEST_CASE("a JSON result to standard output (--json -) comes alone there, the text on stderr", "[cli]") {
    // probe 61: --json /dev/stdout was refused ("not a regular file") and --json - wrote a file named -
    const fs::path dir = test::fresh_test_dir("cli-json-stdout");
    const std::string geometry = test::source_path("examples/diagnose/silo_105mm_wheat.json").string();
    const std::string data = test::source_path("examples/diagnose/oldal_moisture.csv").string();
    const auto run = [&dir](const std::string& args, const std::string& name) {
        const std::string cmd = "cd '" + dir.string() + "' && '" + DEMCAL_BINARY + "' " + args + " > " + name +
                                ".out 2> " + name + ".err";
        const int status = std::system(cmd.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    };
    for (const auto& [args, name] : std::vector<std::pair<std::string, std::string>>{
             {"predict '" + geometry + "' --json -", "predict"},
             {"predict '" + geometry + "' --json /dev/stdout", "predict_dev"},
             {"predict '" + geometry + "' --json /proc/thread-self/fd/1", "predict_thread"},  // (was refused)
             {"diagnose --model oldal --data '" + data + "' --json -", "diagnose"}}) {
        INFO(args);
        REQUIRE(run(args, name) == 0);
        const std::string out = test::read_file(dir / (name + ".out")), err = test::read_file(dir / (name + ".err"));
        INFO(err);
        nlohmann::json parsed;
        CHECK_NOTHROW(parsed = nlohmann::json::parse(out));  // the JSON alone
        CHECK(parsed.is_object());
        CHECK_FALSE(err.empty());  // the table went to stderr
    }
    CHECK_FALSE(fs::exists(dir / "-"));
    // a redirect's file is appended to, not replaced (a result file is written through a rename)
    const std::string appended = "cd '" + dir.string() + "' && (echo first; '" + DEMCAL_BINARY + "' predict '" +
                                 geometry + "' --json /dev/stdout 2>/dev/null) > appended.out";
    REQUIRE(std::system(appended.c_str()) == 0);
    CHECK(test::read_file(dir / "appended.out").rfind("first\n{", 0) == 0);
    // a standard output that refuses the JSON: exit 1, the reason named once (probe 62b: no reason); a stderr that
    // refuses the report: exit 1 (it was 0)
    const auto full = [&](const std::string& redirect) {
        const std::string cmd = "cd '" + dir.string() + "' && '" + DEMCAL_BINARY + "' predict '" + geometry +
                                "' --json - " + redirect;
        const int status = std::system(cmd.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    };
    CHECK(full("> /dev/full 2> full.err") == 1);
    const std::string full_err = test::read_file(dir / "full.err");
    CHECK_THAT(full_err, Contains("the JSON result could not be written to standard output (No space left on device)"));
    CHECK(full_err.find("demcal: error: the standard output") == std::string::npos);  // said once
    CHECK(full("> stdout.out 2> /dev/full") == 1);
    // the file standard output is redirected to is standard output: the JSON is added there, the text goes to stderr
    // (it replaced the text, exit 0, probe 63); as a report it is refused
    CHECK(run("predict '" + geometry + "' --json same.out", "same") == 0);
    CHECK_NOTHROW(nlohmann::json::parse(test::read_file(dir / "same.out")));
    CHECK_THAT(test::read_file(dir / "same.err"), Contains("beverloo"));
    // ... unless stderr is that file too: the JSON would be mixed into the text (review of stop 63)
    const std::string mixed = "cd '" + dir.string() + "' && '" + DEMCAL_BINARY + "' predict '" + geometry +
                              "' --json mixed.out > mixed.out 2>&1";
    const int mixed_status = std::system(mixed.c_str());
    CHECK((WIFEXITED(mixed_status) && WEXITSTATUS(mixed_status) == 2));
    CHECK_THAT(test::read_file(dir / "mixed.out"), Contains("standard error is the same file here"));
    CHECK(run("diagnose --model oldal --data '" + data + "' --report report.out --no-plots", "report") == 2);
    CHECK_THAT(test::read_file(dir / "report.err"), Contains("is the file standard output is redirected to"));
    // a folder's name, /dev/stdout/ too, is no output file (it was "the folder /dev/stdout does not exist")
    CHECK(run("predict '" + geometry + "' --json /dev/stdout/", "slash") == 2);
    CHECK_THAT(test::read_file(dir / "slash.err"), Contains("--json = '/dev/stdout/' ends with '/', a folder's name"));
    fs::remove_all(dir);
}
