// Fuzz tests of the orchestrator's readers: material JSON, the campaign store file and a run's result.json. Every
// seeded mutation of a valid file is either read or refused with std::invalid_argument (exit code 2) or, for a result,
// as damaged (the run is run again); anything else fails.
#include "analytics/user_input.hpp"
#include "fuzz_mutations.hpp"
#include "orchestrator/campaign_store.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"
#include "orchestrator/shear_params.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>

using namespace demcal;
namespace fs = std::filesystem;

TEST_CASE("fuzz: the material JSON reader reads or refuses every mutation", "[fuzz][input]") {
    const std::string valid = test::read_file(std::string(DEMCAL_SOURCE_DIR) + "/examples/materials/sand-tiny.json");
    int accepted = 0, refused = 0;
    for (std::uint32_t seed = 1; seed <= 3000; ++seed) {
        try {
            orchestrator::validate_material(analytics::parse_json_text(test::mutated(valid, seed), "material"));
            ++accepted;
        } catch (const std::invalid_argument&) {
            ++refused;
        } catch (const std::exception& e) {
            FAIL("seed " << seed << ": " << e.what());
        }
    }
    INFO(accepted << " accepted, " << refused << " refused");
    CHECK(refused > 0);
}

TEST_CASE("fuzz: a damaged campaign store is refused or read, never crashes", "[fuzz][store]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-fuzz-store-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    {
        orchestrator::CampaignStore store(dir / "valid.sqlite");
        const auto id =
            store.ensure_campaign("c", orchestrator::CampaignKind::shear, {{"material", {{"density", 2650}}}}).id;
        for (int i = 0; i < 20; ++i) {
            const std::string hash = "h" + std::to_string(i);
            store.ensure_run(id, hash, {{"normal_stress", 1e3 * (i + 1)}}, dir / "runs" / hash, {{"replicate", i}});
            store.mark_running(hash, 1, 1, "local");
            store.mark_done(hash, {{"peak_shear_stress", 100.0 * i}}, 0, 1, 1);
        }
    }
    const std::string valid = test::read_file(dir / "valid.sqlite");
    REQUIRE(valid.size() > 4096);
    int opened = 0, refused = 0, read_errors = 0;
    for (std::uint32_t seed = 1; seed <= 800; ++seed) {
        const fs::path file = dir / "mutated.sqlite";
        fs::remove(file);
        fs::remove(dir / "mutated.sqlite-wal");
        fs::remove(dir / "mutated.sqlite-shm");
        std::string bytes = valid;
        // the fuzzer's edits, but in place: a store keeps its size, its damage is in the pages
        const std::string edit = test::mutated(valid, seed);
        for (std::size_t i = 0; i < bytes.size() && i < edit.size(); ++i) bytes[i] = edit[i];
        if (seed % 10 == 0) bytes.resize(bytes.size() * (seed % 7) / 7);  // and some truncated
        std::ofstream(file, std::ios::binary) << bytes;
        try {
            orchestrator::CampaignStore store(file);
            ++opened;
            try {  // a page that integrity_check passes may still hold values demcal refuses
                for (const auto& c : store.campaigns()) store.campaign_runs(c.id);
            } catch (const std::invalid_argument&) {
                ++read_errors;
            }
        } catch (const std::invalid_argument&) {
            ++refused;
        } catch (const std::exception& e) {
            FAIL("seed " << seed << ": " << e.what());
        }
    }
    INFO(opened << " opened (" << read_errors << " refused while reading), " << refused << " refused");
    CHECK(refused > 0);
    fs::remove_all(dir);
}

TEST_CASE("fuzz: a damaged shear result is refused or read whole, never taken for another result", "[fuzz][input]") {
    // a sealed result as demcal shear-run and shear_box.py write it (schema demcal.shear_result/3)
    nlohmann::json result = {{"schema", orchestrator::kShearResultSchema},
                             {"params", {{"normal_stress", 5e3}, {"seed", 3}}},
                             {"curve", {{"displacement", {0.0, 1e-4, 2e-4}}, {"shear_stress", {0.0, 2100.5, 3300.25}}}},
                             {"peak_shear_stress", 3300.25},
                             {"residual_shear_stress", 2950.0},
                             {"wall_time_s", 12.5}};
    const std::string valid = orchestrator::sealed_result_text(result.dump(1) + "\n");
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-fuzz-result-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    int same = 0, refused = 0;
    for (std::uint32_t seed = 1; seed <= 2000; ++seed) {
        const std::string text = test::mutated(valid, seed);
        orchestrator::write_text_file_atomically(dir / "result.json", text);
        try {
            const auto read = orchestrator::read_shear_result(dir / "result.json");
            // read only when nothing that counts changed (a cut at the very end is no cut)
            CHECK(read == result);
            ++same;
        } catch (const std::invalid_argument&) {
            ++refused;
        } catch (const orchestrator::DamagedResult&) {
            ++refused;
        } catch (const std::exception& e) {
            FAIL("seed " << seed << ": " << e.what());
        }
    }
    fs::remove_all(dir);
    INFO(same << " read unchanged, " << refused << " refused");
    CHECK(refused > 1900);
}
