// analytics::compare_failure_lines: two lines from the same law agree (the combined-interval criterion holds and the
// Welch test does not reject); lines whose slopes differ by many standard errors are told apart; the numbers are the
// textbook ones for two independent regressions.
#include <catch2/catch.hpp>

#include "analytics/failure_line_comparison.hpp"

#include <cmath>
#include <random>
#include <vector>

using namespace demcal::analytics;

namespace {
FailureLine noisy_line(double mu, double c, double noise, unsigned seed, int replicates = 4) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, noise);
    std::vector<double> s, t;
    for (double sigma : {5e3, 10e3, 15e3, 20e3})
        for (int r = 0; r < replicates; ++r) {
            s.push_back(sigma);
            t.push_back(mu * sigma + c + n(rng));
        }
    return fit_failure_line(s, t);
}
}  // namespace

TEST_CASE("lines of the same law agree - lines of different laws are told apart", "[analytics][failure_line_comparison]") {
    int agree_same = 0, mu_within_same = 0, p_small_same = 0, agree_different = 0;
    for (unsigned k = 0; k < 200; ++k) {
        const auto a = noisy_line(0.8, 1000, 300, 2 * k + 1), b = noisy_line(0.8, 1000, 300, 2 * k + 2);
        const auto same = compare_failure_lines(a, b);
        agree_same += same.agree();
        mu_within_same += same.mu_b.within_combined_intervals();
        p_small_same += same.mu_b.p_value < 0.05;
        const auto c = noisy_line(0.95, 1000, 300, 1000 + k);
        agree_different += compare_failure_lines(a, c).mu_b.within_combined_intervals();
    }
    // for equal widths |d| <= sqrt(hw_a^2 + hw_b^2) is |d| / SE_d <= t(n - 2): about 5 % false alarms per parameter
    // (measured here 7 % for the pair of parameters), as the Welch test's 5 %
    CHECK(mu_within_same >= 180);
    CHECK(agree_same >= 170);
    CHECK(p_small_same <= 20);
    // a slope 0.15 apart with SE ~0.01 each: never within the combined intervals
    CHECK(agree_different == 0);
}

TEST_CASE("the comparison's numbers are those of two independent estimates", "[analytics][failure_line_comparison]") {
    const auto a = noisy_line(0.8, 1000, 300, 7), b = noisy_line(0.7, 1500, 300, 8);
    const auto c = compare_failure_lines(a, b);
    CHECK(c.mu_b.difference == Approx(a.mu_b - b.mu_b));
    CHECK(c.mu_b.standard_error == Approx(std::hypot(a.se_mu_b, b.se_mu_b)));
    CHECK(c.tau_c.combined_half_width ==
          Approx(std::hypot(0.5 * (a.tau_c_high - a.tau_c_low), 0.5 * (b.tau_c_high - b.tau_c_low))));
    // Satterthwaite's degrees of freedom lie between the smaller and the sum of the two lines' n - 2
    CHECK(c.mu_b.degrees_of_freedom >= std::min(a.n, b.n) - 2 - 1e-9);
    CHECK(c.mu_b.degrees_of_freedom <= a.n + b.n - 4 + 1e-9);
    CHECK(c.mu_b.p_value < 1e-6);  // 0.1 apart with SE ~0.01
    CHECK(c.to_json()["mu_b"]["within_combined_intervals"] == false);
    CHECK(c.to_json()["mu_b"].contains("combined_half_width_95"));
    FailureLine two;
    two.n = 2;
    CHECK_THROWS_AS(compare_failure_lines(a, two), std::invalid_argument);
}

TEST_CASE("lines with intervals at different levels are not combined", "[analytics][failure_line_comparison]") {
    const std::vector<double> sigma{5e3, 5e3, 10e3, 10e3, 15e3, 15e3};
    const std::vector<double> tau{4.1e3, 3.9e3, 7.2e3, 6.9e3, 10.1e3, 9.8e3};
    const auto at95 = fit_failure_line(sigma, tau, 0.95), at90 = fit_failure_line(sigma, tau, 0.90);
    CHECK_THROWS_WITH(compare_failure_lines(at95, at90), Catch::Contains("95 %") && Catch::Contains("90 %"));
    const auto c = compare_failure_lines(at90, at90);
    CHECK(c.mu_b.confidence == 0.90);
    CHECK(c.to_json()["mu_b"].contains("combined_half_width_90"));  // the key names the level it holds
}

TEST_CASE("an agreement within intervals wider than the slope is inconclusive", "[analytics][failure_line_comparison]") {
    // one packing per stress and a noise near the shear stresses themselves: intervals that hold any slope
    const auto a = noisy_line(0.6, 1000, 4000, 11, 1), b = noisy_line(0.3, 1000, 4000, 12, 1);
    const auto wide = compare_failure_lines(a, b);
    REQUIRE(wide.agree());
    CHECK_FALSE(wide.conclusive());
    CHECK(wide.to_json().at("conclusive") == false);
    // narrow intervals: an agreement, and a difference, are both conclusive
    const auto same = compare_failure_lines(noisy_line(0.8, 1000, 300, 1), noisy_line(0.8, 1000, 300, 2));
    CHECK((same.agree() && same.conclusive()));
    const auto apart = compare_failure_lines(noisy_line(0.8, 1000, 30, 3), noisy_line(0.95, 1000, 30, 4));
    CHECK((!apart.agree() && apart.conclusive()));
}
