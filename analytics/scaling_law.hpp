// Particle-enlargement laws of the seed (section 3.2): the micro parameters that keep the macro behaviour when the
// particle radius r_p grows, E(r_p) = A r_p + B (eq. 3.1) and nu(r_p) = C r_p^-D (eq. 3.2), fitted with GSL and
// reported with standard errors and Student-t intervals. In YADE's linear contact law `poisson` is the stiffness ratio
// ks/kn, so a nu(r_p) fitted from YADE runs is a law for that ratio, not for a physical Poisson ratio.
#pragma once
#include <nlohmann/json.hpp>

#include <span>
#include <string>
#include <vector>

namespace demcal::analytics {

struct LawParameter {
    std::string name;    // "A", "B" (linear) or "C", "D" (power)
    double value = 0;
    double std_error = 0;
    double low = 0, high = 0;  // Student-t interval at the fit's confidence, n - 2 dof
};

struct ScalingLawFit {
    std::string law;                  // "linear" (y = A r + B) or "power" (y = C r^-D)
    std::vector<LawParameter> params;
    int n = 0, dof = 0;
    double confidence = 0.95;
    double r_squared = 0;
    double residual_sd = 0;           // sqrt(weighted SSE / dof), in y units when unweighted
    bool converged = true;            // the nonlinear fit met GSL's tolerances
    // Why these points cannot determine the law (empty: they can): a fit that did not converge, a singular covariance,
    // or for the power law an exponent indistinguishable from 0 or points that bend away from it in log-log.
    std::string undetermined;
    bool determined() const { return undetermined.empty(); }
    double operator()(double r) const;
    std::string formula() const;      // e.g. "E(r) = 91.52 r + 148.9"
    nlohmann::json to_json() const;
};

// Radii closer than this (relative to the larger of two) are one radius for a scaling law: a packing does not tell
// them apart, and a law through them is a law through their noise (1e-3, 1.0000001e-3, 1.0000002e-3 m fitted
// E = 4e17 r - 4e14 Pa, "determined", R^2 = 1).
inline constexpr double kMinRadiusStep = 0.01;
// Throws std::invalid_argument naming `field` and the two radii when two of `radii` (any order) are closer than
// kMinRadiusStep.
void check_radius_spacing(std::vector<double> radii, const std::string& field);

// y = A r + B by weighted least squares (gsl_fit_wlinear; sigma empty = equal weights, scale from the residuals).
// Needs >= 3 points on >= 2 distinct r; throws std::invalid_argument naming the problem otherwise.
ScalingLawFit fit_linear_law(std::span<const double> r, std::span<const double> y, std::span<const double> sigma = {},
                             double confidence = 0.95);

// y = C r^-D by nonlinear least squares (gsl_multifit_nlinear, started from the log-log line). r and y must be > 0.
// `undetermined` says so when D's interval holds 0 (no power law: a constant does as well) or, with 4 points or more,
// when a quadratic term in log y over log r is significant at 1 - confidence (the points are not on a power law).
ScalingLawFit fit_power_law(std::span<const double> r, std::span<const double> y, std::span<const double> sigma = {},
                            double confidence = 0.95);

}  // namespace demcal::analytics
