// Particle-enlargement laws: the seed's eqs. 3.1-3.2 regenerated from noisy points at the seed's radii.
#include "analytics/scaling_law.hpp"

#include <catch2/catch.hpp>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include <cmath>
#include <functional>
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
    SECTION("exact points whose log-log line is already the fit (GSL finds no step from it) are converged") {
        // radii in m (what demcal enlarge reads), several exponents: the start is the optimum to rounding, and GSL's
        // driver reported that as "exceeded max number of iterations" (enlarge printed the law as not determined)
        for (const double d : {0.5, 1.282, 2.0, 3.7})
            for (const std::vector<double>& r : {std::vector<double>{0.001, 0.0012, 0.0015, 0.002},
                                                 std::vector<double>{0.002, 0.0025, 0.003, 0.0035, 0.004}}) {
                std::vector<double> y;
                for (double x : r) y.push_back(0.01 * std::pow(x, -d));
                const auto fit = fit_power_law(r, y);
                INFO("D = " << d << ", " << r.size() << " radii from " << r.front() << " m");
                CHECK(fit.converged);
                CHECK(fit.determined());
                CHECK(fit.params[1].value == Approx(d).epsilon(1e-9));
            }
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

namespace {
// n noisy points y = f(r) (1 + eps), eps ~ N(0, rel_sd): the relative scatter of timings and calibrated values
std::vector<double> noisy(const std::function<double(double)>& f, gsl_rng* rng, double rel_sd) {
    std::vector<double> y;
    for (double r : radii_mm) y.push_back(f(r) * (1 + gsl_ran_gaussian(rng, rel_sd)));
    return y;
}
}  // namespace

TEST_CASE("a noisy power law is determined and its constants fall inside their intervals", "[scaling_law]") {
    std::unique_ptr<gsl_rng, decltype(&gsl_rng_free)> rng(gsl_rng_alloc(gsl_rng_mt19937), gsl_rng_free);
    gsl_rng_set(rng.get(), 11);
    // the seed's cost: doubling r saved 94.9 %, i.e. D = -log2(0.051) = 4.29; timings scatter by 5 %
    const double c = 3600, d = 4.29;
    int determined = 0, covered_c = 0, covered_d = 0;
    const int trials = 200;
    for (int t = 0; t < trials; ++t) {
        const auto y = noisy([&](double r) { return c * std::pow(r, -d); }, rng.get(), 0.05);
        const auto fit = fit_power_law(radii_mm, y, y);  // relative weights
        determined += fit.determined();
        covered_c += fit.params[0].low <= c && c <= fit.params[0].high;
        covered_d += fit.params[1].low <= d && d <= fit.params[1].high;
    }
    CHECK(determined >= 180);  // the curvature test at 5 % refuses about 1 in 20 true power laws
    CHECK(covered_c >= 180);
    CHECK(covered_d >= 180);
}

TEST_CASE("points that follow no power law are refused with the reason", "[scaling_law]") {
    std::unique_ptr<gsl_rng, decltype(&gsl_rng_free)> rng(gsl_rng_alloc(gsl_rng_mt19937), gsl_rng_free);
    gsl_rng_set(rng.get(), 5);
    int flat_refused = 0, flat_by_exponent = 0, curved_refused = 0;
    const int trials = 100;
    for (int t = 0; t < trials; ++t) {
        // a constant with 5 % scatter: any exponent is noise
        const auto flat = fit_power_law(radii_mm, noisy([](double) { return 0.3; }, rng.get(), 0.05));
        flat_refused += !flat.determined();
        flat_by_exponent += flat.undetermined.find("holds 0") != std::string::npos;
        // exponential decay over 1-7 mm: straight in log y over r, bent in log y over log r
        const auto curved = fit_power_law(radii_mm, noisy([](double r) { return std::exp(-r); }, rng.get(), 0.02));
        if (!curved.determined()) {
            ++curved_refused;
            CHECK(curved.undetermined.find("bend away") != std::string::npos);
        }
        CHECK(curved.converged);  // the fit itself converges: only the test of its form refuses it
    }
    CHECK(flat_refused >= 90);
    CHECK(flat_by_exponent >= 85);  // mostly because D's interval holds 0
    CHECK(curved_refused >= 95);
    // exact points on a power law are determined (the curvature test compares no rounding errors)
    std::vector<double> exact;
    for (double r : radii_mm) exact.push_back(0.2344 * std::pow(r, -1.282));
    CHECK(fit_power_law(radii_mm, exact).determined());
}
