// Failed packings in a study or a calibration (calibration/campaign_evaluator): a line left with too few finished
// runs to fit gets rounds of fresh packings (the next seeds) instead of stopping the command for good; which rounds
// run follows from the store, so the same command again computes nothing and decides the same.
// The material shears its box at 2 m/s: the lid servo cannot hold the normal stress, so every kernel run fails by the
// box's own check (a physical failure: never retried), in well under a second.
#include "calibration/campaign_evaluator.hpp"
#include "demcal_cli.hpp"
#include "orchestrator/campaign_store.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace demcal;

namespace {

struct StoredLine {
    std::set<long> base_seeds;
    int runs = 0, failed = 0;
    std::set<std::string> labels;
};

StoredLine stored(const fs::path& dir) {
    orchestrator::CampaignStore store(dir / "campaign.sqlite");
    StoredLine s;
    for (const auto& c : store.campaigns()) {
        s.base_seeds.insert(c.spec.at("base_seed").get<long>());
        s.labels.insert(c.spec.at("label").get<std::string>());
        for (const auto& r : store.campaign_runs(c.id)) {
            ++s.runs;
            if (r.state == orchestrator::RunState::failed) ++s.failed;
        }
    }
    return s;
}

}  // namespace

TEST_CASE("a line whose runs all fail gets two rounds of fresh packings, then a clear error, the same on a rerun") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-replacement-" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto material = nlohmann::json::parse(test::read_file(fs::path(DEMCAL_SOURCE_DIR) /
                                                          "examples/materials/sand-scale-tiny.json"));
    material["particle_radius"] = 0.0045;
    material["shear_velocity"] = 2.0;
    std::ofstream(dir / "material.json") << material.dump();
    const std::string args = "sensitivity '" + (dir / "material.json").string() +
                             "' --params friction_coefficient --levels 3 -s 3e3,5e3,7e3 --engine kernel --jobs 2"
                             " --dir '" + (dir / "c").string() + "'";
    const int rc = test::run_demcal_command(args, dir / "first.log");
    const std::string log = test::read_file(dir / "first.log");
    INFO(log);
    CHECK(rc != 0);
    CHECK(rc != 2);  // not a refusal of the input: the runs themselves failed
    CHECK(log.find("normal_stress") != std::string::npos);  // the failure's field named
    CHECK(log.find("Segmentation") == std::string::npos);
    const StoredLine first = stored(dir / "c");
    // the base line: seeds 1, then 2 and 3 (one packing per stress each round), 9 runs, all failed, none retried
    CHECK(first.base_seeds == std::set<long>{1, 2, 3});
    CHECK(first.runs == 9);
    CHECK(first.failed == 9);
    CHECK(first.labels.count("sensitivity replacement 2") == 1);

    // The same command again: the same rounds from the store, nothing computed, the same answer.
    const int rc_again = test::run_demcal_command(args, dir / "second.log");
    INFO(test::read_file(dir / "second.log"));
    CHECK(rc_again == rc);
    const StoredLine again = stored(dir / "c");
    CHECK(again.runs == 9);
    CHECK(again.base_seeds == first.base_seeds);

    // demcal resume on the folder: the two campaigns whose failures fresh packings replaced are said to be so (each
    // resume reported them as failed lines of their own, exit 1, probe 62); the last round's failures are its own
    const int rc_resume = test::run_demcal_command("resume '" + (dir / "c").string() + "'", dir / "resume.log");
    const std::string resumed = test::read_file(dir / "resume.log");
    INFO(resumed);
    CHECK(rc_resume == 1);
    std::size_t replaced = 0;
    for (std::size_t at = resumed.find("were replaced by the fresh packings of campaign"); at != std::string::npos;
         at = resumed.find("were replaced by the fresh packings of campaign", at + 1))
        ++replaced;
    CHECK(replaced == 2);
    CHECK(again.runs == stored(dir / "c").runs);  // nothing rerun
    fs::remove_all(dir);
}

TEST_CASE("a campaign replaces another's failed runs only as the next round of the same line") {
    orchestrator::ShearCampaignSpec line;
    line.material = {{"friction_coefficient", 0.5}};
    line.normal_stresses = {3e3, 5e3};
    line.replicates = 2;
    line.base_seed = 1;
    line.label = "scale r=0.004";
    auto round1 = line;
    round1.base_seed = 3;
    round1.label = calibration::replacement_label(line.label, 1);
    CHECK(round1.label == "scale r=0.004 replacement 1");
    auto round2 = round1;
    round2.base_seed = 5;
    round2.label = calibration::replacement_label(line.label, 2);
    CHECK(calibration::replaces_failed_runs(round1, line));
    CHECK(calibration::replaces_failed_runs(round2, round1));
    CHECK_FALSE(calibration::replaces_failed_runs(round2, line));   // not the next round
    CHECK_FALSE(calibration::replaces_failed_runs(line, round1));   // not backwards
    auto other_material = round1;
    other_material.material["friction_coefficient"] = 0.6;
    CHECK_FALSE(calibration::replaces_failed_runs(other_material, line));
    auto other_seeds = round1;
    other_seeds.base_seed = 7;
    CHECK_FALSE(calibration::replaces_failed_runs(other_seeds, line));
    auto unlabelled = line;
    unlabelled.label = "";
    auto unlabelled_round1 = round1;
    unlabelled_round1.label = calibration::replacement_label("", 1);
    CHECK(unlabelled_round1.label == "replacement 1");
    CHECK(calibration::replaces_failed_runs(unlabelled_round1, unlabelled));
}
