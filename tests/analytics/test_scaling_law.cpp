// Particle-enlargement laws: the seed's eqs. 3.1-3.2 regenerated from noisy points at the seed's radii.
#include "analytics/scaling_law.hpp"

#include <catch2/catch.hpp>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include <cmath>
#include <memory>
#include <vector>

using namespace demcal::analytics;

namespace {
const std::vector<double> radii_mm{1, 1.5, 2, 3, 5, 7};  // seed section 3.2.1
}

TEST_CASE("E(r) = A r + B is recovered with intervals that cover the truth", "[scaling_law]") {
    std::unique_ptr<gsl_rng, decltype(&gsl_rng_free)> rng(gsl_rng_alloc(gsl_rng_mt19937), gsl_rng_free);
    int covered_a = 0, covered_b = 0;
    const int trials = 200;
    for (int t = 0; t < trials; ++t) {
        gsl_rng_set(rng.get(), 100 + t);
        std::vector<double> e;
        for (double r : radii_mm) e.push_back(91.52 * r + 148.86 + gsl_ran_gaussian(rng.get(), 10.0));
        const auto fit = fit_linear_law(radii_mm, e);
        covered_a += fit.params[0].low <= 91.52 && 91.52 <= fit.params[0].high;
        covered_b += fit.params[1].low <= 148.86 && 148.86 <= fit.params[1].high;
    }
    // 95 % intervals: about 190 of 200 cover; 180 leaves room for chance but not for a wrong standard error.
    CHECK(covered_a >= 180);
    CHECK(covered_b >= 180);
}

TEST_CASE("nu(r) = C r^-D is recovered by the nonlinear fit", "[scaling_law]") {
    std::vector<double> nu;
    for (double r : radii_mm) nu.push_back(0.2344 * std::pow(r, -1.282));
    SECTION("exact points give the constants") {
        const auto fit = fit_power_law(radii_mm, nu);
        CHECK(fit.converged);
        CHECK(fit.params[0].value == Approx(0.2344).epsilon(1e-6));
        CHECK(fit.params[1].value == Approx(1.282).epsilon(1e-6));
        CHECK(fit(2.0) == Approx(0.2344 * std::pow(2.0, -1.282)).epsilon(1e-6));
    }
    SECTION("noisy points: the intervals cover the truth and are not absurdly wide") {
        std::unique_ptr<gsl_rng, decltype(&gsl_rng_free)> rng(gsl_rng_alloc(gsl_rng_mt19937), gsl_rng_free);
        gsl_rng_set(rng.get(), 7);
        int covered = 0;
        const int trials = 200;
        for (int t = 0; t < trials; ++t) {
            std::vector<double> noisy;
            for (double v : nu) noisy.push_back(v + gsl_ran_gaussian(rng.get(), 0.003));
            const auto fit = fit_power_law(radii_mm, noisy);
            covered += fit.params[1].low <= 1.282 && 1.282 <= fit.params[1].high;
            CHECK(fit.params[1].std_error < 0.2);
        }
        CHECK(covered >= 175);
    }
}

TEST_CASE("scaling-law input errors name the point", "[scaling_law]") {
    CHECK_THROWS_WITH(fit_power_law(std::vector<double>{1, 2, -3}, std::vector<double>{1, 2, 3}),
                      Catch::Contains("point 2"));
    CHECK_THROWS_WITH(fit_linear_law(std::vector<double>{1, 1, 1}, std::vector<double>{1, 2, 3}),
                      Catch::Contains("2 distinct radii"));
}
