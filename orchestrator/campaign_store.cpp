#include "orchestrator/campaign_store.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"
#include "orchestrator/shear_campaign.hpp"  // check_shear_result_values

#include <sqlite3.h>
#include <signal.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace demcal::orchestrator {

double now_seconds() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

namespace {

// The word the store holds for each value of a stored enum, one table each; the same table reads it back.
template <class E, std::size_t N>
using WordTable = std::pair<E, const char*>[N];

constexpr WordTable<RunState, 4> kRunStateWords = {
    {RunState::pending, "pending"}, {RunState::running, "running"}, {RunState::done, "done"}, {RunState::failed, "failed"}};
constexpr WordTable<CampaignKind, 2> kCampaignKindWords = {{CampaignKind::shear, "shear"},
                                                           {CampaignKind::crosscheck_silo, "crosscheck_silo"}};
constexpr WordTable<CampaignStatus, 4> kCampaignStatusWords = {{CampaignStatus::open, "open"},
                                                               {CampaignStatus::complete, "complete"},
                                                               {CampaignStatus::interrupted, "interrupted"},
                                                               {CampaignStatus::failed, "failed"}};

template <class E, std::size_t N>
std::string word_of(const WordTable<E, N>& table, E value) {
    for (const auto& [v, word] : table)
        if (v == value) return word;
    return "?";
}

// Throws std::invalid_argument naming `what`, the word and the words known (a newer demcal's store, or a damaged one).
template <class E, std::size_t N>
E value_of(const WordTable<E, N>& table, const std::string& word, const std::string& what) {
    std::string known;
    for (const auto& [v, w] : table) {
        if (word == w) return v;
        known += (known.empty() ? "" : ", ") + std::string(w);
    }
    throw std::invalid_argument(what + " '" + analytics::shortened_text(word) + "' is not one demcal knows (" + known +
                                ")");
}

}  // namespace

std::string to_string(RunState s) { return word_of(kRunStateWords, s); }
RunState run_state_from_string(const std::string& s) { return value_of(kRunStateWords, s, "run state"); }
std::string to_string(CampaignKind k) { return word_of(kCampaignKindWords, k); }
CampaignKind campaign_kind_from_string(const std::string& s) { return value_of(kCampaignKindWords, s, "kind"); }
std::string to_string(CampaignStatus s) { return word_of(kCampaignStatusWords, s); }
CampaignStatus campaign_status_from_string(const std::string& s) {
    return value_of(kCampaignStatusWords, s, "campaign status");
}

namespace {

// SQLite's message for the last failure, with the system's reason where the file system refused ("disk I/O error"
// alone hid that the disk was full).
std::string sqlite_failure(sqlite3* db) {
    if (!db) return "out of memory";
    std::string m = sqlite3_errmsg(db);
    const int code = sqlite3_errcode(db), sys = sqlite3_system_errno(db);
    if ((code == SQLITE_FULL || code == SQLITE_IOERR || code == SQLITE_CANTOPEN) && sys != 0)
        m += std::string(" (") + std::strerror(sys) + ")";
    else if (code == SQLITE_FULL)  // a short write: SQLite keeps no errno for it (demcal sets no page limit)
        m += " (no space left on the device)";
    // what a user of an overnight campaign on a full disk needs next (probe 64 D6: the reason alone was said)
    if (code == SQLITE_FULL || sys == ENOSPC || sys == EDQUOT || sys == EFBIG)
        m += "; the store keeps every change before this one: once there is room, run the command again";
    return m;
}

// "campaign store 'PATH'": a failure names the file (a full disk said "store: cannot commit", probe 63).
std::string store_named(sqlite3* db) {
    const char* file = sqlite3_db_filename(db, "main");
    return std::string("campaign store '") + (file ? file : "") + "'";
}

// A prepared statement that finalises itself; bind by 1-based position.
class Statement {
public:
    Statement(sqlite3* db, const std::string& sql) : db_(db) {
        if (sqlite3_prepare_v2(db, sql.c_str(), -1, &st_, nullptr) != SQLITE_OK)
            throw std::runtime_error(store_named(db) + ": " + sqlite_failure(db) + " in: " + sql);
    }
    ~Statement() { sqlite3_finalize(st_); }
    Statement& bind(int i, const std::string& v) {
        sqlite3_bind_text(st_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
        return *this;
    }
    Statement& bind(int i, const char* v) { return bind(i, std::string(v)); }
    Statement& bind(int i, double v) {
        sqlite3_bind_double(st_, i, v);
        return *this;
    }
    Statement& bind(int i, std::int64_t v) {
        sqlite3_bind_int64(st_, i, v);
        return *this;
    }
    Statement& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
    bool step() {
        const int rc = sqlite3_step(st_);
        if (rc == SQLITE_ROW) return true;
        if (rc == SQLITE_DONE) return false;
        if (rc == SQLITE_CORRUPT || rc == SQLITE_NOTADB)  // the file's fault, not the machine's: bad input
            throw std::invalid_argument(store_named(db_) + " is damaged: " + sqlite3_errmsg(db_));
        throw std::runtime_error(store_named(db_) + ": " + sqlite_failure(db_));
    }
    std::string text(int c) const {
        auto p = sqlite3_column_text(st_, c);
        return p ? reinterpret_cast<const char*>(p) : "";
    }
    double real(int c) const { return sqlite3_column_double(st_, c); }
    std::int64_t integer(int c) const { return sqlite3_column_int64(st_, c); }
    bool is_null(int c) const { return sqlite3_column_type(st_, c) == SQLITE_NULL; }

private:
    sqlite3* db_;
    sqlite3_stmt* st_ = nullptr;
};

// Runs a function inside one IMMEDIATE transaction; rolls back on exception.
template <class F>
void in_transaction(sqlite3* db, F&& f) {
    char* err = nullptr;
    if (sqlite3_exec(db, "BEGIN IMMEDIATE", nullptr, nullptr, &err) != SQLITE_OK) {
        std::string m = sqlite_failure(db);
        sqlite3_free(err);
        throw std::runtime_error(store_named(db) + ": cannot begin a transaction: " + m);
    }
    try {
        f();
    } catch (...) {
        sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
        throw;
    }
    if (sqlite3_exec(db, "COMMIT", nullptr, nullptr, &err) != SQLITE_OK) {
        std::string m = sqlite_failure(db);
        sqlite3_free(err);
        throw std::runtime_error(store_named(db) + ": cannot commit: " + m);
    }
}

#define DEMCAL_RUN_COLUMNS                                                                                          \
    "r.hash, r.params, r.state, r.attempts, r.result, r.cause, r.message, r.exit_code, r.wall_s, r.cpu_s, r.run_dir, " \
    "r.pgid, r.owner_pid"
const char* kRunColumns = DEMCAL_RUN_COLUMNS;
const char* kRunColumnsQuery = "SELECT " DEMCAL_RUN_COLUMNS " FROM runs r";

// A JSON column as the store holds it, read under the same rules as every JSON input (a damaged store is bad input).
nlohmann::json stored_json(const Statement& st, int column, const char* name) {
    return analytics::parse_json_text(st.text(column), name);
}

// Run folders are stored relative to the store's directory, so a campaign moved or copied (cluster to laptop) finds
// its own runs. Rows of older stores hold absolute paths; every demcal run folder is CAMPAIGN/runs/<name>, so such a
// row is read as that layout under the store's directory, never as a folder of the campaign it was copied from.
// Any other path (absolute, or leading out of the campaign folder by "..") is a damaged or edited row: demcal writes
// into a run's folder, so following it would write over files outside the campaign.
std::filesystem::path resolved_run_dir(const std::filesystem::path& stored, const std::filesystem::path& base_dir) {
    const auto refuse = [&](const char* why) -> std::filesystem::path {
        // (without a folder: the caller names the store; "campaign store in ''" named none, probe 63)
        const std::string where =
            base_dir.empty() ? "" : "campaign store in '" + analytics::shortened_text(base_dir.string(), 200) + "': ";
        throw std::invalid_argument(where + "runs.run_dir = '" + analytics::shortened_text(stored.string(), 200) + "' " +
                                    why + " (the store is damaged or was edited; demcal writes into run folders)");
    };
    if (stored.is_relative()) {
        const auto normal = stored.lexically_normal();
        if (normal.empty() || normal == "." || *normal.begin() == "..") return refuse("leads out of the campaign folder");
        return base_dir / normal;
    }
    if (stored.parent_path().filename() == "runs" && stored.filename() != ".." && stored.filename() != "." &&
        !stored.filename().empty())
        return base_dir / "runs" / stored.filename();
    return refuse("is not a folder of the campaign");
}

std::string stored_run_dir(const std::filesystem::path& run_dir, const std::filesystem::path& base_dir) {
    const auto relative = std::filesystem::absolute(run_dir).lexically_normal().lexically_relative(base_dir);
    const bool inside = !relative.empty() && *relative.begin() != "..";
    return inside ? relative.string() : run_dir.string();
}

constexpr double kLongestRunSeconds = 1e9;  // (31 years) no run's wall or CPU time is longer

RunRecord read_run(const Statement& st, bool with_label, const std::filesystem::path& base_dir) {
    RunRecord r;
    r.hash = st.text(0);
    r.params = stored_json(st, 1, "runs.params");
    r.state = run_state_from_string(st.text(2));
    r.attempts = static_cast<int>(st.integer(3));
    if (!st.is_null(4)) r.result = stored_json(st, 4, "runs.result");
    r.cause = st.text(5);
    r.message = st.text(6);
    r.exit_code = static_cast<int>(st.integer(7));
    r.wall_s = st.real(8);
    r.cpu_s = st.real(9);
    for (const double t : {r.wall_s, r.cpu_s})  // (1e300 s printed as a negative count of seconds)
        if (!std::isfinite(t) || t < 0 || t > kLongestRunSeconds)
            throw std::invalid_argument("runs.wall_s/cpu_s = " + analytics::number_text(t) + " s is not a run's time");
    r.run_dir = resolved_run_dir(st.text(10), base_dir);
    r.pgid = static_cast<long>(st.integer(11));
    r.owner_pid = static_cast<long>(st.integer(12));
    if (with_label) r.label = stored_json(st, 13, "campaign_runs.label");
    return r;
}

#define DEMCAL_CAMPAIGN_QUERY "SELECT id, name, kind, spec, status, created_at FROM campaigns"
CampaignRecord read_campaign(const Statement& st) {
    CampaignRecord c;
    c.id = st.integer(0);
    c.name = st.text(1);
    c.kind = campaign_kind_from_string(st.text(2));
    c.spec = stored_json(st, 3, "campaigns.spec");
    c.status = campaign_status_from_string(st.text(4));
    c.created_at = st.real(5);
    return c;
}

}  // namespace

namespace {

constexpr int kDemcalApplicationId = 0x64656d63;  // "demc" in the SQLite header: marks a file as a demcal store
constexpr int kSchemaVersion = 1;                 // meta.schema_version of the stores this demcal writes

// The checks of an existing store, reading only; `store` names it in their refusals.
// A demcal store: our application_id, or (stores written before demcal set it) our five tables.
void check_store_identity(sqlite3* db, const std::string& store) {
    std::int64_t application_id = 0;
    bool has_demcal_tables = false;
    try {
        Statement id(db, "PRAGMA application_id");
        if (id.step()) application_id = id.integer(0);
        Statement tables(db,
                         "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND name IN "
                         "('meta', 'campaigns', 'runs', 'campaign_runs', 'attempts')");
        has_demcal_tables = tables.step() && tables.integer(0) == 5;
    } catch (const std::exception&) {  // not a database at all, or its first page is damaged
        throw std::invalid_argument(store + " is not a readable SQLite database (" + sqlite3_errmsg(db) +
                                    "); nothing was written to it");
    }
    // stores written before demcal set application_id (0) are recognised by their tables
    if (application_id != kDemcalApplicationId && !(application_id == 0 && has_demcal_tables))
        throw std::invalid_argument(store + " is a SQLite database but not a demcal campaign store (application_id " +
                                    std::to_string(application_id) + ", " + (has_demcal_tables ? "" : "no ") +
                                    "demcal tables); nothing was written to it");
}

// Every column demcal reads is there (integrity_check passes a schema whose text was damaged).
void check_store_columns(sqlite3* db, const std::string& store) {
    for (const char* columns : {"SELECT key, value FROM meta", DEMCAL_CAMPAIGN_QUERY,
                                kRunColumnsQuery, "SELECT campaign_id, hash, label, position FROM campaign_runs",
                                "SELECT id, hash, attempt, executor, started_at, finished_at, exit_code, cause, message, "
                                "wall_s, cpu_s FROM attempts"}) {
        try {
            Statement(db, std::string(columns) + " LIMIT 0");
        } catch (const std::exception&) {
            throw std::invalid_argument(store + " does not have the tables of a demcal store (" +
                                        sqlite3_errmsg(db) + "); nothing was written to it");
        }
    }
}

// SQLite's own check of the file: integrity_check, not quick_check, which does not compare an index with its table
// (a damaged index page let status count 2 of 3 runs as a complete campaign). Its cost is quick_check's: 0.12 s
// against 0.11 s on a store of 20 000 runs (103 MB, measured).
void check_store_integrity(sqlite3* db, const std::string& store) {
    std::string verdict;
    try {
        Statement check(db, "PRAGMA integrity_check(1)");
        verdict = check.step() ? check.text(0) : "no answer";
    } catch (const std::exception&) {
        verdict = sqlite3_errmsg(db);
    }
    if (verdict != "ok")
        throw std::invalid_argument(store + " is damaged (SQLite integrity_check: " + analytics::shortened_text(verdict, 200) +
                                    "); restore it from a copy, or move it away to start the campaign afresh");
}

// A newer demcal's store may hold what this one cannot read or would write wrongly: refused, not migrated.
void check_schema_version(sqlite3* db, const std::string& store) {
    Statement version(db, "SELECT value FROM meta WHERE key = 'schema_version'");
    if (version.step()) {
        const std::string v = version.text(0);
        int n = 0;
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
        if (ec != std::errc() || end != v.data() + v.size() || n < 1)
            throw std::invalid_argument(store + ": schema_version '" + analytics::shortened_text(v) +
                                        "' is not a version demcal writes; nothing was written to it");
        if (n > kSchemaVersion)
            throw std::invalid_argument(store + ": schema_version " + v + " is newer than this demcal's (" +
                                        std::to_string(kSchemaVersion) + "); nothing was written to it");
    }
}

// Every row a command may read, read now: refused later, a resume would have taken the lock and written already.
void check_stored_rows(sqlite3* db, const std::string& store) {
    auto readable = [&](const std::string& what, const std::string& sql, auto&& read) {
        Statement rows(db, sql);
        while (rows.step()) {
            try {
                read(rows);
            } catch (const std::invalid_argument& e) {
                throw std::invalid_argument(store + ": " + what + " " + analytics::shortened_text(rows.text(0), 80) +
                                            ": " + e.what() + "; nothing was written to it");
            }
        }
    };
    readable("campaign", DEMCAL_CAMPAIGN_QUERY, [](const Statement& st) { read_campaign(st); });
    readable("run", kRunColumnsQuery, [](const Statement& st) { read_run(st, false, {}); });
    readable("a run of campaign", "SELECT campaign_id, label FROM campaign_runs",
             [](const Statement& st) { stored_json(st, 1, "campaign_runs.label"); });
    // a shear run's numbers, which status and the reports fit lines to: its label's stress the run's, its result
    // one a box can give (an edited row made a line of 9e99 Pa, or of another run's result, with exit 0)
    readable("shear run",
             "SELECT r.hash, r.params, r.result, cr.label FROM runs r JOIN campaign_runs cr ON cr.hash = r.hash "
             "JOIN campaigns c ON c.id = cr.campaign_id WHERE c.kind = 'shear' AND r.state = 'done'",
             [](const Statement& st) {
                 const nlohmann::json params = stored_json(st, 1, "runs.params");
                 const nlohmann::json label = stored_json(st, 3, "campaign_runs.label");
                 if (st.is_null(2)) throw std::invalid_argument("runs.result is empty for a finished run");
                 const nlohmann::json result = stored_json(st, 2, "runs.result");
                 if (!result.is_object() || !result.contains("peak_shear_stress") ||
                     !result["peak_shear_stress"].is_number())
                     throw std::invalid_argument("runs.result has no number peak_shear_stress");
                 check_shear_result_values(result, "runs.result", &params);
                 if (label.is_object() && label.contains("normal_stress") &&
                     (!params.is_object() || label["normal_stress"] != params.value("normal_stress", nlohmann::json())))
                     throw std::invalid_argument("campaign_runs.label's normal_stress " +
                                                 analytics::json_value_text(label["normal_stress"]) +
                                                 " is not the run's");
             });
}

// Refuses, reading only, a file that is not an intact demcal store: nothing may be written into a file that is not
// ours (status and resume wrote demcal's tables into any SQLite file), and a damaged store must not be resumed as if
// it were whole.
void check_existing_store(sqlite3* db, const std::string& name) {
    const std::string store = "campaign store '" + name + "'";
    check_store_identity(db, store);
    check_store_columns(db, store);
    check_store_integrity(db, store);
    check_schema_version(db, store);
    check_stored_rows(db, store);
}

// The store as a SQLite URI for a read-only open. A read-only connection to a WAL store leaves a -wal and a -shm
// beside it; without a -wal (or a rollback journal) nobody has the store open, and `immutable` reads it creating
// neither. A writer that opens it meanwhile appends to its own -wal and changes the file only when it checkpoints.
std::string read_only_uri(const std::filesystem::path& db_path) {
    const std::string path = std::filesystem::absolute(db_path).lexically_normal().string();
    std::string uri = "file://";
    for (const unsigned char c : path) {
        if (std::isalnum(c) || std::string_view("/._-~").find(static_cast<char>(c)) != std::string_view::npos) {
            uri += static_cast<char>(c);
        } else {
            char escaped[4];
            std::snprintf(escaped, sizeof escaped, "%%%02X", c);
            uri += escaped;
        }
    }
    std::error_code ec;
    const bool may_be_open =
        std::filesystem::exists(path + "-wal", ec) || std::filesystem::exists(path + "-journal", ec);
    return may_be_open ? uri : uri + "?immutable=1";
}

// True when the file is a store another process began to make (DB.new-PID, or its -wal/-shm/-journal) and that
// process is gone: what a kill during a store's creation leaves behind.
bool is_abandoned_fresh_store(const std::string& file_name, const std::string& db_name) {
    const std::string prefix = db_name + ".new-";
    if (file_name.compare(0, prefix.size(), prefix) != 0) return false;
    std::string_view rest(file_name);
    rest.remove_prefix(prefix.size());
    for (const char* suffix : {"-wal", "-shm", "-journal"}) {
        const std::string_view s(suffix);
        if (rest.size() > s.size() && rest.substr(rest.size() - s.size()) == s) {
            rest.remove_suffix(s.size());
            break;
        }
    }
    long pid = 0;
    const auto [end, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), pid);
    if (ec != std::errc() || end != rest.data() + rest.size() || pid <= 0) return false;
    if (pid == ::getpid()) return false;
    return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

void remove_abandoned_fresh_stores(const std::filesystem::path& db_path) {
    std::error_code ec;
    const std::filesystem::path folder = db_path.has_parent_path() ? db_path.parent_path() : ".";
    const std::string db_name = db_path.filename().string();
    std::vector<std::filesystem::path> abandoned;
    for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        if (!it->is_regular_file(ec)) continue;
        if (is_abandoned_fresh_store(it->path().filename().string(), db_name)) abandoned.push_back(it->path());
    }
    for (const auto& file : abandoned) std::filesystem::remove(file, ec);
}

}  // namespace

CampaignStore::CampaignStore(const std::filesystem::path& db_path, StoreAccess access)
    : path_(db_path), base_dir_(std::filesystem::absolute(db_path).lexically_normal().parent_path()) {
    std::error_code ec;
    const auto status = std::filesystem::status(db_path, ec);
    const bool existed = std::filesystem::exists(status);
    const bool read_only = access == StoreAccess::read_only;
    if (read_only && !existed)
        throw std::invalid_argument("campaign store '" + db_path.string() + "' does not exist");
    if (existed && !std::filesystem::is_regular_file(status))
        throw std::invalid_argument("campaign store '" + db_path.string() + "' is not a regular file");
    if (existed && std::filesystem::file_size(db_path, ec) == 0)
        throw std::invalid_argument("campaign store '" + db_path.string() +
                                    "' is empty (0 bytes), not a demcal campaign store; nothing was written to it");
    // SQLite's side files must be files: a FIFO named -wal was opened by SQLite as "disk I/O error" (exit 1, no
    // reason) after it had made a -shm beside it (held-back probe 65)
    for (const char* side : {"-wal", "-shm", "-journal"}) {
        const std::filesystem::path file = db_path.string() + side;
        const auto side_status = std::filesystem::symlink_status(file, ec);
        if (std::filesystem::exists(side_status) && !std::filesystem::is_regular_file(side_status))
            throw std::invalid_argument("campaign store '" + db_path.string() + "': its side file " + file.string() +
                                        " is not a regular file (a folder, FIFO, device or link): SQLite cannot use "
                                        "it; nothing was written");
    }
    check_store_path(db_path);
    if (!read_only) remove_abandoned_fresh_stores(db_path);
    if (!existed) {
        // made whole under another name, then renamed into place: a kill -9 in its first milliseconds left a store of
        // 0 or 4096 bytes that every later command refused as not demcal's
        const std::filesystem::path fresh = db_path.string() + ".new-" + std::to_string(::getpid());
        std::filesystem::remove(fresh, ec);
        try {
            CampaignStore made(fresh, db_path.parent_path());
        } catch (const std::exception& e) {
            std::string why = e.what();  // named by the store, not by its temporary name
            for (const std::string& temporary : {std::filesystem::absolute(fresh, ec).string(), fresh.string()})
                for (std::size_t at; !temporary.empty() && (at = why.find(temporary)) != std::string::npos;)
                    why.replace(at, temporary.size(), db_path.string());
            throw std::runtime_error("cannot create the campaign store " + db_path.string() + ": " + why);
        }
        std::filesystem::rename(fresh, db_path);
    }
    const std::string name = read_only ? read_only_uri(db_path) : db_path.string();
    const int flags = read_only ? SQLITE_OPEN_READONLY | SQLITE_OPEN_URI : SQLITE_OPEN_READWRITE;
    if (sqlite3_open_v2(name.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
        std::string m = sqlite_failure(db_);
        sqlite3_close(db_);
        throw std::runtime_error("store: cannot open " + db_path.string() + ": " + m);
    }
    sqlite3_busy_timeout(db_, 10000);
    if (existed) {
        try {
            check_existing_store(db_, db_path.string());
        } catch (...) {
            sqlite3_close(db_);
            throw;
        }
    }
    if (read_only) return;
    create_schema();
}

void CampaignStore::create_schema() {
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=FULL");
    exec("PRAGMA foreign_keys=ON");
    exec("PRAGMA application_id=" + std::to_string(kDemcalApplicationId));
    exec(R"sql(
CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
INSERT OR IGNORE INTO meta VALUES('schema_version', ')sql" + std::to_string(kSchemaVersion) + R"sql(');
CREATE TABLE IF NOT EXISTS campaigns(
  id INTEGER PRIMARY KEY, name TEXT UNIQUE NOT NULL, kind TEXT NOT NULL, spec TEXT NOT NULL,
  status TEXT NOT NULL DEFAULT 'open', created_at REAL NOT NULL);
CREATE TABLE IF NOT EXISTS runs(
  hash TEXT PRIMARY KEY, params TEXT NOT NULL,
  state TEXT NOT NULL CHECK(state IN ('pending','running','done','failed')),
  attempts INTEGER NOT NULL DEFAULT 0, result TEXT, cause TEXT NOT NULL DEFAULT '', message TEXT NOT NULL DEFAULT '',
  exit_code INTEGER NOT NULL DEFAULT 0, wall_s REAL NOT NULL DEFAULT 0, cpu_s REAL NOT NULL DEFAULT 0,
  run_dir TEXT NOT NULL, pgid INTEGER NOT NULL DEFAULT 0, owner_pid INTEGER NOT NULL DEFAULT 0,
  created_at REAL NOT NULL, updated_at REAL NOT NULL);
CREATE TABLE IF NOT EXISTS run_parameters(
  hash TEXT NOT NULL REFERENCES runs(hash), name TEXT NOT NULL, value REAL NOT NULL, PRIMARY KEY(hash, name));
CREATE TABLE IF NOT EXISTS campaign_runs(
  campaign_id INTEGER NOT NULL REFERENCES campaigns(id), hash TEXT NOT NULL REFERENCES runs(hash),
  label TEXT NOT NULL, position INTEGER NOT NULL, PRIMARY KEY(campaign_id, hash));
CREATE TABLE IF NOT EXISTS attempts(
  id INTEGER PRIMARY KEY, hash TEXT NOT NULL REFERENCES runs(hash), attempt INTEGER NOT NULL, executor TEXT NOT NULL,
  started_at REAL NOT NULL, finished_at REAL, exit_code INTEGER, cause TEXT, message TEXT, wall_s REAL, cpu_s REAL);
CREATE INDEX IF NOT EXISTS runs_by_state ON runs(state);
)sql");
}

CampaignStore::CampaignStore(const std::filesystem::path& fresh_path, const std::filesystem::path& base_dir)
    : path_(fresh_path), base_dir_(std::filesystem::absolute(base_dir).lexically_normal()) {
    if (sqlite3_open_v2(fresh_path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK) {
        std::string m = sqlite_failure(db_);
        sqlite3_close(db_);
        std::error_code ec;
        std::filesystem::remove(fresh_path, ec);
        throw std::runtime_error("store: cannot create " + fresh_path.string() + ": " + m);
    }
    try {
        create_schema();
    } catch (...) {
        sqlite3_close(db_);
        db_ = nullptr;
        std::error_code ec;
        for (const char* tail : {"", "-wal", "-shm", "-journal"})
            std::filesystem::remove(fresh_path.string() + tail, ec);
        throw;
    }
}

void CampaignStore::check_store_path(const std::filesystem::path& db_path) {
    // SQLite's unix file layer takes paths of at most 512 bytes (with its -wal and -shm names): a longer one failed
    // with "unable to open database file" after the campaign folder was made
    const std::string full = std::filesystem::absolute(db_path).lexically_normal().string();
    if (full.size() + 4 > kMaxStorePathBytes)
        throw std::invalid_argument("campaign = '" + analytics::shortened_text(db_path.parent_path().string(), 80) +
                                    "': its store's path is " + std::to_string(full.size()) +
                                    " bytes long, SQLite opens at most " + std::to_string(kMaxStorePathBytes - 4) +
                                    ": give a shorter folder");
}

CampaignStore::~CampaignStore() { sqlite3_close(db_); }

void CampaignStore::exec(const std::string& sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
        std::string m = sqlite_failure(db_);
        sqlite3_free(err);
        throw std::runtime_error("store " + path_.string() + ": " + m);
    }
}

void CampaignStore::insert_campaign(const std::string& name, CampaignKind kind, const nlohmann::json& spec) {
    Statement(db_, "INSERT OR IGNORE INTO campaigns(name, kind, spec, created_at) VALUES(?,?,?,?)")
        .bind(1, name).bind(2, to_string(kind)).bind(3, spec.dump()).bind(4, now_seconds()).step();
}

CampaignRecord CampaignStore::ensure_campaign(const std::string& name, CampaignKind kind, const nlohmann::json& spec) {
    if (auto c = find_campaign(name)) return *c;
    in_transaction(db_, [&] { insert_campaign(name, kind, spec); });
    return *find_campaign(name);
}

CampaignRecord CampaignStore::ensure_campaign(const std::string& name, CampaignKind kind, const nlohmann::json& spec,
                                              const std::vector<RunEntry>& runs) {
    in_transaction(db_, [&] {
        insert_campaign(name, kind, spec);
        Statement id(db_, "SELECT id FROM campaigns WHERE name = ?");
        id.bind(1, name);
        if (!id.step()) throw std::runtime_error(store_named(db_) + ": campaign '" + name + "' was not stored");
        const std::int64_t campaign_id = id.integer(0);
        std::int64_t next_position = linked_runs(campaign_id);
        for (const auto& r : runs) insert_run(campaign_id, r, next_position);
    });
    return *find_campaign(name);
}

std::optional<CampaignRecord> CampaignStore::find_campaign(const std::string& name) {
    Statement st(db_, DEMCAL_CAMPAIGN_QUERY " WHERE name = ?");
    st.bind(1, name);
    if (st.step()) return read_campaign(st);
    return std::nullopt;
}

std::vector<CampaignRecord> CampaignStore::campaigns() {
    Statement st(db_, DEMCAL_CAMPAIGN_QUERY " ORDER BY id");
    std::vector<CampaignRecord> out;
    while (st.step()) out.push_back(read_campaign(st));
    return out;
}

void CampaignStore::set_campaign_status(std::int64_t campaign_id, CampaignStatus status) {
    in_transaction(db_, [&] {
        Statement(db_, "UPDATE campaigns SET status = ? WHERE id = ?").bind(1, to_string(status)).bind(2, campaign_id).step();
    });
}

std::optional<std::string> CampaignStore::setting(const std::string& key) {
    Statement q(db_, "SELECT value FROM meta WHERE key = ?");
    q.bind(1, key);
    if (!q.step()) return std::nullopt;
    return q.text(0);
}

void CampaignStore::set_setting_once(const std::string& key, const std::string& value) {
    in_transaction(db_, [&] { Statement(db_, "INSERT OR IGNORE INTO meta VALUES(?, ?)").bind(1, key).bind(2, value).step(); });
}

std::int64_t CampaignStore::linked_runs(std::int64_t campaign_id) {
    Statement count(db_, "SELECT COUNT(*) FROM campaign_runs WHERE campaign_id = ?");
    count.bind(1, campaign_id);
    return count.step() ? count.integer(0) : 0;
}

void CampaignStore::insert_run(std::int64_t campaign_id, const RunEntry& run, std::int64_t& next_position) {
    const double t = now_seconds();
    Statement ins(db_,
                  "INSERT OR IGNORE INTO runs(hash, params, state, run_dir, created_at, updated_at) "
                  "VALUES(?,?,'pending',?,?,?)");
    ins.bind(1, run.hash).bind(2, run.params.dump()).bind(3, stored_run_dir(run.run_dir, base_dir_)).bind(4, t).bind(5, t).step();
    if (sqlite3_changes(db_) > 0) {
        for (const auto& [k, v] : run.params.items())
            if (v.is_number())
                Statement(db_, "INSERT INTO run_parameters VALUES(?,?,?)").bind(1, run.hash).bind(2, k).bind(3, v.get<double>()).step();
    }
    Statement link(db_, "INSERT OR IGNORE INTO campaign_runs(campaign_id, hash, label, position) VALUES(?,?,?,?)");
    link.bind(1, campaign_id).bind(2, run.hash).bind(3, run.label.dump()).bind(4, next_position).step();
    if (sqlite3_changes(db_) > 0) ++next_position;  // (a run linked before keeps its place)
}

RunRecord CampaignStore::ensure_run(std::int64_t campaign_id, const std::string& hash, const nlohmann::json& params,
                                    const std::filesystem::path& run_dir, const nlohmann::json& label) {
    return ensure_runs(campaign_id, {RunEntry{hash, params, run_dir, label}}).front();
}

std::vector<RunRecord> CampaignStore::ensure_runs(std::int64_t campaign_id, const std::vector<RunEntry>& runs) {
    in_transaction(db_, [&] {
        std::int64_t next_position = linked_runs(campaign_id);
        for (const auto& r : runs) insert_run(campaign_id, r, next_position);
    });
    std::vector<RunRecord> out;
    out.reserve(runs.size());
    for (const auto& r : runs) out.push_back(*run(r.hash));
    return out;
}

std::optional<RunRecord> CampaignStore::run(const std::string& hash) {
    Statement st(db_, std::string("SELECT ") + kRunColumns + " FROM runs r WHERE r.hash = ?");
    st.bind(1, hash);
    if (st.step()) return read_run(st, false, base_dir_);
    return std::nullopt;
}

std::vector<RunRecord> CampaignStore::campaign_runs(std::int64_t campaign_id) {
    Statement st(db_, std::string("SELECT ") + kRunColumns +
                          ", c.label FROM campaign_runs c JOIN runs r ON r.hash = c.hash WHERE c.campaign_id = ? "
                          "ORDER BY c.position");
    st.bind(1, campaign_id);
    std::vector<RunRecord> out;
    while (st.step()) out.push_back(read_run(st, true, base_dir_));
    return out;
}

std::vector<RunRecord> CampaignStore::runs_in_state(RunState s) {
    Statement st(db_, std::string("SELECT ") + kRunColumns + " FROM runs r WHERE r.state = ?");
    st.bind(1, to_string(s));
    std::vector<RunRecord> out;
    while (st.step()) out.push_back(read_run(st, false, base_dir_));
    return out;
}

void CampaignStore::mark_running(const std::string& hash, long pgid, long owner_pid, const std::string& executor) {
    in_transaction(db_, [&] {
        const double t = now_seconds();
        Statement(db_,
                  "UPDATE runs SET state = 'running', attempts = attempts + 1, pgid = ?, owner_pid = ?, "
                  "updated_at = ? WHERE hash = ?")
            .bind(1, pgid).bind(2, owner_pid).bind(3, t).bind(4, hash).step();
        Statement(db_,
                  "INSERT INTO attempts(hash, attempt, executor, started_at) "
                  "VALUES(?, (SELECT attempts FROM runs WHERE hash = ?), ?, ?)")
            .bind(1, hash).bind(2, hash).bind(3, executor).bind(4, t).step();
    });
}

namespace {
void close_attempt(sqlite3* db, const std::string& hash, int exit_code, const std::string& cause,
                   const std::string& message, double wall_s, double cpu_s) {
    Statement(db,
              "UPDATE attempts SET finished_at = ?, exit_code = ?, cause = ?, message = ?, wall_s = ?, cpu_s = ? "
              "WHERE id = (SELECT MAX(id) FROM attempts WHERE hash = ?)")
        .bind(1, now_seconds()).bind(2, exit_code).bind(3, cause).bind(4, message).bind(5, wall_s).bind(6, cpu_s)
        .bind(7, hash).step();
}
}  // namespace

void CampaignStore::mark_done(const std::string& hash, const nlohmann::json& result, int exit_code, double wall_s,
                              double cpu_s) {
    in_transaction(db_, [&] {
        Statement(db_,
                  "UPDATE runs SET state = 'done', result = ?, exit_code = ?, wall_s = ?, cpu_s = ?, cause = '', "
                  "message = '', pgid = 0, updated_at = ? WHERE hash = ?")
            .bind(1, result.dump()).bind(2, exit_code).bind(3, wall_s).bind(4, cpu_s).bind(5, now_seconds())
            .bind(6, hash).step();
        close_attempt(db_, hash, exit_code, "ok", "", wall_s, cpu_s);
    });
}

void CampaignStore::mark_attempt_failed(const std::string& hash, const std::string& cause, const std::string& message,
                                        int exit_code, double wall_s, double cpu_s, bool final) {
    in_transaction(db_, [&] {
        Statement(db_,
                  "UPDATE runs SET state = ?, cause = ?, message = ?, exit_code = ?, wall_s = ?, cpu_s = ?, pgid = 0, "
                  "updated_at = ? WHERE hash = ?")
            .bind(1, final ? "failed" : "pending").bind(2, cause).bind(3, message).bind(4, exit_code).bind(5, wall_s)
            .bind(6, cpu_s).bind(7, now_seconds()).bind(8, hash).step();
        close_attempt(db_, hash, exit_code, cause, message, wall_s, cpu_s);
    });
}

void CampaignStore::reset_to_pending(const std::string& hash, const std::string& why) {
    in_transaction(db_, [&] {
        Statement(db_, "UPDATE runs SET state = 'pending', result = NULL, pgid = 0, updated_at = ? WHERE hash = ?")
            .bind(1, now_seconds()).bind(2, hash).step();
        Statement(db_,
                  "UPDATE attempts SET finished_at = ?, cause = 'interrupted', message = ? "
                  "WHERE hash = ? AND finished_at IS NULL")
            .bind(1, now_seconds()).bind(2, why).bind(3, hash).step();
    });
}

std::vector<CampaignStore::Attempt> CampaignStore::attempts(const std::string& hash) {
    Statement st(db_,
                 "SELECT attempt, started_at, IFNULL(finished_at, 0), IFNULL(wall_s, 0), IFNULL(cpu_s, 0), "
                 "IFNULL(exit_code, 0), IFNULL(cause, ''), IFNULL(message, ''), executor FROM attempts WHERE hash = ? "
                 "ORDER BY id");
    st.bind(1, hash);
    std::vector<Attempt> out;
    while (st.step())
        out.push_back({static_cast<int>(st.integer(0)), st.real(1), st.real(2), st.real(3), st.real(4),
                       static_cast<int>(st.integer(5)), st.text(6), st.text(7), st.text(8)});
    return out;
}

}  // namespace demcal::orchestrator
