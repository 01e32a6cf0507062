// The campaign store: one SQLite file in the campaign directory holding campaigns, runs (identity, parameters, state,
// result, timings, error), every attempt of every run, and the numeric parameters in a queryable table.
// Every state change is one transaction with synchronous=FULL, so a kill -9 at any moment leaves the store at the last
// committed change: a finished run is either fully recorded (result included) or still pending/running.
#pragma once
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

struct sqlite3;

namespace demcal::orchestrator {

enum class RunState { pending, running, done, failed };
std::string to_string(RunState s);
RunState run_state_from_string(const std::string& s);

// What a campaign is; a store holding a kind this demcal does not know is refused (a newer demcal's store).
enum class CampaignKind { shear, crosscheck_silo };
std::string to_string(CampaignKind k);
// Throws std::invalid_argument naming the value and the kinds known.
CampaignKind campaign_kind_from_string(const std::string& s);

// Where a campaign stands, as its last command left it: open (runs to do, or the simulator could not be started),
// complete (every run done), interrupted (Ctrl-C, a signal), failed (runs failed for good). resume continues every
// campaign that is not complete; a store holding another word is refused (a newer demcal's, or damaged).
enum class CampaignStatus { open, complete, interrupted, failed };
std::string to_string(CampaignStatus s);
// Throws std::invalid_argument naming the value and the statuses known.
CampaignStatus campaign_status_from_string(const std::string& s);

struct RunRecord {
    std::string hash;
    nlohmann::json params;
    RunState state = RunState::pending;
    int attempts = 0;
    nlohmann::json result;           // null unless done
    std::string cause, message;      // of the last failure
    int exit_code = 0;
    double wall_s = 0, cpu_s = 0;    // of the successful (or last) attempt
    std::filesystem::path run_dir;   // absolute; stored relative to the campaign directory
    long pgid = 0, owner_pid = 0;    // while running: the process group and the orchestrator that owns it
    nlohmann::json label;            // campaign-specific tags (normal stress, replicate), from campaign_runs
};

struct CampaignRecord {
    std::int64_t id = 0;
    std::string name;
    CampaignKind kind = CampaignKind::shear;
    CampaignStatus status = CampaignStatus::open;
    nlohmann::json spec;
    double created_at = 0;
};

// read_only: the file must exist, and nothing is written to it or beside it (status; the check before a campaign
// directory is locked). The write methods then fail.
enum class StoreAccess { read_write, read_only };

class CampaignStore {
public:
    // Opens the store, creating it when the file does not exist (read_write). An existing file must be an intact
    // demcal store this demcal can read (application_id, or the tables of a store written before it was set; PRAGMA
    // integrity_check; a schema_version not newer than its own; every campaign and run row readable, its kind known):
    // anything else is refused with std::invalid_argument naming the file, before anything is written to it.
    explicit CampaignStore(const std::filesystem::path& db_path, StoreAccess access = StoreAccess::read_write);
    ~CampaignStore();
    CampaignStore(const CampaignStore&) = delete;
    CampaignStore& operator=(const CampaignStore&) = delete;

    // The longest store path SQLite's unix file layer opens (its -wal/-shm names included).
    static constexpr std::size_t kMaxStorePathBytes = 512;
    // Throws std::invalid_argument naming the folder when a store at `db_path` could not be opened for its length
    // (CampaignDirectory calls it before it makes the folder).
    static void check_store_path(const std::filesystem::path& db_path);

    // A run to register: its identity (hash), what it depends on, its folder and its label in the campaign.
    struct RunEntry {
        std::string hash;
        nlohmann::json params;
        std::filesystem::path run_dir;
        nlohmann::json label;
    };

    // Returns the campaign of that name, creating it with `spec` if new.
    CampaignRecord ensure_campaign(const std::string& name, CampaignKind kind, const nlohmann::json& spec);
    // The same, with every run of the campaign registered in the same transaction (ensure_runs): a kill leaves the
    // campaign with all its planned runs or not stored at all. (A campaign stored without all its runs was counted
    // complete by `status` with the runs it had; probe 64 D5.)
    CampaignRecord ensure_campaign(const std::string& name, CampaignKind kind, const nlohmann::json& spec,
                                   const std::vector<RunEntry>& runs);
    std::optional<CampaignRecord> find_campaign(const std::string& name);
    std::vector<CampaignRecord> campaigns();
    void set_campaign_status(std::int64_t campaign_id, CampaignStatus status);

    // A store-wide setting (table meta), e.g. the simulator build whose results the store holds; nullopt if unset.
    std::optional<std::string> setting(const std::string& key);
    // Sets it unless it is already set (the first writer wins: two processes record the same value, or the second
    // learns the first one's on its next read).
    void set_setting_once(const std::string& key, const std::string& value);

    // Registers a run (new identity: pending) and links it to the campaign with its label. Returns the stored record.
    RunRecord ensure_run(std::int64_t campaign_id, const std::string& hash, const nlohmann::json& params,
                         const std::filesystem::path& run_dir, const nlohmann::json& label);
    // Registers every run as ensure_run does, all in one transaction; their stored records in the order given.
    std::vector<RunRecord> ensure_runs(std::int64_t campaign_id, const std::vector<RunEntry>& runs);
    std::optional<RunRecord> run(const std::string& hash);
    std::vector<RunRecord> campaign_runs(std::int64_t campaign_id);
    std::vector<RunRecord> runs_in_state(RunState s);

    void mark_running(const std::string& hash, long pgid, long owner_pid, const std::string& executor);
    void mark_done(const std::string& hash, const nlohmann::json& result, int exit_code, double wall_s, double cpu_s);
    // Records a failed attempt; `final` marks the run failed, otherwise it goes back to pending for a retry.
    void mark_attempt_failed(const std::string& hash, const std::string& cause, const std::string& message,
                             int exit_code, double wall_s, double cpu_s, bool final);
    // Back to pending without counting a failure (interrupted by the user, or forced to recompute).
    void reset_to_pending(const std::string& hash, const std::string& why);

    struct Attempt {
        int attempt;
        double started_at, finished_at, wall_s, cpu_s;
        int exit_code;
        std::string cause, message, executor;
    };
    std::vector<Attempt> attempts(const std::string& hash);

private:
    // A new store under `fresh_path` with demcal's schema (then renamed into place by the public constructor).
    CampaignStore(const std::filesystem::path& fresh_path, const std::filesystem::path& base_dir);
    void create_schema();
    void insert_campaign(const std::string& name, CampaignKind kind, const nlohmann::json& spec);  // (in a transaction)
    // (in a transaction) `next_position`: the run's place in the campaign if it is new to it (then counted on)
    void insert_run(std::int64_t campaign_id, const RunEntry& run, std::int64_t& next_position);
    std::int64_t linked_runs(std::int64_t campaign_id);  // the runs linked to the campaign so far
    void exec(const std::string& sql);
    sqlite3* db_ = nullptr;
    std::filesystem::path path_;
    std::filesystem::path base_dir_;  // the campaign directory: run folders are stored relative to it
};

double now_seconds();  // wall clock, seconds since the epoch

}  // namespace demcal::orchestrator
