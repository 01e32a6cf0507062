// Shear campaigns on the kernel engine (`demcal shear --engine kernel`): the same store, cache and run directories
// as YADE's, the engine part of each run's identity, the kernel runs started as `demcal shear-run` subprocesses.
#include <catch2/catch.hpp>

#include "campaign_test_support.hpp"
#include "orchestrator/campaign_store.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>
#include <set>
#include <string>
#include <tuple>
#include <utility>

namespace fs = std::filesystem;
using namespace demcal;
using orchestrator::RunState;

namespace {
const std::string tiny = test::source_path("examples/materials/sand-tiny.json").string();
}

TEST_CASE("a kernel-engine campaign fits a failure line, stores its runs beside YADE's and never repeats one",
          "[kernel_engine]") {
    const fs::path dir = test::fresh_test_dir("kernel-campaign");
    const std::vector<std::string> args{"shear", tiny,         "--normal-stress", "3e3,5e3,7e3", "--engine",
                                        "kernel", "--jobs", "2", "--campaign",    dir.string()};
    REQUIRE(test::run_demcal(args, dir / "first.log") == 0);
    const std::string first = test::read_file(dir / "first.log");
    INFO(first);
    CHECK(first.find("kernel engine") != std::string::npos);
    CHECK(first.find("Peak failure line") != std::string::npos);
    const auto runs = test::stored_runs(dir);
    REQUIRE(runs.size() == 3);
    std::set<std::string> hashes;
    for (const auto& r : runs) {
        CHECK(r.state == RunState::done);
        CHECK(r.result.at("engine").get<std::string>().rfind("demcal-kernel-shear-box/", 0) == 0);
        CHECK(r.result.at("peak_shear_stress").get<double>() > 0);
        CHECK(std::abs(r.result.at("normal_stress_held").get<double>() / r.label.at("normal_stress").get<double>() -
                       1) < 0.1);
        // the directory says how to repeat the run, and its identity is not a YADE run's with the same parameters
        CHECK(test::read_file(r.run_dir / "ENGINE").find("shear-run params.json result.json") != std::string::npos);
        CHECK_FALSE(fs::exists(r.run_dir / "shear_box.py"));
        const std::string yade_identity = orchestrator::run_identity(
            test::read_file(test::source_path("yade_scripts/shear_box.py")), r.params);
        CHECK(r.hash != yade_identity);
        CHECK(orchestrator::params_digest(r.result.at("params")) == orchestrator::params_digest(r.params));  // its run
        hashes.insert(r.hash);
    }
    CHECK(hashes.size() == 3);
    // the second time everything is reused
    REQUIRE(test::run_demcal(args, dir / "second.log") == 0);
    CHECK(test::read_file(dir / "second.log").find("0 computed now, 3 reused") != std::string::npos);
    CHECK(test::stored_runs(dir).size() == 3);
    // a stop between the last run and the report (probe 64: kill -9 left 0-byte or cut plots, a missing JSON) is
    // mended by resume, which writes a complete campaign's report again from the store
    std::vector<fs::path> reports;
    for (const auto& e : fs::directory_iterator(dir))
        for (const char* stem : {"failure_line_", "shear_curves_"})
            if (e.path().filename().string().rfind(stem, 0) == 0) reports.push_back(e.path());
    REQUIRE_FALSE(reports.empty());
    for (const auto& f : reports) std::ofstream(f, std::ios::trunc).close();  // cut to nothing
    const auto json_it = std::find_if(reports.begin(), reports.end(), [](const fs::path& f) {
        return f.extension() == ".json";
    });
    REQUIRE(json_it != reports.end());
    const fs::path json = *json_it;
    fs::remove(json);
    REQUIRE(test::run_demcal({"resume", dir.string()}, dir / "resume.log") == 0);
    const std::string resumed = test::read_file(dir / "resume.log");
    INFO(resumed);
    CHECK(resumed.find("is written again from the store") != std::string::npos);
    CHECK(resumed.find("0 computed now, 3 reused") != std::string::npos);
    for (const auto& f : reports) CHECK(fs::file_size(f) > 0);
    CHECK(nlohmann::json::parse(test::read_file(json)).at("peak_failure_line").at("mu_b").get<double>() > 0);
    CHECK(test::stored_runs(dir).size() == 3);
}

TEST_CASE("the kernel engine refuses a YADE template and bad run parameters, naming them", "[kernel_engine]") {
    const fs::path dir = test::fresh_test_dir("kernel-refusals");
    CHECK(test::run_demcal({"shear", tiny, "-s", "2e3,4e3", "--engine", "kernel", "--template", tiny, "-c",
                            (dir / "c").string()},
                           dir / "template.log") == 2);
    CHECK(test::read_file(dir / "template.log").find("--engine yade only") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "c"));
    // shear-run itself speaks the YADE script's protocol: exit 2 and a DEMCAL_FAILURE params line naming the field
    nlohmann::json p = nlohmann::json::parse(test::read_file(tiny));
    p.erase("name");
    p.erase("description");
    p["normal_stress"] = 4e3;
    p["seed"] = 1;
    p["box_width"] = 0.005;
    orchestrator::write_text_file_atomically(dir / "params.json", p.dump());
    CHECK(test::run_demcal({"shear-run", (dir / "params.json").string(), (dir / "result.json").string()},
                           dir / "run.log") == 2);
    const std::string log = test::read_file(dir / "run.log");
    CHECK(log.find("DEMCAL_FAILURE params:") != std::string::npos);
    CHECK(log.find("box_width") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "result.json"));
}

TEST_CASE("runs that timed out are tried again by resume (a longer --timeout), runs the physics failed are not",
          "[kernel_engine]") {
    // a timeout was stored as a final failure: `resume --timeout 100` ran nothing and ended "3 failed", exit 1
    const fs::path dir = test::fresh_test_dir("kernel-campaign-timeout");
    const std::string camp = (dir / "c").string();
    // sand.json's runs take several seconds: the shortest --timeout (1 s) stops them all
    const std::string sand = test::source_path("examples/materials/sand.json").string();
    CHECK(test::run_demcal({"shear", sand, "-s", "3e3,5e3,7e3", "--engine", "kernel", "--jobs", "2", "--timeout",
                            "1", "--retries", "0", "--campaign", camp},
                           dir / "first.log") == 1);
    for (const auto& r : test::stored_runs(camp)) {
        CHECK(r.state == RunState::failed);
        CHECK(r.cause == "timeout");
    }
    const int rc = test::run_demcal({"resume", camp, "--timeout", "600", "--jobs", "2"}, dir / "resume.log");
    INFO(test::read_file(dir / "resume.log"));
    CHECK(rc == 0);
    for (const auto& r : test::stored_runs(camp)) CHECK(r.state == RunState::done);
    CHECK_THAT(test::read_file(dir / "resume.log"), Catch::Matchers::Contains("Peak failure line"));
    fs::remove_all(dir);
}

TEST_CASE("resume does not take another replicate's result, copied into an interrupted run's folder, for the run's",
          "[kernel_engine]") {
    // two replicates of one stress differ only in their seed: a result copied from one to the other passed every
    // check of the result's own values (probe 44); the kernel's results carry their parameters' digest
    const fs::path dir = test::fresh_test_dir("kernel-copied-result");
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3,6e3", "-r", "2", "--engine", "kernel", "--jobs", "2",
                              "--campaign", dir.string()},
                             dir / "first.log") == 0);
    auto runs = test::stored_runs(dir);
    REQUIRE(runs.size() == 4);
    const orchestrator::RunRecord* a = nullptr;
    const orchestrator::RunRecord* b = nullptr;
    for (const auto& r : runs)
        if (r.params.at("normal_stress").get<double>() == 3e3) (a ? b : a) = &r;
    REQUIRE((a && b));
    REQUIRE(a->params.at("seed") != b->params.at("seed"));
    const std::string own_result = test::read_file(b->run_dir / "result.json");
    const pid_t gone = ::fork();  // a pid that is no process's: the orchestrator that "died" while b ran
    if (gone == 0) ::_exit(0);
    ::waitpid(gone, nullptr, 0);
    {
        orchestrator::CampaignStore store(dir / "campaign.sqlite");
        store.mark_running(b->hash, 0, gone, "local");
        store.set_campaign_status(store.campaigns().front().id, orchestrator::CampaignStatus::interrupted);
    }
    fs::copy_file(a->run_dir / "result.json", b->run_dir / "result.json", fs::copy_options::overwrite_existing);
    REQUIRE(test::run_demcal({"resume", dir.string()}, dir / "resume.log") == 0);
    INFO(test::read_file(dir / "resume.log"));
    for (const auto& r : test::stored_runs(dir)) {
        if (r.hash != b->hash) continue;
        CHECK(r.state == RunState::done);
        CHECK(orchestrator::params_digest(r.result.at("params")) == orchestrator::params_digest(b->params));
        CHECK(r.result.at("peak_shear_stress") != a->result.at("peak_shear_stress"));
    }
    // the rerun computes the run's own result again (the kernel is deterministic; only the wall time differs)
    auto without_wall_time = [](const std::string& text) {
        auto j = nlohmann::json::parse(orchestrator::unsealed_result_text(text));
        j.erase("wall_time_s");
        return j;
    };
    CHECK(without_wall_time(test::read_file(b->run_dir / "result.json")) == without_wall_time(own_result));
}

TEST_CASE("a result whose parameters' digest is not the run's, or is no digest, is refused", "[kernel_engine]") {
    const nlohmann::json params{{"normal_stress", 5e3}, {"seed", 1}, {"density", 2650}};
    nlohmann::json result{{"schema", orchestrator::kShearResultSchema2}, {"peak_shear_stress", 3e3},
                          {"normal_stress_target", 5e3}};
    CHECK_NOTHROW(orchestrator::check_shear_result_values(result, "r", &params));  // YADE's /2: no digest
    result["params_sha256"] = orchestrator::params_digest(params);
    CHECK_NOTHROW(orchestrator::check_shear_result_values(result, "r", &params));
    nlohmann::json other_seed = params;
    other_seed["seed"] = 2;
    CHECK_THROWS_WITH(orchestrator::check_shear_result_values(result, "r", &other_seed),
                      Catch::Contains("other parameters"));
    result["params_sha256"] = "ABC";
    CHECK_THROWS_WITH(orchestrator::check_shear_result_values(result, "r", &params),
                      Catch::Contains("params_sha256 = \"ABC\" is not 64 lowercase hex digits"));
}

TEST_CASE("a result of schema 3 is its run's only when it records the run's parameters", "[kernel_engine]") {
    // both engines write the params.json object they ran; another run's result (same stress, other seed) is refused
    const nlohmann::json params{{"normal_stress", 5e3}, {"seed", 1}, {"density", 2650}};
    nlohmann::json result{{"schema", orchestrator::kShearResultSchema}, {"peak_shear_stress", 3e3},
                          {"normal_stress_target", 5e3}};
    CHECK_THROWS_WITH(orchestrator::check_shear_result_values(result, "r", &params),
                      Catch::Contains("params = <missing> is not the object of the run's params.json"));
    result["params"] = "x";
    CHECK_THROWS_WITH(orchestrator::check_shear_result_values(result, "r", &params),
                      Catch::Contains("params = \"x\" is not the object"));
    // written as read: 2650.0 from a computed level and 2650 from a file are one value
    result["params"] = {{"normal_stress", 5000}, {"seed", 1}, {"density", 2650.0}};
    CHECK_NOTHROW(orchestrator::check_shear_result_values(result, "r", &params));
    CHECK_NOTHROW(orchestrator::check_shear_result_values(result, "r", nullptr));
    result["params"]["seed"] = 2;
    CHECK_THROWS_WITH(orchestrator::check_shear_result_values(result, "r", &params),
                      Catch::Contains("seed = 2 where this run has 1") && Catch::Contains("another run's result"));
    result["params"]["seed"] = 1;
    result["params"].erase("density");
    CHECK_THROWS_WITH(orchestrator::check_shear_result_values(result, "r", &params),
                      Catch::Contains("density is missing"));
    result["params"]["density"] = 2650;
    result["params"]["damping"] = 0.2;
    CHECK_THROWS_WITH(orchestrator::check_shear_result_values(result, "r", &params),
                      Catch::Contains("damping = 0.2 is not this run's"));
    // a schema that is no string (a damaged store row) is no /3 result: refused as input, not a library's type error
    result["schema"] = 5;
    result.erase("params");
    CHECK_NOTHROW(orchestrator::check_shear_result_values(result, "r", &params));
}

TEST_CASE("status tells a folder's campaigns apart by what they ran",
          "[kernel_engine]") {
    // probe 59: a calibration's folder listed 42 campaigns as digests only ("shear-0f5a811c912e [complete] ...")
    const fs::path dir = test::fresh_test_dir("kernel-status");
    nlohmann::json material = nlohmann::json::parse(test::read_file(tiny));
    material["friction_coefficient"] = 0.3;
    material["name"] = "sand-tiny, rougher";
    const fs::path other = dir / "other.json";
    std::ofstream(other) << material.dump();
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3,5e3,7e3", "--engine", "kernel", "-c", dir.string()},
                             dir / "a.log") == 0);
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3,5e3,7e3", "--engine", "kernel", "--seed", "5", "-c",
                              dir.string()},
                             dir / "b.log") == 0);
    REQUIRE(test::run_demcal({"shear", other.string(), "-s", "3e3,5e3,7e3", "--engine", "kernel", "-c", dir.string()},
                             dir / "c.log") == 0);
    // the first campaign's stresses in another order: the same campaign (probe 61: a second one opened)
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "7e3,3e3,5000", "--engine", "kernel", "-c", dir.string()},
                             dir / "d.log") == 0);
    REQUIRE(test::run_demcal({"status", dir.string()}, dir / "status.log") == 0);
    const std::string status = test::read_file(dir / "status.log");
    std::size_t campaigns = 0;
    for (std::size_t at = status.find("\nshear-"); at != std::string::npos; at = status.find("\nshear-", at + 1)) ++campaigns;
    CHECK(campaigns + (status.rfind("shear-", 0) == 0 ? 1 : 0) == 3);
    INFO(status);
    using Catch::Matchers::Contains;
    // every campaign names its material and the field in which the campaigns differ (the name: held-back suite, the
    // stored spec had lost it); the fields all share are left out
    CHECK_THAT(status, Contains("  kernel engine, material 'sand-tiny', friction_coefficient 0.5; 3 normal stresses "
                                "3000 to 7000 Pa x 1 packings from seed 1\n") &&
                           Contains("  kernel engine, material 'sand-tiny', friction_coefficient 0.5; 3 normal "
                                    "stresses 3000 to 7000 Pa x 1 packings from seed 5\n") &&
                           !Contains("density") &&
                           Contains("  kernel engine, material 'sand-tiny, rougher', friction_coefficient 0.3; 3 normal "
                                    "stresses"));
    fs::remove_all(dir);
}

TEST_CASE("status names every level of a one-parameter study, the base's too", "[kernel_engine]") {
    // probe 62: each level is one campaign, so each value is seen once; the tie went to the smallest text, and the
    // lowest level was shown without its friction, read as the base material
    const fs::path dir = test::fresh_test_dir("kernel-status-study");
    REQUIRE(test::run_demcal({"sensitivity", tiny, "--params", "friction_coefficient", "--levels", "3", "-s",
                              "3e3,5e3,7e3", "--engine", "kernel", "-c", dir.string()},
                             dir / "study.log") == 0);
    REQUIRE(test::run_demcal({"status", dir.string()}, dir / "status.log") == 0);
    // (campaigns listed, campaigns whose line names the friction) in a status output
    const auto count_labelled = [](const std::string& status) {
        std::size_t labelled = 0, campaigns = 0;
        for (std::size_t at = status.find("  kernel engine"); at != std::string::npos;
             at = status.find("  kernel engine", at + 1)) {
            ++campaigns;
            const std::string line = status.substr(at, status.find('\n', at) - at);
            if (line.find(", friction_coefficient ") != std::string::npos) ++labelled;
        }
        return std::pair{campaigns, labelled};
    };
    const std::string status = test::read_file(dir / "status.log");
    INFO(status);
    auto [campaigns, labelled] = count_labelled(status);
    CHECK(campaigns == 3);
    CHECK(labelled == campaigns);
    // a campaign of the base material added to the folder (probe 62b: a calibration's) made the base's friction the
    // most common value, and the study's base level lost its label again; so did a majority (3 of 5, review of
    // stop 63): a field is left out only where every campaign holds the same value
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3,5e3,7e3", "--engine", "kernel", "-c", dir.string()},
                             dir / "plain.log") == 0);
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3,5e3,7e3", "--engine", "kernel", "--seed", "7", "-c",
                              dir.string()},
                             dir / "plain7.log") == 0);
    REQUIRE(test::run_demcal({"status", dir.string()}, dir / "status2.log") == 0);
    const std::string status2 = test::read_file(dir / "status2.log");
    INFO(status2);
    std::tie(campaigns, labelled) = count_labelled(status2);
    CHECK(campaigns == 5);
    CHECK(labelled == campaigns);
    fs::remove_all(dir);
}

TEST_CASE("a list typed with blanks after its commas is the same list", "[kernel_engine]") {
    // probe 61: "-s '3e3, 5e3, 7e3'" was refused (' 5e3' is not a number), as were --seeds "1, 2" and --theta "70, 60"
    const fs::path dir = test::fresh_test_dir("kernel-spaced-list");
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3,5e3,7e3", "--engine", "kernel", "-c", dir.string()},
                             dir / "a.log") == 0);
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3, 5e3,\t7e3 ", "--engine", "kernel", "-c", dir.string()},
                             dir / "b.log") == 0);
    const std::string again = test::read_file(dir / "b.log");
    INFO(again);
    CHECK_THAT(again, Catch::Matchers::Contains("0 computed now, 3 reused"));  // the same campaign, its runs reused
    // an item of blanks only is still an empty item
    CHECK(test::run_demcal({"shear", tiny, "-s", "3e3, ,7e3", "--engine", "kernel", "-c", dir.string()},
                           dir / "c.log") == 2);
    CHECK_THAT(test::read_file(dir / "c.log"), Catch::Matchers::Contains("'3e3, ,7e3' has an empty item"));
    fs::remove_all(dir);
}

TEST_CASE("a campaign named by its stresses in the order typed (before they were sorted) is continued, not doubled",
          "[kernel_engine]") {
    // review of stop 61: sorting the stresses renamed every campaign typed out of order; resume then opened a second
    const fs::path dir = test::fresh_test_dir("kernel-typed-order");
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "3e3,5e3,7e3", "--engine", "kernel", "-c", (dir / "new").string()},
                             dir / "new.log") == 0);
    nlohmann::json legacy_spec;
    {
        orchestrator::CampaignStore store(dir / "new" / "campaign.sqlite");
        REQUIRE(store.campaigns().size() == 1);
        legacy_spec = store.campaigns().front().spec;
    }
    // the store an earlier demcal made for -s 7e3,3e3,5e3: its spec and name keep the typed order, no runs yet
    legacy_spec["normal_stresses"] = {7e3, 3e3, 5e3};
    legacy_spec.erase("material_name");
    const std::string legacy_name =
        orchestrator::legacy_campaign_name(orchestrator::ShearCampaignSpec::from_json(legacy_spec));
    fs::create_directories(dir / "old");
    {
        orchestrator::CampaignStore store(dir / "old" / "campaign.sqlite");
        store.ensure_campaign(legacy_name, orchestrator::CampaignKind::shear, legacy_spec);
    }
    REQUIRE(test::run_demcal({"shear", tiny, "-s", "7e3,3e3,5e3", "--engine", "kernel", "-c", (dir / "old").string()},
                             dir / "old.log") == 0);
    REQUIRE(test::run_demcal({"resume", (dir / "old").string()}, dir / "resume.log") == 0);
    orchestrator::CampaignStore store(dir / "old" / "campaign.sqlite");
    const auto campaigns = store.campaigns();
    REQUIRE(campaigns.size() == 1);
    CHECK(campaigns.front().name == legacy_name);
    CHECK(store.campaign_runs(campaigns.front().id).size() == 3);
    // a number written otherwise (2650.0 for 2650) is the same material: the same campaign (probe 61)
    nlohmann::json respelled = nlohmann::json::parse(test::read_file(tiny));
    REQUIRE(respelled.at("density").is_number_integer());
    respelled["density"] = respelled["density"].get<double>();
    std::ofstream(dir / "respelled.json") << respelled.dump();
    REQUIRE(test::run_demcal({"shear", (dir / "respelled.json").string(), "-s", "3e3,5e3,7e3", "--engine", "kernel",
                              "-c", (dir / "new").string()},
                             dir / "respelled.log") == 0);
    CHECK(orchestrator::CampaignStore(dir / "new" / "campaign.sqlite").campaigns().size() == 1);
    fs::remove_all(dir);
}
