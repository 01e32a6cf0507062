#include "analytics/scaling_law.hpp"

#include "analytics/regression.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>
#include <gsl/gsl_multifit.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

namespace demcal::analytics {

void check_radius_spacing(std::vector<double> radii, const std::string& field) {
    std::sort(radii.begin(), radii.end());
    for (std::size_t i = 1; i < radii.size(); ++i)
        if (radii[i] - radii[i - 1] < kMinRadiusStep * std::fabs(radii[i])) {
            std::ostringstream o;
            o << std::setprecision(12) << field << ": " << radii[i - 1] << " and " << radii[i] << " m differ by less than "
              << 100 * kMinRadiusStep << " %: one radius for a scaling law (give radii further apart)";
            throw std::invalid_argument(o.str());
        }
}

namespace {

// Checks sizes and values; returns the weights (1 / sigma^2, or 1).
std::vector<double> checked_weights(const char* law, std::span<const double> r, std::span<const double> y,
                                    std::span<const double> sigma, double confidence, bool positive) {
    const std::string where = std::string(law) + " law: ";
    if (y.size() != r.size() || (!sigma.empty() && sigma.size() != r.size()))
        throw std::invalid_argument(where + std::to_string(r.size()) + " radii but " + std::to_string(y.size()) +
                                    " values and " + std::to_string(sigma.size()) + " uncertainties");
    if (!(confidence > 0 && confidence < 1))
        throw std::invalid_argument(where + "confidence = " + std::to_string(confidence) + " is not in (0, 1)");
    std::set<double> distinct;
    std::vector<double> w(r.size(), 1.0);
    for (std::size_t i = 0; i < r.size(); ++i) {
        if (!std::isfinite(r[i]) || !std::isfinite(y[i]) || (positive && (r[i] <= 0 || y[i] <= 0)))
            throw std::invalid_argument(where + "point " + std::to_string(i) + " (r = " + std::to_string(r[i]) +
                                        ", y = " + std::to_string(y[i]) + ") must be finite" +
                                        (positive ? " and > 0" : ""));
        if (!sigma.empty()) {
            if (!(sigma[i] > 0) || !std::isfinite(sigma[i]))
                throw std::invalid_argument(where + "uncertainty of point " + std::to_string(i) + " = " +
                                            std::to_string(sigma[i]) + " must be finite and > 0");
            w[i] = 1 / (sigma[i] * sigma[i]);
        }
        distinct.insert(r[i]);
    }
    if (r.size() < 3 || distinct.size() < 2)
        throw std::invalid_argument(where + "needs at least 3 points on 2 distinct radii, got " +
                                    std::to_string(r.size()) + " on " + std::to_string(distinct.size()));
    return w;
}

double weighted_r_squared(std::span<const double> y, const std::vector<double>& w, double sse) {
    double sw = 0, swy = 0;
    for (std::size_t i = 0; i < y.size(); ++i) sw += w[i], swy += w[i] * y[i];
    const double mean = swy / sw;
    double sst = 0;
    for (std::size_t i = 0; i < y.size(); ++i) sst += w[i] * (y[i] - mean) * (y[i] - mean);
    return sst > 0 ? 1 - sse / sst : 1.0;
}

LawParameter parameter(const char* name, double value, double variance, double t) {
    const double se = std::sqrt(std::max(variance, 0.0));
    if (value == 0) value = 0;  // -0 read "D = -0"
    return {name, value, se, value - t * se, value + t * se};
}

std::string number(double v) {
    std::ostringstream o;
    o.precision(4);
    o << v;
    return o.str();
}

// Two-sided p-value of the quadratic term of log y = a + b log r + c (log r)^2, weights w y^2 (the variance of log y
// is about that of y over y^2), scale from the residuals. Needs 4 points or more; 1 (no evidence) otherwise.
double log_log_curvature_p_value(std::span<const double> r, std::span<const double> y, const std::vector<double>& w) {
    const std::size_t n = r.size();
    if (n < 4) return 1;
    gsl_matrix* x = gsl_matrix_alloc(n, 3);
    gsl_vector *ly = gsl_vector_alloc(n), *wl = gsl_vector_alloc(n), *c = gsl_vector_alloc(3);
    gsl_matrix* cov = gsl_matrix_alloc(3, 3);
    for (std::size_t i = 0; i < n; ++i) {
        const double lr = std::log(r[i]);
        gsl_matrix_set(x, i, 0, 1);
        gsl_matrix_set(x, i, 1, lr);
        gsl_matrix_set(x, i, 2, lr * lr);
        gsl_vector_set(ly, i, std::log(y[i]));
        gsl_vector_set(wl, i, w[i] * y[i] * y[i]);
    }
    double chisq = 0, weighted_total = 0;
    for (std::size_t i = 0; i < n; ++i) weighted_total += gsl_vector_get(wl, i) * std::pow(gsl_vector_get(ly, i), 2);
    gsl_multifit_linear_workspace* work = gsl_multifit_linear_alloc(n, 3);
    gsl_multifit_wlinear(x, wl, ly, c, cov, &chisq, work);
    const int dof = static_cast<int>(n) - 3;
    const double se = std::sqrt(gsl_matrix_get(cov, 2, 2) * chisq / dof);
    const double t = std::fabs(gsl_vector_get(c, 2)) / se;
    gsl_multifit_linear_free(work);
    gsl_matrix_free(x);
    gsl_matrix_free(cov);
    gsl_vector_free(ly);
    gsl_vector_free(wl);
    gsl_vector_free(c);
    // points on the curve to rounding (exact data): the t ratio would compare rounding errors
    if (!(se > 0) || chisq <= 1e-20 * weighted_total) return 1;
    return 2 * gsl_cdf_tdist_Q(t, dof);
}

// Why the points cannot determine the power law, or empty.
std::string power_law_undetermined(const ScalingLawFit& fit, std::span<const double> y, double curvature_p) {
    const auto& d = fit.params[1];
    if (std::all_of(y.begin(), y.end(), [&](double v) { return v == y[0]; }))
        return "the same value at every radius: a constant, with no exponent to estimate";
    if (!fit.converged) return "the nonlinear fit did not converge";
    if (!std::isfinite(fit.params[0].std_error) || !std::isfinite(d.std_error))
        return "the covariance is singular: C and D cannot be separated";
    const std::string percent = number(100 * fit.confidence) + " %";
    if (d.low <= 0 && 0 <= d.high)
        return "D = " + number(d.value) + " +/- " + number(d.std_error) + ": its " + percent + " interval [" +
               number(d.low) + ", " + number(d.high) + "] holds 0, so the points show no power law (a constant fits "
               "as well)";
    if (curvature_p < 1 - fit.confidence)
        return "the points bend away from a power law: a quadratic term in log y over log r is significant (p = " +
               number(curvature_p) + ")";
    return {};
}

}  // namespace

double ScalingLawFit::operator()(double r) const {
    if (law == "linear") return params[0].value * r + params[1].value;
    return params[0].value * std::pow(r, -params[1].value);
}

std::string ScalingLawFit::formula() const {
    std::ostringstream o;
    o.precision(4);
    if (law == "linear")
        o << "y(r) = " << params[0].value << " r " << (params[1].value < 0 ? "- " : "+ ") << std::fabs(params[1].value);
    else if (params[1].value < 0)  // y grows with r: "r^-(-0.5)", not "r^--0.5"
        o << "y(r) = " << params[0].value << " r^-(" << params[1].value << ")";
    else
        o << "y(r) = " << params[0].value << " r^-" << params[1].value;
    return o.str();
}

nlohmann::json ScalingLawFit::to_json() const {
    nlohmann::json j = {{"law", law},   {"formula", formula()},       {"n", n},
                        {"dof", dof},   {"confidence", confidence},   {"r_squared", r_squared},
                        {"residual_sd", residual_sd}, {"converged", converged}, {"determined", determined()},
                        {"undetermined_because", undetermined}, {"params", nlohmann::json::object()}};
    for (const auto& p : params)
        j["params"][p.name] = {{"value", p.value}, {"std_error", p.std_error}, {"low", p.low}, {"high", p.high}};
    return j;
}

ScalingLawFit fit_linear_law(std::span<const double> r, std::span<const double> y, std::span<const double> sigma,
                             double confidence) {
    const auto w = checked_weights("linear", r, y, sigma, confidence, false);
    double c0, c1, cov00, cov01, cov11, chisq;
    gsl_fit_wlinear(r.data(), 1, w.data(), 1, y.data(), 1, r.size(), &c0, &c1, &cov00, &cov01, &cov11, &chisq);
    ScalingLawFit fit;
    fit.law = "linear";
    fit.n = static_cast<int>(r.size());
    fit.dof = fit.n - 2;
    fit.confidence = confidence;
    // gsl_fit_wlinear's covariance trusts the weights' scale; treat them as relative (scale from the residuals).
    const double s2 = chisq / fit.dof;
    const double t = gsl_cdf_tdist_Pinv(0.5 + confidence / 2, fit.dof);
    fit.params = {parameter("A", c1, cov11 * s2, t), parameter("B", c0, cov00 * s2, t)};
    fit.residual_sd = std::sqrt(s2);
    fit.r_squared = weighted_r_squared(y, w, chisq);
    if (!std::isfinite(fit.params[0].std_error) || !std::isfinite(fit.params[1].std_error))
        fit.undetermined = "the covariance is singular: A and B cannot be separated";
    return fit;
}

ScalingLawFit fit_power_law(std::span<const double> r, std::span<const double> y, std::span<const double> sigma,
                            double confidence) {
    const auto w = checked_weights("power", r, y, sigma, confidence, true);
    // Start from the straight line log y = log C - D log r.
    std::vector<double> lr(r.size()), ly(r.size());
    for (std::size_t i = 0; i < r.size(); ++i) lr[i] = std::log(r[i]), ly[i] = std::log(y[i]);
    double c0, c1, cov00, cov01, cov11, sse_log;
    gsl_fit_linear(lr.data(), 1, ly.data(), 1, r.size(), &c0, &c1, &cov00, &cov01, &cov11, &sse_log);
    const ResidualFunction residuals = [&](const double* p, double* f) {
        for (std::size_t i = 0; i < r.size(); ++i) f[i] = (p[0] * std::pow(r[i], -p[1]) - y[i]) * std::sqrt(w[i]);
    };
    const auto ls = fit_least_squares(r.size(), residuals, {std::exp(c0), -c1});
    ScalingLawFit fit;
    fit.law = "power";
    fit.n = static_cast<int>(r.size());
    fit.dof = fit.n - 2;
    fit.confidence = confidence;
    fit.converged = ls.converged;
    const double t = gsl_cdf_tdist_Pinv(0.5 + confidence / 2, fit.dof);
    // fit_least_squares already scales the covariance by SSE / dof (relative weights).
    fit.params = {parameter("C", ls.params[0], ls.covariance[0], t), parameter("D", ls.params[1], ls.covariance[3], t)};
    fit.residual_sd = std::sqrt(ls.sse / fit.dof);
    fit.r_squared = weighted_r_squared(y, w, ls.sse);
    fit.undetermined = power_law_undetermined(fit, y, log_log_curvature_p_value(r, y, w));
    return fit;
}

}  // namespace demcal::analytics
