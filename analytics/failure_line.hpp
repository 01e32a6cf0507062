// Linearised failure line of a granular assembly, tau = tan(phi_b) sigma + tau_c (seed, section 3.1),
// fitted by ordinary least squares with GSL, with the statistics a calibration needs to trust it.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <span>
#include <string>

namespace demcal::analytics {

// Lack-of-fit F test: only possible when some normal stress has replicates (pure error).
struct LackOfFit {
    double f_statistic = 0;  // (SS_lof / df_lof) / (SS_pe / df_pe)
    int df_lack_of_fit = 0;  // distinct normal stresses - 2
    int df_pure_error = 0;   // points - distinct normal stresses
    double p_value = 1;      // P(F > f_statistic); small means the line does not fit the means
};

struct FailureLine {
    int n = 0;                     // points fitted
    int distinct_levels = 0;       // distinct normal stresses
    double mu_b = 0;               // internal friction coefficient tan(phi_b) [-]
    double tau_c = 0;              // cohesion, the intercept [Pa]
    double se_mu_b = 0, se_tau_c = 0, cov_mu_b_tau_c = 0;  // from the fit's covariance (residual variance)
    double phi_b_deg = 0, se_phi_b_deg = 0;                // atan(mu_b), delta-method standard error
    double confidence = 0.95;      // level of the intervals below
    double mu_b_low = 0, mu_b_high = 0, tau_c_low = 0, tau_c_high = 0;  // Student-t intervals, n - 2 dof
    double r_squared = 0;
    double residual_sd = 0;        // sqrt(SSE / (n - 2)) [Pa]
    std::optional<LackOfFit> lack_of_fit;

    double shear_stress(double sigma) const { return mu_b * sigma + tau_c; }
    // Half-width of the confidence band of the fitted mean line at normal stress sigma.
    double band_half_width(double sigma) const;
    nlohmann::json to_json() const;
};

// Fits the failure line to (sigma_i, tau_i). Needs at least 3 points on at least 2 distinct normal stresses;
// throws std::invalid_argument naming the problem otherwise (or on non-finite input).
FailureLine fit_failure_line(std::span<const double> sigma, std::span<const double> tau, double confidence = 0.95);

// The same requirement on a campaign before it runs (`replicates` points at each stress): at least 2 distinct normal
// stresses and 3 points. Throws std::invalid_argument naming --normal-stress or --replicates and the values, so that
// a campaign whose line cannot be fitted is refused before its runs, not after them.
void check_failure_line_design(std::span<const double> normal_stresses, int replicates);
// The smallest spread of a design's normal stresses, (largest - smallest) / largest: more than a simulated box's
// servo spreads a stress, and below what a Jenike test's loads span (a factor of 2-4).
inline constexpr double kMinNormalStressSpread = 0.2;
// Throws std::invalid_argument naming `field` and the range when normal stresses from `lowest` to `highest` spread
// less than kMinNormalStressSpread: a line through them is a line through their noise.
void check_normal_stress_spread(double lowest, double highest, const std::string& field);

// The largest stress a measured point of a bulk solid's failure line can have: grains crush at tens of MPa, and no
// shear cell reaches 1 GPa. A larger value is a unit slip (kPa typed as Pa twice, psi as Pa) or garbage.
inline constexpr double kMaxMeasuredStressPa = 1e9;
// Throws std::invalid_argument naming `field` and the value when a measured normal or shear stress is negative or
// above kMaxMeasuredStressPa. One rule for every way a measured line comes in (a CSV, --measured).
void check_measured_stress(double value, const std::string& field);

}  // namespace demcal::analytics
