// Fuzz tests of the analytics readers: thousands of seeded mutations of valid files, each either read or refused with
// std::invalid_argument (what every command turns into exit code 2); any other exception or a crash fails.
#include "analytics/dem_diagnosis.hpp"
#include "analytics/discharge_models.hpp"
#include "analytics/measured_data.hpp"
#include "analytics/user_input.hpp"
#include "fuzz_mutations.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>

#include <sstream>

using namespace demcal;

namespace {
constexpr std::uint32_t kMutations = 3000;

// Runs `read` on every mutation of `valid`; counts the accepted and refused ones, fails on anything else.
template <class Read>
void fuzz(const std::string& valid, Read read) {
    REQUIRE_NOTHROW(read(valid));
    int accepted = 0, refused = 0;
    for (std::uint32_t seed = 1; seed <= kMutations; ++seed) {
        const std::string input = test::mutated(valid, seed);
        try {
            read(input);
            ++accepted;
        } catch (const std::invalid_argument& e) {
            ++refused;
            if (std::string(e.what()).size() > 2000) FAIL("seed " << seed << ": a message of " << std::string(e.what()).size() << " characters");
        } catch (const std::exception& e) {
            FAIL("seed " << seed << ": " << typeid(e).name() << ": " << e.what());
        }
    }
    INFO(accepted << " accepted, " << refused << " refused");
    CHECK(accepted + refused == static_cast<int>(kMutations));
    CHECK(refused > 0);
}
}  // namespace

TEST_CASE("fuzz: the geometry JSON reader reads or refuses every mutation", "[fuzz][input]") {
    fuzz(test::read_file(std::string(DEMCAL_SOURCE_DIR) + "/examples/diagnose/silo_105mm_wheat.json"),
         [](const std::string& text) {
             analytics::geometry_from_json(analytics::parse_json_text(text, "geometry"));
         });
}

TEST_CASE("fuzz: the measured-data CSV reader reads or refuses every mutation", "[fuzz][input]") {
    std::string valid = test::read_file(std::string(DEMCAL_SOURCE_DIR) + "/examples/diagnose/oldal_clean.csv");
    valid.resize(std::min<std::size_t>(valid.size(), 4000));  // whole rows suffice; keeps the test short
    valid.resize(valid.rfind('\n') + 1);
    fuzz(valid, [](const std::string& text) {
        std::istringstream in(text);
        analytics::validate_measured(analytics::parse_csv(in, "data.csv"), analytics::MeasuredKind::discharge);
    });
}

TEST_CASE("fuzz: the silo-dem measured-rate reader reads or refuses every mutation", "[fuzz][input]") {
    fuzz(test::read_file(std::string(DEMCAL_SOURCE_DIR) + "/examples/diagnose/silo_dem/wall045_measured.csv"),
         [](const std::string& text) {
             std::istringstream in(text);
             analytics::silo_measurements_from(analytics::parse_csv(in, "data.csv"));
         });
}
