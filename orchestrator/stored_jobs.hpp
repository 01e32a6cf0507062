// Jobs of a campaign kept in the campaign store that are not shear runs (the silo cross-check's kernel and YADE
// runs): each is a run of the store (identity hash, params, label, run folder), so its state, result, timings and
// every attempt survive a crash, and `demcal status` lists it. A job whose run is done and whose result file is still
// in its folder is reused; one refused for its input (exit 2) is failed for good; any other failure goes back to
// pending, so the same command tries it again. The caller holds the campaign directory (CampaignDirectory).
#pragma once
#include "orchestrator/campaign_store.hpp"
#include "orchestrator/executor.hpp"

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace demcal::orchestrator {

struct StoredJob {
    std::string name;                    // for progress lines, e.g. "theta_30 yade"
    std::string hash;                    // the run's identity: sha256 of `params`
    nlohmann::json params;               // what the run depends on, stored with it
    nlohmann::json label;                // tags for reports (angle, code)
    std::filesystem::path dir;           // run folder; stdout.log and stderr.log go there
    std::vector<std::string> argv;       // command, run in `dir`
    std::string result_file;             // in `dir`, written (atomically) as the run's last act; read into the store
    std::vector<std::filesystem::path> outputs;  // further files it writes: a done run missing one runs again
    double timeout_s = 3600;
};

// Builds a StoredJob whose hash is sha256 of params.dump().
StoredJob stored_job(std::string name, nlohmann::json params, nlohmann::json label, std::filesystem::path dir,
                     std::vector<std::string> argv, std::string result_file, double timeout_s);

// The result a stored job left in its folder, if any: `result_file` parsed (for CampaignDirectory's recovery).
std::optional<nlohmann::json> stored_job_result(const RunRecord& run);

struct StoredJobsOutcome {
    int reused = 0, executed = 0, failed = 0, pending = 0;  // failed: for good; pending: to try again
    bool interrupted = false;
};

using StoredJobEvent = std::function<void(const std::string& event, const StoredJob& job, const std::string& detail)>;

// Registers the jobs in campaign `campaign_id` and runs those not done through `executor`. Events: "started",
// "done", "failed" (for good), "retry later", "interrupted"; detail: the wall time or the failure.
StoredJobsOutcome run_stored_jobs(CampaignStore& store, std::int64_t campaign_id, const std::vector<StoredJob>& jobs,
                                  Executor& executor, const StoredJobEvent& on_event = {});

}  // namespace demcal::orchestrator
