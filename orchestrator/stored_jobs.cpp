#include "orchestrator/stored_jobs.hpp"

#include "orchestrator/run_identity.hpp"

#include <unistd.h>

#include <deque>
#include <fstream>
#include <map>
#include <sstream>

namespace demcal::orchestrator {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The result file as JSON, or nothing when it is absent or not JSON (a run that did not finish), breaks the input
// rules (too large, nested too deep, a repeated key) or fails its seal: read as shear results are, so that a file
// damaged or planted in a run folder costs a rerun, not the orchestrator.
std::optional<json> read_result(const fs::path& file) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return std::nullopt;
    try {
        return read_result_json(file, "result '" + file.string() + "'");
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

// Why a job the store has as done must run again, or "" to reuse it: its result file gone or damaged, not the result
// the store recorded when the run ended (a result file that carries no seal, e.g. YADE's silo.py's, is checked this
// way: a report reads the file, so a file changed since would be reported as the run's), or another output gone.
std::string why_done_job_is_stale(const StoredJob& job, const RunRecord& rec) {
    const fs::path file = job.dir / job.result_file;
    const std::optional<json> now = read_result(file);
    if (!now) return "its output " + file.string() + " is gone or damaged";
    if (!rec.result.is_null() && *now != rec.result)
        return "its output " + file.string() + " is not the result recorded when the run ended";
    for (const auto& f : job.outputs)
        if (!fs::exists(f)) return "its output " + f.string() + " is gone";
    return "";
}

std::string seconds_text(double s) {
    std::ostringstream o;
    o.precision(3);
    o << s << " s";
    return o.str();
}

}  // namespace

StoredJob stored_job(std::string name, json params, json label, fs::path dir, std::vector<std::string> argv,
                     std::string result_file, double timeout_s) {
    params["result_file"] = result_file;  // part of the identity, and how a recovery finds the result
    StoredJob j;
    j.name = std::move(name);
    j.hash = sha256_hex(params.dump());
    j.params = std::move(params);
    j.label = std::move(label);
    j.dir = std::move(dir);
    j.argv = std::move(argv);
    j.result_file = std::move(result_file);
    j.timeout_s = timeout_s;
    return j;
}

std::optional<json> stored_job_result(const RunRecord& run) {
    if (!run.params.is_object() || !run.params.contains("result_file") || !run.params["result_file"].is_string())
        return std::nullopt;
    return read_result(run.run_dir / run.params["result_file"].get<std::string>());
}

StoredJobsOutcome run_stored_jobs(CampaignStore& store, std::int64_t campaign_id, const std::vector<StoredJob>& jobs,
                                  Executor& executor, const StoredJobEvent& on_event) {
    auto event = [&](const std::string& what, const StoredJob& job, const std::string& detail) {
        if (on_event) on_event(what, job, detail);
    };
    StoredJobsOutcome out;
    std::deque<const StoredJob*> queue;
    std::map<std::string, const StoredJob*> by_hash;
    std::vector<CampaignStore::RunEntry> entries;
    for (const StoredJob& job : jobs)
        if (by_hash.emplace(job.hash, &job).second)  // the same run twice: once
            entries.push_back({job.hash, job.params, job.dir, job.label});
    // every run stored in one transaction: a kill leaves all of them or none (probe 64 D5)
    const std::vector<RunRecord> records = store.ensure_runs(campaign_id, entries);
    for (std::size_t i = 0; i < entries.size(); ++i) {
        const StoredJob& job = *by_hash.at(entries[i].hash);
        RunRecord rec = records[i];
        if (rec.state == RunState::done) {
            const std::string why = why_done_job_is_stale(job, rec);
            if (!why.empty()) {
                store.reset_to_pending(job.hash, why);
                rec.state = RunState::pending;
            }
        }
        if (rec.state == RunState::done) ++out.reused;
        if (rec.state == RunState::failed) ++out.failed;
        if (rec.state == RunState::pending) queue.push_back(&job);
    }
    ExecutorEvents events;
    events.started = [&](const Job& j, long handle) {
        store.mark_running(j.id, handle, ::getpid(), executor.name());
        event("started", *by_hash.at(j.id), "");
    };
    events.finished = [&](const Job& j, const JobOutcome& o) {
        const StoredJob& job = *by_hash.at(j.id);
        if (o.interrupted) {
            store.reset_to_pending(j.id, "interrupted by the user");
            out.interrupted = true;
            ++out.pending;
            event("interrupted", job, "");
            return;
        }
        std::string cause = o.failure_cause, message = o.message;
        std::optional<json> result;
        if (o.succeeded()) {
            result = read_result(job.dir / job.result_file);
            if (!result) cause = "no_result", message = "exit code 0 but " + job.result_file + " is missing or damaged";
        } else if (cause.empty()) {
            cause = o.timed_out ? "timeout" : "exit_code";
            message = (o.timed_out ? "timed out after " + seconds_text(o.wall_s) : "exit code " + std::to_string(o.exit_code)) +
                      (message.empty() ? "" : ": " + message);
        }
        if (result) {
            store.mark_done(j.id, *result, o.exit_code, o.wall_s, o.cpu_s);
            ++out.executed;
            event("done", job, seconds_text(o.wall_s));
            return;
        }
        // its input was refused, or its output ran away: the same job fails the same way
        const bool final = o.exit_code == 2 || cause == kOutputLimitCause;
        store.mark_attempt_failed(j.id, cause, message, o.exit_code, o.wall_s, o.cpu_s, final);
        ++(final ? out.failed : out.pending);
        event(final ? "failed" : "retry later", job, cause + ": " + message);
    };
    JobSource next = [&]() -> std::optional<Job> {
        if (queue.empty()) return std::nullopt;
        const StoredJob& job = *queue.front();
        queue.pop_front();
        fs::remove(job.dir / job.result_file);  // a result must come from this attempt
        for (const auto& f : job.outputs) fs::remove(f);
        return Job{job.hash, job.dir, job.argv, job.timeout_s};
    };
    InterruptGuard guard;
    if (!queue.empty()) executor.run(next, events);
    if (interrupted()) out.interrupted = true;
    return out;
}

}  // namespace demcal::orchestrator
