// Campaigns over real YADE runs of the tiny shear box (examples/materials/sand-tiny.json, a few hundred particles).
#include "campaign_test_support.hpp"
#include "orchestrator/run_identity.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <csignal>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

using namespace demcal;
using orchestrator::RunState;
namespace fs = std::filesystem;

namespace {
const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();

std::map<double, orchestrator::RunRecord> by_stress(const std::vector<orchestrator::RunRecord>& runs) {
    std::map<double, orchestrator::RunRecord> m;
    for (const auto& r : runs) m[r.label.at("normal_stress").get<double>()] = r;
    return m;
}
}  // namespace

TEST_CASE("a tiny YADE shear campaign gives positive peaks and a failure line, and is never computed twice",
          "[yade]") {
    const fs::path dir = test::fresh_test_dir("tiny-campaign");
    const std::vector<std::string> args{"shear", tiny, "--normal-stress", "2e3,4e3,6e3", "--jobs", "2",
                                        "--campaign", dir.string()};
    REQUIRE(test::run_demcal(args, dir / "first.log") == 0);
    const std::string first = test::read_file(dir / "first.log");
    INFO(first);
    CHECK(first.find("Peak failure line") != std::string::npos);
    const auto runs = test::stored_runs(dir);
    REQUIRE(runs.size() == 3);
    for (const auto& r : runs) {
        CHECK(r.state == RunState::done);
        const double peak = r.result.at("peak_shear_stress").get<double>();
        CHECK(std::isfinite(peak));
        CHECK(peak > 0);
        CHECK(r.result.at("particle_count").get<int>() > 100);
        // The run directory repeats by hand: the generated script and its parameters are there.
        CHECK(fs::exists(r.run_dir / "shear_box.py"));
        CHECK(nlohmann::json::parse(test::read_file(r.run_dir / "params.json")) == r.params);
        // the result records the parameters it ran (schema /3): the orchestrator knows it for this run's
        CHECK(r.result.at("schema") == orchestrator::kShearResultSchema);
        CHECK(orchestrator::params_digest(r.result.at("params")) == orchestrator::params_digest(r.params));
        // YADE's own /tmp/yade-XXXXXX of this run is gone (run_clean.py): a campaign leaves nothing in /tmp
        const std::string out = test::read_file(r.run_dir / "stdout.log");
        const std::string mark = "run_clean: removed YADE's temporary directory ";
        const auto at = out.find(mark);
        REQUIRE(at != std::string::npos);
        const std::string tmp = out.substr(at + mark.size(), out.find('\n', at) - at - mark.size());
        CHECK(tmp.rfind("/tmp/yade-", 0) == 0);
        CHECK_FALSE(fs::exists(tmp));
    }
    const fs::path json_path = test::find_file(dir, "failure_line_", ".json");
    REQUIRE_FALSE(json_path.empty());
    const auto result = nlohmann::json::parse(test::read_file(json_path));
    const double mu_b = result.at("peak_failure_line").at("mu_b").get<double>();
    CHECK(std::isfinite(mu_b));
    CHECK(fs::exists(fs::path(json_path).replace_extension(".png")));

    // The same parameters: same identities, nothing computed again.
    REQUIRE(test::run_demcal(args, dir / "second.log") == 0);
    const std::string second = test::read_file(dir / "second.log");
    INFO(second);
    CHECK(second.find("0 computed now, 3 reused") != std::string::npos);
    for (const auto& r : test::stored_runs(dir)) CHECK(r.attempts == 1);
    fs::remove_all(dir);
}

TEST_CASE("a run whose script raises is recorded as failed and a hanging run is killed at its timeout while the "
          "others finish", "[yade]") {
    const fs::path dir = test::fresh_test_dir("failing-campaign");
    // A template that is the real shear box, preceded by two deliberate faults chosen by the normal stress.
    const std::string faults =
        "import json, time\n"
        "_p = json.load(open('params.json'))\n"
        "if _p['normal_stress'] == 1000: raise RuntimeError('deliberate failure for the test')\n"
        "if _p['normal_stress'] == 1500: time.sleep(3600)\n";
    const fs::path tmpl = dir / "faulty_shear_box.py";
    orchestrator::write_text_file_atomically(
        tmpl, faults + test::read_file(test::source_path("yade_scripts/shear_box.py")));
    // Long enough for a tiny run on a loaded 2-core machine (15-30 s alone, 45 s seen under load); the other worker
    // finishes the three good runs meanwhile, so the hang costs little extra time.
    const double timeout = 90;
    const int code = test::run_demcal({"shear", tiny, "--normal-stress", "1000,1500,2e3,4e3,6e3", "--jobs", "2",
                                       "--retries", "0", "--timeout", std::to_string(timeout), "--template",
                                       tmpl.string(), "--campaign", (dir / "c").string()},
                                      dir / "run.log");
    const std::string log = test::read_file(dir / "run.log");
    INFO(log);
    CHECK(code == 1);  // failures are reported in the exit code
    auto runs = by_stress(test::stored_runs(dir / "c"));
    REQUIRE(runs.size() == 5);
    CHECK(runs[1000].state == RunState::failed);
    CHECK(runs[1000].message.find("deliberate failure for the test") != std::string::npos);
    CHECK(runs[1500].state == RunState::failed);
    CHECK(runs[1500].cause == "timeout");
    CHECK(runs[1500].wall_s >= timeout);
    CHECK(runs[1500].wall_s < timeout + 15);
    for (double s : {2e3, 4e3, 6e3}) CHECK(runs[s].state == RunState::done);
    CHECK(log.find("Peak failure line") != std::string::npos);  // fitted on the three that finished
    CHECK(test::processes_under(dir).empty());
    fs::remove_all(dir);
}

TEST_CASE("kill -9 of the orchestrator mid-campaign, then resume: nothing finished is lost or run again", "[yade]") {
    const fs::path dir = test::fresh_test_dir("killed-campaign");
    const fs::path cdir = dir / "c";
    const int pid = test::spawn_demcal({"shear", tiny, "--normal-stress", "2e3,3e3,4e3,5e3", "--jobs", "2",
                                        "--campaign", cdir.string()},
                                       dir / "killed.log");
    // Wait until at least one run is done and another is running, then kill the orchestrator outright.
    std::map<std::string, nlohmann::json> done_before;
    for (int i = 0; i < 600 && done_before.empty(); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        if (!fs::exists(cdir / "campaign.sqlite")) continue;
        for (const auto& r : test::stored_runs(cdir))
            if (r.state == RunState::done) done_before[r.hash] = r.result;
    }
    REQUIRE_FALSE(done_before.empty());
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    CHECK(test::processes_under(cdir).empty());  // its YADE runs died with it
    for (const auto& r : test::stored_runs(cdir))
        if (r.state == RunState::done) done_before[r.hash] = r.result;  // anything committed up to the kill
    REQUIRE(done_before.size() < 4);
    // status sees that no demcal holds the folder: the runs left "running" are named interrupted, not running
    REQUIRE(test::run_demcal({"status", cdir.string()}, dir / "status.log") == 0);
    CHECK_THAT(test::read_file(dir / "status.log"), Catch::Matchers::Contains("interrupted (no demcal holds"));
    CHECK_THAT(test::read_file(dir / "status.log"), !Catch::Matchers::Contains(" running"));

    REQUIRE(test::run_demcal({"resume", cdir.string()}, dir / "resume.log") == 0);
    INFO(test::read_file(dir / "resume.log"));
    const auto after = test::stored_runs(cdir);
    REQUIRE(after.size() == 4);
    for (const auto& r : after) {
        CHECK(r.state == RunState::done);
        if (done_before.count(r.hash)) {
            CHECK(r.attempts == 1);                 // not run again
            CHECK(r.result == done_before[r.hash]);  // and not lost
        }
    }
    fs::remove_all(dir);
}
