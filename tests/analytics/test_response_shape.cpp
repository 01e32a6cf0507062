// Response shapes (constant / linear / parabolic) on synthetic responses of known shape with noise.
#include "analytics/response_shape.hpp"

#include <catch2/catch.hpp>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

using namespace demcal::analytics;

namespace {

// Levels of a sensitivity study: base value 0.5 varied by +-50 %.
std::vector<double> levels(int n) {
    std::vector<double> x;
    for (int i = 0; i < n; ++i) x.push_back(0.25 + 0.5 * i / (n - 1));
    return x;
}

// Share of `trials` noisy responses (GSL's generator: the same numbers on every platform) classified as `expected`.
double share_classified_as(ResponseShape expected, const std::function<double(double)>& truth, double noise_sd,
                           int n_levels, int trials, ShapeCriterion criterion = ShapeCriterion::f_test) {
    std::unique_ptr<gsl_rng, decltype(&gsl_rng_free)> rng(gsl_rng_alloc(gsl_rng_mt19937), gsl_rng_free);
    gsl_rng_set(rng.get(), 12345);
    const auto x = levels(n_levels);
    const std::vector<double> sigma(x.size(), noise_sd);
    int right = 0;
    for (int t = 0; t < trials; ++t) {
        std::vector<double> y;
        for (double v : x) y.push_back(truth(v) + gsl_ran_gaussian(rng.get(), noise_sd));
        if (classify_response(x, y, sigma, 0.5, {criterion, 0.05}).shape == expected) ++right;
    }
    return static_cast<double>(right) / trials;
}

}  // namespace

TEST_CASE("weighted fits agree with hand computations and exact shapes are recognised", "[response_shape]") {
    const std::vector<double> x{1, 2, 3, 4, 5};
    SECTION("an exact line: slope and value at the reference, linear") {
        std::vector<double> y;
        for (double v : x) y.push_back(2 + 3 * (v - 3));
        const auto r = classify_response(x, y, {}, 3.0);
        CHECK(r.shape == ResponseShape::linear);
        CHECK(r.selected().coefficients[0].value == Approx(2).epsilon(1e-12));
        CHECK(r.selected().coefficients[1].value == Approx(3).epsilon(1e-12));
        CHECK(r.slope(10) == Approx(3).epsilon(1e-12));
        CHECK(r.value(4) == Approx(5).epsilon(1e-12));
    }
    SECTION("a small parabola plus a line: all three coefficients") {
        // y = 1 - 0.5 (x - 2) + 0.25 (x - 2)^2 plus a symmetric residual pattern orthogonal to 1, x, x^2
        const std::vector<double> wiggle{0.01, -0.04, 0.06, -0.04, 0.01};  // 4th-difference pattern
        std::vector<double> y;
        for (std::size_t i = 0; i < x.size(); ++i)
            y.push_back(1 - 0.5 * (x[i] - 2) + 0.25 * (x[i] - 2) * (x[i] - 2) + wiggle[i]);
        const auto r = classify_response(x, y, {}, 2.0);
        REQUIRE(r.fits.size() == 3);
        CHECK(r.fits[2].coefficients[0].value == Approx(1).epsilon(1e-10));
        CHECK(r.fits[2].coefficients[1].value == Approx(-0.5).epsilon(1e-10));
        CHECK(r.fits[2].coefficients[2].value == Approx(0.25).epsilon(1e-10));
        CHECK(r.fits[2].chi_squared == Approx(0.0070).epsilon(1e-10));  // sum of wiggle^2
        CHECK(r.shape == ResponseShape::parabolic);
        // F = (SSE_lin - SSE_par) / (SSE_par / 2); SSE_lin - SSE_par = 0.25^2 * Sxx of the centred squares = 0.875
        REQUIRE(r.parabolic_vs_linear);
        CHECK(r.parabolic_vs_linear->f_statistic == Approx(0.875 / (0.0070 / 2)).epsilon(1e-9));
    }
    SECTION("a point with a large uncertainty hardly moves the weighted line") {
        std::vector<double> y{1, 2, 3, 4, 50};  // the last point is far off but known only to +-1000
        const std::vector<double> sigma{0.1, 0.1, 0.1, 0.1, 1000};
        const auto r = classify_response(x, y, sigma, 3.0);
        CHECK(r.fits[1].coefficients[1].value == Approx(1).margin(1e-3));
        CHECK(r.shape == ResponseShape::linear);
    }
}

TEST_CASE("noisy synthetic responses are classified by their true shape", "[response_shape]") {
    const int trials = 400;
    const double noise = 0.01;  // like the standard error of a failure line's mu_b
    SECTION("constant: false alarms near the significance level") {
        const double right = share_classified_as(ResponseShape::constant, [](double) { return 0.6; }, noise, 5, trials);
        CHECK(right > 0.88);  // two tests at 5 % each: at most about 10 % false shapes
    }
    SECTION("linear") {
        CHECK(share_classified_as(ResponseShape::linear, [](double v) { return 0.4 + 0.4 * v; }, noise, 5, trials) >
              0.9);
    }
    SECTION("parabolic") {
        auto truth = [](double v) { return 0.6 + 0.05 * (v - 0.5) - 3.0 * (v - 0.5) * (v - 0.5); };
        CHECK(share_classified_as(ResponseShape::parabolic, truth, noise, 5, trials) > 0.9);
        CHECK(share_classified_as(ResponseShape::parabolic, truth, noise, 7, trials, ShapeCriterion::aicc) > 0.9);
    }
    SECTION("a weak curvature on a strong trend stays linear") {
        auto truth = [](double v) { return 0.4 + 0.4 * v + 0.001 * (v - 0.5) * (v - 0.5); };
        CHECK(share_classified_as(ResponseShape::linear, truth, noise, 5, trials) > 0.88);
    }
}

TEST_CASE("the coefficients carry their significance", "[response_shape]") {
    const std::vector<double> x{1, 2, 3, 4, 5}, y{0.50, 0.52, 0.49, 0.51, 0.50};
    const auto r = classify_response(x, y, std::vector<double>(5, 0.01), 3.0);
    CHECK(r.shape == ResponseShape::constant);
    CHECK(r.fits[1].coefficients[1].p_value > 0.5);   // no slope
    CHECK(r.fits[0].coefficients[0].p_value < 1e-6);  // but certainly a non-zero level
    const auto j = r.to_json();
    CHECK(j.at("shape") == "constant");
    CHECK(j.at("fits").size() == 3);
}

TEST_CASE("bad input is refused with the problem named", "[response_shape]") {
    const std::vector<double> x{1, 2, 3}, y{1, 2, 3};
    CHECK_THROWS_WITH(classify_response(x, std::vector<double>{1, 2}, {}, 2), Catch::Contains("3 levels but 2"));
    CHECK_THROWS_WITH(classify_response(std::vector<double>{1, 1, 2}, y, {}, 2),
                      Catch::Contains("at least 3 distinct levels"));
    CHECK_THROWS_WITH(classify_response(x, y, std::vector<double>{1, 0, 1}, 2), Catch::Contains("uncertainty of level 1"));
    CHECK_THROWS_WITH(shape_criterion_from_string("bic"), Catch::Contains("'bic'"));
}

TEST_CASE("a trend limited to degree 1 is a line or a constant, never a parabola", "[response_shape]") {
    const std::vector<double> x{1, 1.5, 2, 3, 5, 7};
    std::vector<double> bent, rising;
    for (double v : x) bent.push_back(1 + (v - 4) * (v - 4)), rising.push_back(0.5 + 0.05 * v + 1e-3 * std::sin(7 * v));
    ResponseShapeOptions linear_at_most;
    linear_at_most.max_degree = 1;
    CHECK(classify_response(x, bent, {}, 1, {}).shape == ResponseShape::parabolic);  // the default sees the bend
    const auto limited = classify_response(x, bent, {}, 1, linear_at_most);
    CHECK(limited.shape != ResponseShape::parabolic);
    CHECK(limited.fits.size() == 2);
    CHECK_FALSE(limited.parabolic_vs_linear);
    CHECK(classify_response(x, rising, {}, 1, linear_at_most).shape == ResponseShape::linear);
    linear_at_most.max_degree = 3;
    CHECK_THROWS_WITH(classify_response(x, rising, {}, 1, linear_at_most), Catch::Contains("max_degree = 3"));
}
