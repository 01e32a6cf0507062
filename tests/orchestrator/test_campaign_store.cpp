#include "orchestrator/campaign_store.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"

#include <catch2/catch.hpp>

#include <sqlite3.h>
#include <csignal>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

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
        cid = s.ensure_campaign("c1", CampaignKind::shear, {{"x", 1}}).id;
        CHECK(s.ensure_campaign("c1", CampaignKind::shear, {{"x", 2}}).id == cid);  // same name, same campaign
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
        cid = s.ensure_campaign("c1", CampaignKind::shear, {{"x", 1}}).id;
        for (const std::string h : {"finished", "unfinished", "garbled", "flipped", "unsealed", "legacy"}) {
            fs::create_directories(d / "runs" / h);
            s.ensure_run(cid, h, {{"normal_stress", 1e4}}, d / "runs" / h, {{"replicate", 0}});
            s.mark_running(h, 999999, 999999, "local");  // no such process group: the orchestrator died with it
        }
    }
    using demcal::orchestrator::sealed_result_text;
    using demcal::orchestrator::write_text_file_atomically;
    const std::string body =
        R"({"schema": "demcal.shear_result/2", "peak_shear_stress": 4321.0, "wall_time_s": 17.5})" "\n";
    write_text_file_atomically(d / "runs/finished/result.json", sealed_result_text(body));
    write_text_file_atomically(d / "runs/garbled/result.json", R"({"peak_shear_st)");
    // one digit changed after the write (4321.0 -> 4821.0): still JSON, still a number, caught by the seal
    std::string flipped = sealed_result_text(body);
    flipped[flipped.find("4321") + 1] = '8';
    write_text_file_atomically(d / "runs/flipped/result.json", flipped);
    write_text_file_atomically(d / "runs/unsealed/result.json", body);  // schema /2 without its seal
    // a result of a template older than the seal (schema /1) is still read
    write_text_file_atomically(d / "runs/legacy/result.json",
                               R"({"schema": "demcal.shear_result/1", "peak_shear_stress": 1234.0})");
    { ShearCampaignRunner reopened(d, ExecutionOptions{}); }
    CampaignStore s(d / "campaign.sqlite");
    const auto finished = s.run("finished");
    REQUIRE(finished);
    CHECK(finished->state == RunState::done);
    CHECK(finished->result.at("peak_shear_stress").get<double>() == 4321.0);
    CHECK(finished->wall_s == 17.5);
    CHECK(s.run("unfinished")->state == RunState::pending);
    CHECK(s.run("garbled")->state == RunState::pending);  // a partial file is not a result
    CHECK(s.run("flipped")->state == RunState::pending);  // nor a damaged one: it is run again
    CHECK(s.run("unsealed")->state == RunState::pending);
    CHECK(s.run("legacy")->state == RunState::done);
    fs::remove_all(d);
}

namespace {
std::string bytes_of(const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void sql(const fs::path& db_file, const std::string& statements) {
    sqlite3* db = nullptr;
    REQUIRE(sqlite3_open(db_file.c_str(), &db) == SQLITE_OK);
    CHECK(sqlite3_exec(db, statements.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK);
    sqlite3_close(db);
}
}  // namespace

TEST_CASE("a file that is not a demcal store is refused without a byte written to it", "[store]") {
    const fs::path d = fresh_dir("foreign-store");
    auto refused_untouched = [&](const fs::path& file, const std::string& expected) {
        const std::string before = bytes_of(file);
        CHECK_THROWS_AS(CampaignStore(file), std::invalid_argument);
        CHECK_THROWS_WITH(CampaignStore(file), Catch::Contains(file.string()) && Catch::Contains(expected));
        CHECK(bytes_of(file) == before);
        CHECK_FALSE(fs::exists(file.string() + "-wal"));
    };
    std::ofstream(d / "empty.sqlite").close();
    refused_untouched(d / "empty.sqlite", "is empty (0 bytes)");
    std::ofstream(d / "text.sqlite") << "just some notes, not a database at all\n" << std::string(5000, 'x');
    refused_untouched(d / "text.sqlite", "is not a readable SQLite database");
    sql(d / "other.sqlite", "CREATE TABLE notes(t TEXT); INSERT INTO notes VALUES('mine');");
    refused_untouched(d / "other.sqlite", "not a demcal campaign store");
    sql(d / "app.sqlite", "PRAGMA application_id = 42; CREATE TABLE meta(key TEXT);");
    refused_untouched(d / "app.sqlite", "application_id 42");
    fs::remove_all(d);
}

TEST_CASE("a damaged store is refused before a resume, a store without application_id is still accepted", "[store]") {
    const fs::path d = fresh_dir("damaged-store");
    {
        CampaignStore s(d / "c.sqlite");
        const auto cid = s.ensure_campaign("c1", CampaignKind::shear, {{"x", 1}}).id;
        for (int i = 0; i < 200; ++i)  // several pages of runs
            s.ensure_run(cid, "h" + std::to_string(i), {{"normal_stress", 1e4 + i}, {"note", std::string(200, 'n')}},
                         d / "runs" / ("h" + std::to_string(i)), {{"replicate", i}});
    }
    REQUIRE_FALSE(fs::exists(d / "c.sqlite-wal"));  // the last connection checkpointed it into the file
    fs::copy_file(d / "c.sqlite", d / "legacy.sqlite");
    sql(d / "legacy.sqlite", "PRAGMA application_id = 0;");  // as written before demcal set it
    CHECK(CampaignStore(d / "legacy.sqlite").campaigns().size() == 1);

    {  // overwrite the middle of the file: b-tree pages of the runs table
        std::fstream f(d / "c.sqlite", std::ios::in | std::ios::out | std::ios::binary);
        const auto size = fs::file_size(d / "c.sqlite");
        f.seekp(static_cast<std::streamoff>(size / 2));
        const std::string junk(3000, '\x7f');
        f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
    }
    CHECK_THROWS_WITH(CampaignStore(d / "c.sqlite"), Catch::Contains("is damaged (SQLite integrity_check"));
    fs::remove_all(d);
}

namespace {
// The file offset just past the last byte of `index`'s root page.
long end_of_root_page(const fs::path& db_file, const std::string& index) {
    sqlite3* db = nullptr;
    REQUIRE(sqlite3_open(db_file.c_str(), &db) == SQLITE_OK);
    auto integer = [&](const std::string& query) {
        sqlite3_stmt* st = nullptr;
        REQUIRE(sqlite3_prepare_v2(db, query.c_str(), -1, &st, nullptr) == SQLITE_OK);
        REQUIRE(sqlite3_step(st) == SQLITE_ROW);
        const long value = sqlite3_column_int64(st, 0);
        sqlite3_finalize(st);
        return value;
    };
    const long end = integer("SELECT rootpage FROM sqlite_master WHERE name = '" + index + "'") *
                     integer("PRAGMA page_size");
    sqlite3_close(db);
    return end;
}
}  // namespace

TEST_CASE("a store whose index no longer matches its table is refused as damaged", "[store]") {
    // SQLite's quick_check reads every page but does not compare an index with its table: a damaged index page made
    // status report 2 of 3 runs as a complete campaign and resume say "nothing to resume" (held-back probe, stop 64)
    const fs::path d = fresh_dir("damaged-index");
    {
        CampaignStore s(d / "c.sqlite");
        const auto cid = s.ensure_campaign("c1", CampaignKind::shear, {{"x", 1}}).id;
        for (int i = 0; i < 3; ++i) {  // hashes as long as a run's (16 hex digits)
            const std::string hash = "8091ce02b330fe9" + std::to_string(i);
            s.ensure_run(cid, hash, {{"normal_stress", 1e4 + i}}, d / "runs" / hash, {{"replicate", i}});
        }
    }
    const long page_end = end_of_root_page(d / "c.sqlite", "sqlite_autoindex_campaign_runs_1");
    {  // the end of the index's page holds the first key, the hash last: letters in place of its last digits keep
       // the page well formed (what quick_check looks at) and the key no longer that of its row
        std::fstream f(d / "c.sqlite", std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(static_cast<std::streamoff>(page_end - 4));
        const std::string junk(4, 'X');
        f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
    }
    CHECK_THROWS_WITH(CampaignStore(d / "c.sqlite"),
                      Catch::Contains("is damaged") && Catch::Contains("sqlite_autoindex_campaign_runs_1"));
    fs::remove_all(d);
}

TEST_CASE("run folders are stored relative to the campaign, so a copied campaign uses its own", "[store]") {
    const fs::path d = fresh_dir("moved-store");
    fs::create_directories(d / "a");
    {
        CampaignStore s(d / "a" / "campaign.sqlite");
        const auto cid = s.ensure_campaign("c1", CampaignKind::shear, {{"x", 1}}).id;
        s.ensure_run(cid, "h1", {{"normal_stress", 1e4}}, d / "a" / "runs" / "h1", {{"replicate", 0}});
        s.ensure_run(cid, "h2", {{"normal_stress", 2e4}}, d / "a" / "runs" / "h2", {{"replicate", 0}});
    }
    // h2 as an older store recorded it: absolute, in the original campaign's folder
    sql(d / "a" / "campaign.sqlite", "UPDATE runs SET run_dir = '" + (d / "a" / "runs" / "h2").string() +
                                         "' WHERE hash = 'h2';");
    fs::copy(d / "a", d / "b", fs::copy_options::recursive);
    CampaignStore copy(d / "b" / "campaign.sqlite");
    CHECK(copy.run("h1")->run_dir == d / "b" / "runs" / "h1");
    CHECK(copy.run("h2")->run_dir == d / "b" / "runs" / "h2");
    fs::remove_all(d);
}

TEST_CASE("a store another process began to make and never finished is removed when the store is next opened",
          "[store]") {
    // a kill during a store's creation leaves DB.new-PID (and maybe its -wal/-shm); the next writer removes those of
    // processes that are gone, never a live process's, never another file
    const fs::path d = fresh_dir("store-abandoned");
    const pid_t gone = ::fork();
    if (gone == 0) ::_exit(0);
    REQUIRE(gone > 0);
    int status = 0;
    ::waitpid(gone, &status, 0);
    const std::string dead = std::to_string(gone), live = std::to_string(::getppid());
    const std::vector<std::string> abandoned = {"c.sqlite.new-" + dead, "c.sqlite.new-" + dead + "-wal",
                                                "c.sqlite.new-" + dead + "-shm"};
    const std::vector<std::string> kept = {"c.sqlite.new-" + live, "c.sqlite.new-" + dead + "x",
                                           "c.sqlite.new-", "other.sqlite.new-" + dead, "c.sqlite.new--1"};
    for (const auto& name : abandoned) std::ofstream(d / name) << "x";
    for (const auto& name : kept) std::ofstream(d / name) << "x";
    SECTION("on creation") { CampaignStore s(d / "c.sqlite"); }
    SECTION("on reopening") {
        { CampaignStore s(d / "c2.sqlite"); }
        fs::rename(d / "c2.sqlite", d / "c.sqlite");
        CampaignStore s(d / "c.sqlite");
    }
    SECTION("never by a reader") {
        { CampaignStore s(d / "c2.sqlite"); }
        fs::rename(d / "c2.sqlite", d / "c.sqlite");
        CampaignStore s(d / "c.sqlite", StoreAccess::read_only);
        for (const auto& name : abandoned) CHECK(fs::exists(d / name));
        fs::remove_all(d);
        return;
    }
    for (const auto& name : abandoned) CHECK_FALSE(fs::exists(d / name));
    for (const auto& name : kept) CHECK(fs::exists(d / name));
    CHECK(fs::exists(d / "c.sqlite"));
    fs::remove_all(d);
}

TEST_CASE("a campaign is stored with all its runs or not at all, whenever its process is killed", "[store]") {
    // Before (probe 64 D5): the campaign, then each run, each in its own transaction: a kill between them left a
    // campaign with part of its runs, which `status` counted as complete with the runs it had.
    const fs::path d = fresh_dir("store-whole-campaign");
    constexpr int kRuns = 50000;  // enough that the kill lands while they are being stored
    std::vector<CampaignStore::RunEntry> runs;
    for (int i = 0; i < kRuns; ++i) {
        const std::string hash = "h" + std::to_string(i);
        runs.push_back({hash, {{"normal_stress", 1e4 + i}}, d / "runs" / hash, {{"replicate", i}}});
    }
    { CampaignStore s(d / "c.sqlite"); }  // made whole beforehand: the kill falls on the campaign's registration
    const pid_t child = ::fork();
    if (child == 0) {
        CampaignStore s(d / "c.sqlite");
        s.ensure_campaign("c1", CampaignKind::shear, {{"x", 1}}, runs);
        ::_exit(0);
    }
    REQUIRE(child > 0);
    ::usleep(100'000);
    int status = 0;
    const bool killed_while_storing = ::waitpid(child, &status, WNOHANG) == 0;
    ::kill(child, SIGKILL);
    ::waitpid(child, &status, 0);
    CampaignStore s(d / "c.sqlite");
    const auto campaigns = s.campaigns();
    INFO("killed while storing: " << killed_while_storing);
    if (campaigns.empty()) {
        CHECK(s.runs_in_state(RunState::pending).empty());
    } else {
        CHECK(s.campaign_runs(campaigns.front().id).size() == static_cast<std::size_t>(kRuns));
    }
    // and when not killed: the campaign and every run, their records in the order given
    const auto c = s.ensure_campaign("c1", CampaignKind::shear, {{"x", 1}}, runs);
    CHECK(s.campaign_runs(c.id).size() == static_cast<std::size_t>(kRuns));
    const auto records = s.ensure_runs(c.id, {runs[7], runs[3]});
    REQUIRE(records.size() == 2);
    CHECK(records[0].hash == "h7");
    CHECK(records[1].hash == "h3");
    fs::remove_all(d);
}
