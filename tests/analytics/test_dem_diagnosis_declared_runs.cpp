// diagnose_dem on a candidate whose response no low-degree curve over its range follows (nearly flat, then a steep
// fall: cohesion close to arching). The smoothed curve then misses the declared material's own runs, and the
// "improvement" from the declared value to the fit is the curve's error, not an effect: on clean data nothing may be
// named, and an effect must always beat the declared material's real runs out of sample.
#include "analytics/dem_diagnosis.hpp"
#include "synthetic_silo_rates.hpp"
#include <catch2/catch.hpp>

namespace an = demcal::analytics;
using demcal::test::SyntheticSilo;

TEST_CASE("silo-dem: a smoothed curve that misses the declared runs names no effect on clean data",
          "[diagnose][silo-dem]") {
    SyntheticSilo model;
    model.steep_near = 0.3;
    const auto data = model.measured(0.0);  // the declared material's own rates
    int calls = 0;
    const auto setup = model.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.3, data, &calls);
    const auto r = an::diagnose_dem(data, model.rates(data, 0.0), {setup}, {});
    REQUIRE(r.candidates.size() == 1);
    const auto& c = r.candidates[0];
    REQUIRE(c.available);
    INFO("chi2 declared " << c.chi2_declared << ", fitted " << c.chi2_fitted << ", CV RMSE " << c.cv_rmse
                          << " against the declared runs' " << r.rmse_before << ", fitted " << c.fitted);
    CHECK(r.effect == -1);
    CHECK_FALSE(c.cv_gain);
}

TEST_CASE("silo-dem: the same steep candidate is named where the data hold its effect", "[diagnose][silo-dem]") {
    SyntheticSilo model;
    model.steep_near = 0.3;
    const auto data = model.measured(0.27);  // rates 22 % below the declared material's
    int calls = 0;
    const auto setup = model.candidate("cohesion", "grain_grain.surface_energy_J_m2", 0.3, data, &calls);
    const auto r = an::diagnose_dem(data, model.rates(data, 0.0), {setup}, {});
    REQUIRE(r.effect == 0);
    CHECK(r.candidates[0].cv_rmse < 0.5 * r.rmse_before);
}

TEST_CASE("silo-dem: measured rates an order of magnitude off the declared runs' are named as another unit",
          "[diagnose][silo-dem]") {
    SyntheticSilo model;
    const auto data = model.measured(0.0);
    const auto declared = model.rates(data, 0.0);
    CHECK(an::rate_scale_mismatch(data, declared).empty());  // the declared material's own rates
    auto scaled = data;
    for (double& rate : scaled.rate_g_s) rate *= 3;  // an effect's size of change, not a unit's
    CHECK(an::rate_scale_mismatch(scaled, declared).empty());
    for (const double factor : {1e-3, 1.0 / 60, 60.0, 3600.0}) {  // kg/s, per minute, per hour under rate_g_s
        auto other_unit = data;
        for (double& rate : other_unit.rate_g_s) rate *= factor;
        INFO("factor " << factor);
        CHECK_THAT(an::rate_scale_mismatch(other_unit, declared),
                   Catch::Contains("times the declared material's") && Catch::Contains("another unit"));
    }
    CHECK_THROWS(an::rate_scale_mismatch(data, {1.0}));  // one rate per condition
}
