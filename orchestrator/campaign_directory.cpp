#include "orchestrator/campaign_directory.hpp"

#include "analytics/number_text.hpp"
#include "orchestrator/executor.hpp"
#include "orchestrator/slurm_executor.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace demcal::orchestrator {

namespace fs = std::filesystem;

void check_campaign_folder(const fs::path& dir, const std::string& marker) {
    if (analytics::has_control_character(dir.string()))
        throw std::invalid_argument("campaign = '" + analytics::shortened_text(dir.string(), 200) +
                                    "': the path holds a control character (a newline, a tab): no batch script, plot "
                                    "or log line can name it; give a path without one (a campaign resumes where it "
                                    "is moved)");
    std::error_code ec;
    // a link whose target is gone: creating the folder failed with "File exists" (probe 60)
    if (fs::is_symlink(fs::symlink_status(dir, ec)) && !fs::exists(dir, ec))
        throw std::invalid_argument("campaign = '" + analytics::shortened_text(dir.string(), 200) +
                                    "' is a symbolic link to '" +
                                    analytics::shortened_text(fs::read_symlink(dir, ec).string(), 200) +
                                    "', which does not exist: make its target, or give another folder");
    if (!fs::is_directory(dir, ec) || fs::exists(dir / marker, ec)) return;
    std::vector<std::string> folders;
    std::size_t count = 0;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        std::error_code type_ec;
        if (!it->is_directory(type_ec)) continue;  // a file: a console log, a batch system's output (sbatch -o DIR/..)
        if (folders.size() < 3) folders.push_back(analytics::shortened_text(it->path().filename().string(), 40));
        ++count;
    }
    if (ec)
        throw std::invalid_argument("campaign = '" + analytics::shortened_text(dir.string(), 200) +
                                    "': cannot list the folder: " + ec.message());
    if (count == 0) return;
    std::string listed;
    for (const auto& name : folders) listed += (listed.empty() ? "" : ", ") + name + "/";
    if (count > folders.size()) listed += ", ... " + std::to_string(count) + " in all";
    throw std::invalid_argument("campaign = '" + analytics::shortened_text(dir.string(), 200) + "': holds other "
                                "folders (" + listed + ") and no campaign (no " + marker + "): give a new folder, "
                                "one with files only (a console log), or a campaign's folder to continue it");
}

CampaignDirectory::CampaignDirectory(const fs::path& dir, const FinishedResult& finished)
    : dir_(fs::absolute(dir).lexically_normal()) {
    std::error_code ec;
    check_campaign_folder(dir_, "campaign.sqlite");
    // a store this demcal refuses is refused before anything is written: the lock file, the folder, the store
    if (fs::exists(dir_ / "campaign.sqlite", ec)) CampaignStore(dir_ / "campaign.sqlite", StoreAccess::read_only);
    CampaignStore::check_store_path(dir_ / "campaign.sqlite");
    fs::create_directories(dir_, ec);  // the first thing a campaign writes: a folder it cannot make is bad input
    if (ec || !fs::is_directory(dir_))
        throw std::invalid_argument("campaign = '" + analytics::shortened_text(dir.string(), 200) +
                                    "': cannot create the campaign folder" + (ec ? ": " + ec.message() : std::string()));
    lock_ = std::make_unique<FolderLock>(dir_, "campaign directory");
    try {
        store_ = std::make_unique<CampaignStore>(dir_ / "campaign.sqlite");
    } catch (...) {
        // a file that is not our store was refused: leave its folder as it was found (no lock file of ours in it)
        lock_->release_and_forget();
        throw;
    }
    for (const auto& r : store_->runs_in_state(RunState::running)) {
        const auto attempts = store_->attempts(r.hash);
        const std::string executor = attempts.empty() ? "local" : attempts.back().executor;
        if (executor == "slurm")
            cancel_stale_slurm_task(r.pgid);
        else
            kill_stale_process_group(r.pgid, r.run_dir);
        // A run that wrote its result just before the orchestrator died is finished: keep it. The file is removed
        // before every attempt and written atomically as the run's last act, so it is this attempt's, whole.
        if (const auto result = finished(r)) {
            store_->mark_done(r.hash, *result, 0, result->value("wall_time_s", 0.0), 0.0);
            continue;
        }
        store_->reset_to_pending(r.hash, "the orchestrator (pid " + std::to_string(r.owner_pid) +
                                             ") stopped while the run was running");
    }
}

CampaignDirectory::~CampaignDirectory() {
    store_.reset();  // the store closed before the lock is given up
    lock_.reset();
}

}  // namespace demcal::orchestrator
