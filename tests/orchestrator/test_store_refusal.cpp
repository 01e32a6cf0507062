// `demcal status` and `demcal resume` on real stores made by the real binary: status never writes to the store, and
// a store either command refuses (a newer schema, an unknown campaign kind, a row that is not readable) is refused
// with exit 2, the store file and the field named, and its folder left byte for byte as it was (no lock file, no
// -wal or -shm). A folder without a store is still refused as holding none.
#include "campaign_test_support.hpp"

#include <catch2/catch.hpp>

#include <sqlite3.h>
#include <sys/stat.h>  // mkfifo

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>

namespace fs = std::filesystem;
using namespace demcal;
using Catch::Matchers::Contains;

namespace {

using FolderState = std::map<std::string, std::pair<std::string, fs::file_time_type>>;

// Every file under `dir` with its bytes and modification time; folders by name.
FolderState folder_state(const fs::path& dir) {
    FolderState state;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string name = fs::relative(e.path(), dir).string();
        state[name] = e.is_regular_file() ? std::make_pair(test::read_file(e.path()), e.last_write_time())
                                          : std::make_pair(std::string("folder"), fs::file_time_type());
    }
    return state;
}

// What differs from `before` in `dir`, e.g. "campaign.sqlite changed, .lock added"; empty when nothing does.
std::string changes(const FolderState& before, const fs::path& dir) {
    const FolderState after = folder_state(dir);
    std::string out;
    for (const auto& [name, state] : after)
        if (!before.count(name))
            out += name + " added, ";
        else if (before.at(name) != state)
            out += name + " changed, ";
    for (const auto& [name, state] : before)
        if (!after.count(name)) out += name + " removed, ";
    return out;
}

void sql(const fs::path& db_file, const std::string& statements) {
    sqlite3* db = nullptr;
    REQUIRE(sqlite3_open(db_file.c_str(), &db) == SQLITE_OK);
    CHECK(sqlite3_exec(db, statements.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK);
    sqlite3_close(db);
}

// A complete shear campaign of two runs in `campaign`, made by `demcal shear` with a stand-in simulator (written to
// `dir`, returned) that writes the result file named by its last argument. The lock file is removed, as in a
// campaign copied from elsewhere, so a lock a refused command leaves behind is seen; the store's time is set an hour
// back, so a rewrite shows in it even on a file system with coarse times.
fs::path complete_campaign(const fs::path& dir, const fs::path& campaign) {
    const fs::path yade = test::write_stand_in_yade(dir);
    const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
    const int rc = test::run_demcal({"shear", tiny, "-s", "5e3,1e4,2e4", "--yade", yade.string(), "--campaign",
                                     campaign.string(), "--plot", "svg"},
                                    dir / "shear.log");
    INFO(test::read_file(dir / "shear.log"));
    REQUIRE(rc == 0);
    fs::remove(campaign / ".lock");
    REQUIRE_FALSE(fs::exists(campaign / "campaign.sqlite-wal"));  // closed: the store is all in its file
    fs::last_write_time(campaign / "campaign.sqlite", fs::file_time_type::clock::now() - std::chrono::hours(1));
    return yade;
}

}  // namespace

TEST_CASE("status reads a store without writing to it, also while another connection has it open", "[cli][store]") {
    const fs::path dir = test::fresh_test_dir("status-read-only");
    const fs::path campaign = dir / "campaign";
    complete_campaign(dir, campaign);
    const auto before = folder_state(campaign);
    CHECK(test::run_demcal({"status", campaign.string()}, dir / "status.log") == 0);
    INFO(test::read_file(dir / "status.log"));
    CHECK_THAT(test::read_file(dir / "status.log"), Contains("[complete] shear: 3 runs, 3 done"));
    CHECK(changes(before, campaign) == "");  // status rewrote the file (SQLite's change counter) and its time

    // a campaign running: its committed changes are in the -wal, which status reads and leaves as it was
    sqlite3* db = nullptr;
    REQUIRE(sqlite3_open((campaign / "campaign.sqlite").c_str(), &db) == SQLITE_OK);
    REQUIRE(sqlite3_exec(db, "UPDATE campaigns SET status = 'interrupted'", nullptr, nullptr, nullptr) == SQLITE_OK);
    REQUIRE(fs::exists(campaign / "campaign.sqlite-wal"));
    const std::string store = test::read_file(campaign / "campaign.sqlite");
    const std::string wal = test::read_file(campaign / "campaign.sqlite-wal");
    CHECK(test::run_demcal({"status", campaign.string()}, dir / "status.log") == 0);
    CHECK_THAT(test::read_file(dir / "status.log"), Contains("[interrupted] shear: 3 runs, 3 done"));
    const bool store_unchanged = test::read_file(campaign / "campaign.sqlite") == store;
    const bool wal_unchanged = test::read_file(campaign / "campaign.sqlite-wal") == wal;
    CHECK(store_unchanged);
    CHECK(wal_unchanged);
    sqlite3_close(db);
    fs::remove_all(dir);
}

TEST_CASE("status and resume refuse a newer schema, an unknown kind or an unreadable row, writing nothing",
          "[cli][store]") {
    const fs::path dir = test::fresh_test_dir("store-refusal");
    const fs::path pristine = dir / "pristine";
    const fs::path yade = complete_campaign(dir, pristine);
    struct Case {
        std::string damage, expect;
    };
    const std::vector<Case> cases{
        {"UPDATE meta SET value = '999' WHERE key = 'schema_version'", "schema_version 999 is newer than this demcal's"},
        {"UPDATE meta SET value = 'two' WHERE key = 'schema_version'", "schema_version 'two' is not a version demcal"},
        {"UPDATE campaigns SET kind = 'martian'", "campaign 1: kind 'martian' is not one demcal knows (shear"},
        {"UPDATE campaigns SET status = 'paused'",
         "campaign 1: campaign status 'paused' is not one demcal knows (open, complete, interrupted, failed)"},
        {"UPDATE campaigns SET spec = '{not json'", "campaigns.spec is not valid JSON"},
        // valid JSON, not a spec: the JSON library's text, exit 1, after part of the output (probe 63)
        {"UPDATE campaigns SET spec = json_remove(spec, '$.material')", "campaign 1: the campaign's spec has no 'material'"},
        {"UPDATE campaigns SET spec = json_set(spec, '$.replicates', 'x')",
         "the campaign's spec field 'replicates' = \"x\" is not a whole number"},
        {"UPDATE campaigns SET spec = '[]'", "the campaign's spec is not a JSON object"},
        {"UPDATE campaigns SET spec = json_set(spec, '$.engine', 'warp')", "campaign 1: engine = 'warp' is not one of"},
        {"UPDATE runs SET result = '{\"peak' WHERE rowid = 1", "runs.result is not valid JSON"},
        // rows edited to send demcal's writes outside the campaign, or to make nonsense of its line (probe 44)
        {"UPDATE runs SET run_dir = '/tmp' WHERE rowid = 1", "runs.run_dir = '/tmp' is not a folder of the campaign"},
        {"UPDATE runs SET run_dir = 'runs/../../victim' WHERE rowid = 1", "leads out of the campaign folder"},
        {"UPDATE runs SET result = '{\"schema\": \"demcal.shear_result/1\", \"peak_shear_stress\": -5000}' "
         "WHERE rowid = 1",
         "peak_shear_stress = -5000 Pa is outside [0, "},
        {"UPDATE runs SET result = json_set(result, '$.normal_stress_target', 123456.0) WHERE rowid = 1",
         "the result of a run at normal stress 123456 Pa, not of this run's"},
        {"UPDATE runs SET result = '{}' WHERE rowid = 1", "runs.result has no number peak_shear_stress"},
        {"UPDATE campaign_runs SET label = json_set(label, '$.normal_stress', 9e99) WHERE rowid = 1",
         "campaign_runs.label's normal_stress 9e+99 is not the run's"},
        {"UPDATE runs SET cpu_s = 1e300 WHERE rowid = 1", "runs.wall_s/cpu_s = 1e+300 s is not a run's time"},
    };
    for (const auto& c : cases) {
        INFO(c.damage);
        const fs::path campaign = dir / "campaign";
        fs::remove_all(campaign);
        fs::copy(pristine, campaign, fs::copy_options::recursive);
        const fs::path store = campaign / "campaign.sqlite";
        sql(store, c.damage);
        REQUIRE_FALSE(fs::exists(campaign / "campaign.sqlite-wal"));
        fs::last_write_time(store, fs::file_time_type::clock::now() - std::chrono::hours(1));
        const auto before = folder_state(campaign);
        for (const std::vector<std::string>& args :
             {std::vector<std::string>{"status", campaign.string()},
              std::vector<std::string>{"resume", campaign.string(), "--yade", yade.string()}}) {
            INFO(args[0]);
            CHECK(test::run_demcal(args, dir / "out.log") == 2);
            const std::string log = test::read_file(dir / "out.log");
            INFO(log);
            CHECK_THAT(log, Contains(store.string()) && Contains(c.expect));
            CHECK(std::count(log.begin(), log.end(), '\n') == 1);  // one line
            CHECK(changes(before, campaign) == "");  // no .lock, no -wal, the store's bytes and time
        }
    }
    fs::remove_all(dir);
}

TEST_CASE("status and resume on a folder without a store refuse it as holding none and create nothing",
          "[cli][store]") {
    const fs::path dir = test::fresh_test_dir("store-none");
    fs::create_directories(dir / "empty");
    for (const std::string command : {"status", "resume"}) {
        INFO(command);
        CHECK(test::run_demcal({command, (dir / "empty").string()}, dir / "out.log") == 2);
        CHECK_THAT(test::read_file(dir / "out.log"), Contains("holds no campaign.sqlite"));
        // a folder that is not there is named so (probe 59b: "holds no campaign.sqlite")
        CHECK(test::run_demcal({command, (dir / "missing").string()}, dir / "out.log") == 2);
        CHECK_THAT(test::read_file(dir / "out.log"), Contains("missing' does not exist"));
        CHECK(fs::is_empty(dir / "empty"));
        CHECK_FALSE(fs::exists(dir / "missing"));
        // a FIFO is no folder (it was told it "holds no campaign.sqlite", probe 63)
        REQUIRE(::mkfifo((dir / "fifo").c_str(), 0600) == 0);
        CHECK(test::run_demcal({command, (dir / "fifo").string()}, dir / "out.log") == 2);
        CHECK_THAT(test::read_file(dir / "out.log"), Contains(command + ": DIR = '") && Contains("is not a folder"));
        fs::remove(dir / "fifo");
        // the store file itself given for its folder: named as a file, the folder to give named
        std::ofstream(dir / "campaign.sqlite") << "";
        CHECK(test::run_demcal({command, (dir / "campaign.sqlite").string()}, dir / "out.log") == 2);
        CHECK_THAT(test::read_file(dir / "out.log"),
                   Contains(command + ": DIR = '") && Contains("is a file, not a campaign folder"));
        CHECK(fs::file_size(dir / "campaign.sqlite") == 0);
        fs::remove(dir / "campaign.sqlite");
    }
    fs::remove_all(dir);
}

TEST_CASE("a store with no campaign recorded (its command killed first) is not called complete", "[cli][store]") {
    // probe 60: kill -9 about 30 ms into `shear` left a store without its campaign; resume said "nothing to resume:
    // every campaign is complete" with exit 0
    const fs::path dir = test::fresh_test_dir("store-no-campaign");
    { orchestrator::CampaignStore store(dir / "campaign.sqlite"); }
    CHECK(test::run_demcal({"resume", dir.string()}, dir / "resume.log") == 2);
    CHECK_THAT(test::read_file(dir / "resume.log"),
               Contains("holds a store with no campaign recorded in it") && Contains("run that command again"));
    CHECK(test::run_demcal({"status", dir.string()}, dir / "status.log") == 0);
    CHECK_THAT(test::read_file(dir / "status.log"), Contains("no campaigns in") && Contains("run that command again"));
    fs::remove_all(dir);
}

TEST_CASE("a store whose -wal or -shm is not a regular file is refused, writing nothing", "[cli][store]") {
    // a FIFO named campaign.sqlite-wal: "disk I/O error" with no reason (exit 1), and a -shm made beside it (probe 65)
    const fs::path dir = test::fresh_test_dir("store-side-files");
    const fs::path pristine = dir / "pristine", campaign = dir / "campaign";
    complete_campaign(dir, pristine);
    for (const char* side : {"campaign.sqlite-wal", "campaign.sqlite-shm"})
        for (const std::string command : {"status", "resume"}) {
            INFO(side << " " << command);
            fs::remove_all(campaign);
            fs::copy(pristine, campaign, fs::copy_options::recursive);
            fs::remove(campaign / side);
            REQUIRE(::mkfifo((campaign / side).c_str(), 0600) == 0);
            const FolderState before = folder_state(campaign);
            CHECK(test::run_demcal({command, campaign.string()}, dir / "out.log") == 2);
            CHECK_THAT(test::read_file(dir / "out.log"), Contains(std::string(side) + " is not a regular file"));
            CHECK(changes(before, campaign).empty());
        }
    fs::remove_all(dir);
}
