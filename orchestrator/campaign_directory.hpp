// A campaign directory held by one demcal at a time: its lock (flock on DIR/.lock, released by the kernel when the
// holder dies, even by kill -9) and its store (DIR/campaign.sqlite), with the runs a dead holder left "running"
// recovered on opening. Shared by the shear campaigns and the jobs of other campaigns kept in the store (the silo
// cross-check).
#pragma once
#include "orchestrator/campaign_store.hpp"
#include "orchestrator/folder_lock.hpp"

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

namespace demcal::orchestrator {

// A campaign folder is new, holds files only, or is already a campaign's: one that holds `marker` (the store,
// campaign.sqlite; a silo campaign's campaign.json). A folder with folders of its own (a home or project folder given
// by mistake, "/") would get a store, runs/ and reports among its files, the same names overwritten:
// std::invalid_argument naming the folder and a few of its folders, before anything is written. Files alone are
// taken: a console log or a batch system's output file (sbatch -o DIR/...) exists before demcal starts. A folder
// that does not exist, or is not a folder, is left to the caller. A path holding a control character (a newline) is
// refused whatever the folder holds: SLURM's task list, the plots and the logs name runs by it.
void check_campaign_folder(const std::filesystem::path& dir, const std::string& marker);

// The result a run left in its folder if it finished (written atomically as its last act), else nothing.
using FinishedResult = std::function<std::optional<nlohmann::json>(const RunRecord& run)>;

class CampaignDirectory {
public:
    // Checks a store already there, reading only (std::invalid_argument for one this demcal refuses, with nothing
    // written), creates the folder if needed (std::invalid_argument naming it when it cannot be made), takes its lock
    // (std::runtime_error when another demcal holds it), opens the store and recovers stale runs: a run marked running
    // belongs to a demcal that died (we hold the lock); its process group or SLURM task is stopped, and it is done if
    // `finished` finds its result, else back to pending.
    CampaignDirectory(const std::filesystem::path& dir, const FinishedResult& finished);
    ~CampaignDirectory();
    CampaignDirectory(const CampaignDirectory&) = delete;
    CampaignDirectory& operator=(const CampaignDirectory&) = delete;

    const std::filesystem::path& dir() const { return dir_; }
    CampaignStore& store() { return *store_; }

private:
    std::filesystem::path dir_;
    std::unique_ptr<FolderLock> lock_;
    std::unique_ptr<CampaignStore> store_;
};

}  // namespace demcal::orchestrator
