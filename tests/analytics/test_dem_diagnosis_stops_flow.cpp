// diagnose_dem when a candidate's value stops the flow (a cohesion that arches the bed): the search keeps to the
// flowing side, the values that stopped it are reported, and a declared material that does not flow is refused.
#include "analytics/dem_diagnosis.hpp"
#include "synthetic_silo_rates.hpp"
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

namespace an = demcal::analytics;
using demcal::test::SyntheticSilo;

TEST_CASE("silo-dem: values that stop the flow confine the search to the flowing side and are reported",
          "[diagnose][silo-dem]") {
    const SyntheticSilo model{3.0, 0.2};
    const auto data = model.measured(0.1);
    int calls = 0;
    an::DemDiagnoseOptions o;
    o.grid_points = 5;  // 0, 0.075, 0.15, 0.225, 0.3: the last two arch the bed
    const auto setup = model.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.3, data, &calls);
    const auto r = an::diagnose_dem(data, model.rates(data, 0.0), {setup}, o);
    REQUIRE(r.candidates.size() == 1);
    const auto& c = r.candidates[0];
    REQUIRE(c.available);
    CHECK(c.stops_flow == std::vector<double>{0.225, 0.3});
    CHECK(c.spec.upper == 0.15);  // the last flowing value run
    CHECK(c.spec.lower == 0.0);
    CHECK(c.fitted == Approx(0.1).margin(0.01));
    CHECK(c.interval_low <= 0.1);
    CHECK(c.interval_high >= 0.1);
    CHECK(r.effect == 0);
    CHECK(r.rmse_after < 0.5 * r.rmse_before);
    const auto j = r.to_json(data);
    CHECK(j["candidates"][0]["stops_flow"].size() == 2);
}

TEST_CASE("silo-dem: a coarse grid that stops the flow at its first step is filled in toward the stop",
          "[diagnose][silo-dem]") {
    const SyntheticSilo model{3.0, 0.2};
    const auto data = model.measured(0.1);
    int calls = 0;
    an::DemDiagnoseOptions o;
    o.grid_points = 3;  // 0 (declared), 0.2, 0.4: both beyond the declared value arch the bed
    const auto setup = model.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.4, data, &calls);
    const auto r = an::diagnose_dem(data, model.rates(data, 0.0), {setup}, o);
    REQUIRE(r.candidates.size() == 1);
    const auto& c = r.candidates[0];
    INFO(c.unavailable);
    REQUIRE(c.available);
    // halved toward the stop: 0.1, then 0.05 and 0.15 (all flowing)
    for (double v : {0.1, 0.05, 0.15}) CHECK(std::find(c.evaluated.begin(), c.evaluated.end(), v) != c.evaluated.end());
    CHECK(c.stops_flow == std::vector<double>{0.2, 0.4});
    CHECK(c.fitted == Approx(0.1).margin(0.01));
    CHECK(r.effect == 0);
}

TEST_CASE("silo-dem: a candidate that stops the flow next to the declared value is not tried, and says why",
          "[diagnose][silo-dem]") {
    const SyntheticSilo model{3.0, 0.01};
    const auto data = model.measured(0.0);
    int calls = 0;
    an::DemDiagnoseOptions o;
    o.grid_points = 3;  // 0 (declared), 0.2, 0.4; halved toward the stop: 0.1, 0.05, 0.025 arch the bed too
    const auto setup = model.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.4, data, &calls);
    const auto r = an::diagnose_dem(data, model.rates(data, 0.0), {setup}, o);
    REQUIRE(r.candidates.size() == 1);
    CHECK_FALSE(r.candidates[0].available);
    CHECK_THAT(r.candidates[0].unavailable, Catch::Matchers::Contains("the flow stops at 0.025"));
    CHECK(calls == 5);  // 0.2, 0.4, then one halving per round
    CHECK(r.effect == -1);
}

TEST_CASE("silo-dem: a declared material that does not discharge where the data have a rate is refused",
          "[diagnose][silo-dem]") {
    const SyntheticSilo model{3.0, 0.2};
    const auto data = model.measured(0.1);
    int calls = 0;
    auto rates = model.rates(data, 0.1);
    rates[2] = NAN;  // (40 deg: no steady rate)
    const auto setup = model.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.3, data, &calls);
    CHECK_THROWS_WITH(an::diagnose_dem(data, rates, {setup}, {}),
                      Catch::Matchers::Contains("does not discharge at theta40"));
    CHECK(calls == 0);
}
