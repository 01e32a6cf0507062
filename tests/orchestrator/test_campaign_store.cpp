#include "orchestrator/campaign_store.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <unistd.h>

using namespace demcal::orchestrator;
namespace fs = std::filesystem;

namespace {
fs::path fresh_dir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("demcal-test-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}
}  // namespace

TEST_CASE("the store keeps runs, states, results and attempts across reopening", "[store]") {
    const fs::path d = fresh_dir("store");
    std::int64_t cid;
    {
        CampaignStore s(d / "c.sqlite");
        cid = s.ensure_campaign("c1", "shear", {{"x", 1}}).id;
        CHECK(s.ensure_campaign("c1", "shear", {{"x", 2}}).id == cid);  // same name, same campaign
        s.ensure_run(cid, "h1", {{"normal_stress", 1e4}}, d / "runs/h1", {{"replicate", 0}});
        s.ensure_run(cid, "h2", {{"normal_stress", 2e4}}, d / "runs/h2", {{"replicate", 0}});
        s.ensure_run(cid, "h1", {{"normal_stress", 1e4}}, d / "runs/h1", {{"replicate", 0}});  // no duplicate
        s.mark_running("h1", 1234, ::getpid(), "local");
        s.mark_done("h1", {{"peak_shear_stress", 5000.0}}, 0, 12.5, 12.0);
        s.mark_running("h2", 1235, ::getpid(), "local");
        s.mark_attempt_failed("h2", "timeout", "killed", -1, 60, 59, false);
        s.mark_running("h2", 1236, ::getpid(), "local");  // the retry; then the process dies with us
    }
    CampaignStore s(d / "c.sqlite");
    const auto runs = s.campaign_runs(cid);
    REQUIRE(runs.size() == 2);
    CHECK(runs[0].hash == "h1");
    CHECK(runs[0].state == RunState::done);
    CHECK(runs[0].result["peak_shear_stress"].get<double>() == 5000.0);
    CHECK(runs[0].wall_s == 12.5);
    CHECK(runs[1].state == RunState::running);
    CHECK(runs[1].attempts == 2);
    CHECK(runs[1].pgid == 1236);
    const auto att = s.attempts("h2");
    REQUIRE(att.size() == 2);
    CHECK(att[0].cause == "timeout");
    s.reset_to_pending("h2", "orchestrator died");
    CHECK(s.run("h2")->state == RunState::pending);
    CHECK(s.attempts("h2").back().cause == "interrupted");
    CHECK(s.runs_in_state(RunState::running).empty());
    fs::remove_all(d);
}

TEST_CASE("a run that wrote its result just before the orchestrator died is kept as done on reopening", "[store]") {
    const fs::path d = fresh_dir("stale-runs");
    std::int64_t cid;
    {
        CampaignStore s(d / "campaign.sqlite");
        cid = s.ensure_campaign("c1", "shear", {{"x", 1}}).id;
        for (const std::string h : {"finished", "unfinished", "garbled"}) {
            fs::create_directories(d / "runs" / h);
            s.ensure_run(cid, h, {{"normal_stress", 1e4}}, d / "runs" / h, {{"replicate", 0}});
            s.mark_running(h, 999999, 999999, "local");  // no such process group: the orchestrator died with it
        }
    }
    demcal::orchestrator::write_text_file_atomically(d / "runs/finished/result.json",
                                                     R"({"peak_shear_stress": 4321.0, "wall_time_s": 17.5})");
    demcal::orchestrator::write_text_file_atomically(d / "runs/garbled/result.json", R"({"peak_shear_st)");
    { ShearCampaignRunner reopened(d, ExecutionOptions{}); }
    CampaignStore s(d / "campaign.sqlite");
    const auto finished = s.run("finished");
    REQUIRE(finished);
    CHECK(finished->state == RunState::done);
    CHECK(finished->result.at("peak_shear_stress").get<double>() == 4321.0);
    CHECK(finished->wall_s == 17.5);
    CHECK(s.run("unfinished")->state == RunState::pending);
    CHECK(s.run("garbled")->state == RunState::pending);  // a partial file is not a result
    fs::remove_all(d);
}
