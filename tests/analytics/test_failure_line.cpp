#include "analytics/failure_line.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using demcal::analytics::fit_failure_line;

// Values computed by hand (sums of squares on paper); the fit must agree to 1e-12.
TEST_CASE("failure line fit agrees with a hand computation", "[failure_line]") {
    const std::vector<double> sigma{1, 2, 3, 4}, tau{2.1, 3.9, 6.2, 7.8};
    // xbar = 2.5, ybar = 5, Sxx = 5, Sxy = 9.7 -> slope 1.94, intercept 0.15; SSE = 0.082, s^2 = 0.041, SST = 18.9
    const auto fl = fit_failure_line(sigma, tau);
    const double tol = 1e-12;
    CHECK(fl.mu_b == Approx(1.94).epsilon(tol));
    CHECK(fl.tau_c == Approx(0.15).epsilon(tol));
    CHECK(fl.se_mu_b == Approx(std::sqrt(0.041 / 5)).epsilon(tol));
    CHECK(fl.se_tau_c == Approx(std::sqrt(0.041 * (0.25 + 2.5 * 2.5 / 5))).epsilon(tol));
    CHECK(fl.cov_mu_b_tau_c == Approx(-0.041 * 2.5 / 5).epsilon(tol));
    CHECK(fl.r_squared == Approx(1 - 0.082 / 18.9).epsilon(tol));
    CHECK(fl.residual_sd == Approx(std::sqrt(0.041)).epsilon(tol));
    CHECK(fl.phi_b_deg == Approx(std::atan(1.94) * 180 / M_PI).epsilon(tol));
    const double t975_2dof = 4.302652729749464;  // Student t, 2 dof, 97.5 % (tables: 4.3027)
    CHECK(fl.mu_b_high - fl.mu_b == Approx(t975_2dof * std::sqrt(0.041 / 5)).epsilon(1e-9));
    CHECK_FALSE(fl.lack_of_fit.has_value());  // no replicates, no pure error
}

TEST_CASE("lack-of-fit test with replicates agrees with a hand computation", "[failure_line]") {
    const std::vector<double> sigma{1, 1, 2, 2, 3, 3, 4, 4}, tau{1, 2, 4, 5, 5, 6, 9, 10};
    // level means 1.5 4.5 5.5 9.5 -> line 2.5 sigma - 1; SS_lof = 2 (0 + .25 + 1 + .25) = 3, SS_pe = 2
    // F = (3/2)/(2/4) = 3 with (2, 4) dof; for F(2, d2): P(F > x) = (1 + 2x/d2)^(-d2/2) = 2.5^-2 = 0.16
    const auto fl = fit_failure_line(sigma, tau);
    CHECK(fl.mu_b == Approx(2.5).epsilon(1e-12));
    CHECK(fl.tau_c == Approx(-1.0).epsilon(1e-12));
    REQUIRE(fl.lack_of_fit.has_value());
    CHECK(fl.lack_of_fit->df_lack_of_fit == 2);
    CHECK(fl.lack_of_fit->df_pure_error == 4);
    CHECK(fl.lack_of_fit->f_statistic == Approx(3.0).epsilon(1e-12));
    CHECK(fl.lack_of_fit->p_value == Approx(0.16).epsilon(1e-10));
}

TEST_CASE("failure line refuses what cannot define a line", "[failure_line]") {
    const std::vector<double> one_level{1e4, 1e4, 1e4}, taus{5e3, 6e3, 7e3};
    CHECK_THROWS_WITH(fit_failure_line(one_level, taus), Catch::Contains("at least 2 normal stresses"));
    const std::vector<double> s2{1e4, 2e4}, t2{1, 2};
    CHECK_THROWS_WITH(fit_failure_line(s2, t2), Catch::Contains("at least 3 points"));
    const std::vector<double> s3{1e4, 2e4, 3e4}, t3{1, NAN, 2};
    CHECK_THROWS_WITH(fit_failure_line(s3, t3), Catch::Contains("point 1 is not finite"));
}

TEST_CASE("confidence band is narrowest at the mean normal stress", "[failure_line]") {
    const std::vector<double> sigma{5e3, 1e4, 1.5e4, 2e4}, tau{4.1e3, 7.0e3, 10.2e3, 12.9e3};
    const auto fl = fit_failure_line(sigma, tau);
    CHECK(fl.band_half_width(1.25e4) < fl.band_half_width(5e3));
    CHECK(fl.band_half_width(1.25e4) < fl.band_half_width(2e4));
    CHECK(fl.band_half_width(0) == Approx(fl.tau_c_high - fl.tau_c).epsilon(1e-12));
}
