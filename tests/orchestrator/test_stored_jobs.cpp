// Jobs kept in the campaign store that are not shear runs (orchestrator/stored_jobs): a finished job is reused while
// its outputs are there, a job refused for its input (exit 2) fails for good, any other failure is tried again by the
// next call, and a run left "running" by a dead orchestrator is recovered by CampaignDirectory (done when its result
// is in its folder). Real processes (sh) through the local executor, a real SQLite store.
#include "orchestrator/campaign_directory.hpp"
#include "orchestrator/stored_jobs.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

using namespace demcal::orchestrator;
namespace fs = std::filesystem;

namespace {

StoredJob shell_job(const fs::path& root, const std::string& name, const std::string& script) {
    fs::create_directories(root / name);
    return stored_job(name, {{"script", script}}, {{"job", name}}, root / name, {"sh", "-c", script}, "result.json",
                      60);
}

// The commands open their campaign folder (its store) before they make their jobs' folders; a folder of folders
// without a store is refused (check_campaign_folder).
void open_store_first(const fs::path& root) { CampaignDirectory made(root, stored_job_result); }

std::map<std::string, std::string> run_all(CampaignDirectory& d, const std::vector<StoredJob>& jobs,
                                           StoredJobsOutcome& out) {
    std::map<std::string, std::string> events;
    LocalExecutor executor(2);
    const auto id = d.store().ensure_campaign("test", CampaignKind::crosscheck_silo, nlohmann::json::object()).id;
    out = run_stored_jobs(d.store(), id, jobs, executor,
                          [&](const std::string& e, const StoredJob& j, const std::string&) { events[j.name] = e; });
    return events;
}

}  // namespace

TEST_CASE("stored jobs: reuse, failure for good on exit 2, retry of other failures, outputs checked", "[store]") {
    const fs::path root = fs::temp_directory_path() / ("demcal-test-stored-jobs-" + std::to_string(::getpid()));
    fs::remove_all(root);
    open_store_first(root);
    std::vector<StoredJob> jobs = {shell_job(root, "good", "echo '{\"x\": 1}' > result.json && touch other.out"),
                                   shell_job(root, "refused", "exit 2"),
                                   shell_job(root, "flaky", "if [ -e ../flaky.ok ]; then echo '{}' > result.json; "
                                                            "else exit 1; fi")};
    jobs[0].outputs = {root / "good" / "other.out"};
    {
        CampaignDirectory d(root, stored_job_result);
        StoredJobsOutcome out;
        auto events = run_all(d, jobs, out);
        CHECK(events["good"] == "done");
        CHECK(events["refused"] == "failed");
        CHECK(events["flaky"] == "retry later");
        CHECK(out.executed == 1);
        CHECK(out.failed == 1);
        CHECK(out.pending == 1);
        const auto good = d.store().run(jobs[0].hash);
        REQUIRE(good);
        CHECK(good->state == RunState::done);
        CHECK(good->result["x"] == 1);
        CHECK(d.store().run(jobs[1].hash)->state == RunState::failed);
        CHECK(d.store().run(jobs[2].hash)->state == RunState::pending);
        CHECK(d.store().run(jobs[2].hash)->attempts == 1);
    }
    std::ofstream(root / "flaky.ok") << "";
    fs::remove(root / "good" / "other.out");  // an output gone: the job runs again
    {
        CampaignDirectory d(root, stored_job_result);
        StoredJobsOutcome out;
        auto events = run_all(d, jobs, out);
        CHECK(events["good"] == "done");
        CHECK(events.count("refused") == 0);  // failed for good: not started again
        CHECK(events["flaky"] == "done");
        CHECK(d.store().run(jobs[2].hash)->attempts == 2);
    }
    {
        CampaignDirectory d(root, stored_job_result);
        StoredJobsOutcome out;
        auto events = run_all(d, jobs, out);
        CHECK(events.empty());  // all reused or failed for good
        CHECK(out.reused == 2);
        // a run marked running by an orchestrator that died after the job wrote its result: done on reopening
        d.store().mark_running(jobs[0].hash, 999999, 999999, "local");
    }
    {
        CampaignDirectory d(root, stored_job_result);
        CHECK(d.store().run(jobs[0].hash)->state == RunState::done);
        d.store().mark_running(jobs[2].hash, 999999, 999999, "local");
        fs::remove(root / "flaky" / "result.json");
    }
    CampaignDirectory d(root, stored_job_result);  // ... and without its result: back to pending
    CHECK(d.store().run(jobs[2].hash)->state == RunState::pending);
    // the lock is held: refused as bad input (exit 2 in every command), naming the folder
    CHECK_THROWS_AS(CampaignDirectory(root, stored_job_result), std::invalid_argument);
    fs::remove_all(root);
}

TEST_CASE("stored jobs: a result file nested 100000 deep or with a repeated key is a damaged result, not a crash",
          "[store]") {
    // the result is read back on every reuse and recovery: a file damaged (or planted) in a run folder must cost a
    // rerun, never the orchestrator; the JSON reader's depth limit is what keeps the parse and the store's dump bounded
    const fs::path root = fs::temp_directory_path() / ("demcal-test-stored-deep-" + std::to_string(::getpid()));
    fs::remove_all(root);
    open_store_first(root);
    const std::string deep = "python3 -c \"print('[' * 100000 + ']' * 100000)\" > result.json";
    std::vector<StoredJob> jobs = {shell_job(root, "deep", deep),
                                   shell_job(root, "twice", "echo '{\"x\": 1, \"x\": 2}' > result.json")};
    CampaignDirectory d(root, stored_job_result);
    StoredJobsOutcome out;
    auto events = run_all(d, jobs, out);
    for (const auto& job : jobs) {
        INFO(job.name);
        CHECK(events[job.name] == "retry later");
        const auto run = d.store().run(job.hash);
        REQUIRE(run);
        CHECK(run->state == RunState::pending);
        CHECK(run->cause == "no_result");
    }
    CHECK(out.executed == 0);
    fs::remove_all(root);
}

TEST_CASE("stored jobs: a done job whose result file is no longer the result the store recorded runs again",
          "[store]") {
    // YADE's silo.py writes no seal, and the cross-check's report reads the file: a file changed after the run (a bit
    // flipped, another run's result copied in) must not be reported as this run's
    const fs::path root = fs::temp_directory_path() / ("demcal-test-stored-changed-" + std::to_string(::getpid()));
    fs::remove_all(root);
    open_store_first(root);
    std::vector<StoredJob> jobs = {shell_job(root, "counted", "echo '{\"rate\": 0.25}' > result.json"),
                                   shell_job(root, "kept", "echo '{\"rate\": 0.5}' > result.json")};
    {
        CampaignDirectory d(root, stored_job_result);
        StoredJobsOutcome out;
        run_all(d, jobs, out);
        CHECK(out.executed == 2);
    }
    std::ofstream(root / "counted" / "result.json") << "{\"rate\": 0.35}\n";  // valid JSON, not the run's result
    CampaignDirectory d(root, stored_job_result);
    StoredJobsOutcome out;
    auto events = run_all(d, jobs, out);
    CHECK(events["counted"] == "done");  // ran again
    CHECK(events.count("kept") == 0);    // reused
    CHECK(out.reused == 1);
    CHECK(out.executed == 1);
    const auto run = d.store().run(jobs[0].hash);
    REQUIRE(run);
    CHECK(run->result["rate"] == 0.25);
    fs::remove_all(root);
}
