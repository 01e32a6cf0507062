// diagnose_dem when two candidates explain the rates alike (cohesion and wall friction both lower the rate): the
// better one is named, the other reported as a rival with a warning; a candidate that fits clearly worse is not.
#include "analytics/dem_diagnosis.hpp"
#include "synthetic_silo_rates.hpp"
#include <catch2/catch.hpp>

namespace an = demcal::analytics;
using demcal::test::SyntheticSilo;

TEST_CASE("silo-dem: a candidate that explains the data as well as the effect is named as its rival",
          "[diagnose][silo-dem]") {
    const SyntheticSilo truth{3.0};
    const auto data = truth.measured(0.1);
    int calls = 0;
    // the same effect on the rates through another parameter (scaled: 0.2 of it is 0.1 of the truth's)
    const SyntheticSilo alike{1.5};
    const auto effect = truth.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.3, data, &calls);
    const auto rival = alike.candidate("wall_friction", "grain_wall.friction", 0.6, data, &calls);
    const auto r = an::diagnose_dem(data, truth.rates(data, 0.0), {effect, rival}, {});
    REQUIRE(r.effect >= 0);
    REQUIRE(r.rivals.size() == 1);
    CHECK(r.rivals[0] != r.effect);
    const std::string named = r.candidates[std::size_t(r.effect)].spec.name;
    const std::string other = r.candidates[std::size_t(r.rivals[0])].spec.name;
    CHECK(named != other);
    bool warned = false;
    for (const auto& w : r.warnings) warned = warned || w.find("cannot tell the two apart") != std::string::npos;
    CHECK(warned);
    CHECK(r.to_json(data)["effect"]["rivals"].size() == 1);
}

TEST_CASE("silo-dem: a candidate that fits clearly worse is no rival", "[diagnose][silo-dem]") {
    const SyntheticSilo truth{3.0};
    const auto data = truth.measured(0.1);
    int calls = 0;
    // a weak effect that cannot reach the measured drop within its bounds (at most 1 - exp(-0.3 * 0.1) = 3 %)
    const SyntheticSilo weak{0.3};
    const auto effect = truth.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.3, data, &calls);
    const auto other = weak.candidate("restitution", "grain_grain.restitution", 0.1, data, &calls);
    const auto r = an::diagnose_dem(data, truth.rates(data, 0.0), {effect, other}, {});
    REQUIRE(r.effect == 0);
    CHECK(r.rivals.empty());
    CHECK(r.to_json(data)["effect"]["rivals"].empty());
}
