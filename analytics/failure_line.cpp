#include "analytics/failure_line.hpp"

#include "analytics/number_text.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>

#include <cmath>
#include <map>
#include <set>
#include <numbers>
#include <stdexcept>
#include <string>

namespace demcal::analytics {

namespace {
double t_quantile(double confidence, int dof) { return gsl_cdf_tdist_Pinv(0.5 + confidence / 2.0, dof); }
}  // namespace

void check_failure_line_design(std::span<const double> normal_stresses, int replicates) {
    const std::set<double> distinct(normal_stresses.begin(), normal_stresses.end());
    // a stress given twice was one set of runs (a run is its stress and seed), announced as two
    if (distinct.size() < normal_stresses.size())
        for (std::size_t i = 0; i < normal_stresses.size(); ++i)
            for (std::size_t k = 0; k < i; ++k)
                if (normal_stresses[k] == normal_stresses[i])
                    throw std::invalid_argument("normal-stress: " + number_text(normal_stresses[i]) +
                                                " Pa is given twice: one stress runs once per replicate (for more "
                                                "packings at a stress use --replicates)");
    if (distinct.size() < 2)
        throw std::invalid_argument("normal-stress: a failure line needs at least 2 distinct normal stresses, got " +
                                    std::to_string(distinct.size()));
    // stresses closer than the box's servo holds them (a few % of the target, up to 15 % in a small box) make a line
    // of that noise: 5000, 5000.0000001, 5000.0000002 Pa gave mu_b = 2e9 with exit 0
    check_normal_stress_spread(*distinct.begin(), *distinct.rbegin(), "normal-stress");
    if (static_cast<double>(distinct.size()) * replicates < 3)
        throw std::invalid_argument("replicates = " + std::to_string(replicates) + " at " +
                                    std::to_string(distinct.size()) +
                                    " distinct normal-stress values: a failure line needs at least 3 points (a line "
                                    "through 2 leaves nothing to estimate its uncertainty)");
}

void check_normal_stress_spread(double lowest, double highest, const std::string& field) {
    if (highest - lowest < kMinNormalStressSpread * std::fabs(highest))
        throw std::invalid_argument(field + ": " + number_text(lowest) + " to " + number_text(highest) +
                                    " Pa: a failure line needs normal stresses at least " +
                                    number_text(100 * kMinNormalStressSpread) +
                                    " % apart (the largest - the smallest, over the largest: here " +
                                    number_text(100 * (highest - lowest) / std::fabs(highest), 3) +
                                    " %; e.g. " + number_text(lowest) + " to " +
                                    number_text(lowest / (1 - kMinNormalStressSpread), 4) +
                                    " Pa or more): closer ones give a line through their noise");
}

void check_measured_stress(double value, const std::string& field) {
    if (!(value >= 0))
        throw std::invalid_argument(field + ": " + number_text(value) + " Pa is negative: a measured stress is >= 0");
    if (value > kMaxMeasuredStressPa)
        throw std::invalid_argument(field + ": " + number_text(value) + " Pa is above " +
                                    number_text(kMaxMeasuredStressPa) +
                                    " Pa, more than any shear test of a bulk solid reaches (its grains crush at tens "
                                    "of MPa): a unit slip?");
}

FailureLine fit_failure_line(std::span<const double> sigma, std::span<const double> tau, double confidence) {
    if (sigma.size() != tau.size())
        throw std::invalid_argument("failure line: " + std::to_string(sigma.size()) + " normal stresses but " +
                                    std::to_string(tau.size()) + " shear stresses");
    if (!(confidence > 0 && confidence < 1))
        throw std::invalid_argument("failure line: confidence=" + std::to_string(confidence) + " not in (0, 1)");
    const int n = static_cast<int>(sigma.size());
    std::map<double, std::vector<double>> groups;  // normal stress -> shear stresses at it (replicates)
    for (int i = 0; i < n; ++i) {
        if (!std::isfinite(sigma[i]) || !std::isfinite(tau[i]))
            throw std::invalid_argument("failure line: point " + std::to_string(i) + " is not finite (sigma=" +
                                        std::to_string(sigma[i]) + ", tau=" + std::to_string(tau[i]) + ")");
        groups[sigma[i]].push_back(tau[i]);
    }
    if (n < 3 || groups.size() < 2)
        throw std::invalid_argument("failure line: needs at least 3 points on at least 2 normal stresses, got " +
                                    std::to_string(n) + " points on " + std::to_string(groups.size()));

    FailureLine fl;
    fl.n = n;
    fl.distinct_levels = static_cast<int>(groups.size());
    fl.confidence = confidence;
    double c0, c1, cov00, cov01, cov11, sse;
    // gsl_fit_linear scales the covariance by the residual variance SSE/(n-2).
    gsl_fit_linear(sigma.data(), 1, tau.data(), 1, n, &c0, &c1, &cov00, &cov01, &cov11, &sse);
    fl.tau_c = c0;
    fl.mu_b = c1;
    fl.se_tau_c = std::sqrt(cov00);
    fl.se_mu_b = std::sqrt(cov11);
    fl.cov_mu_b_tau_c = cov01;
    const int dof = n - 2;
    fl.residual_sd = std::sqrt(sse / dof);
    const double t = t_quantile(confidence, dof);
    fl.mu_b_low = fl.mu_b - t * fl.se_mu_b;
    fl.mu_b_high = fl.mu_b + t * fl.se_mu_b;
    fl.tau_c_low = fl.tau_c - t * fl.se_tau_c;
    fl.tau_c_high = fl.tau_c + t * fl.se_tau_c;
    const double rad_to_deg = 180.0 / std::numbers::pi;
    fl.phi_b_deg = std::atan(fl.mu_b) * rad_to_deg;
    fl.se_phi_b_deg = fl.se_mu_b / (1.0 + fl.mu_b * fl.mu_b) * rad_to_deg;  // d atan(x)/dx = 1/(1+x^2)

    double mean_tau = 0;
    for (double v : tau) mean_tau += v;
    mean_tau /= n;
    double sst = 0;
    for (double v : tau) sst += (v - mean_tau) * (v - mean_tau);
    fl.r_squared = sst > 0 ? 1.0 - sse / sst : 1.0;

    // Pure error from replicates at the same normal stress; the rest of SSE is lack of fit.
    double ss_pure_error = 0;
    for (const auto& [s, taus] : groups) {
        double m = 0;
        for (double v : taus) m += v;
        m /= static_cast<double>(taus.size());
        for (double v : taus) ss_pure_error += (v - m) * (v - m);
    }
    const int df_pe = n - fl.distinct_levels;
    const int df_lof = fl.distinct_levels - 2;
    if (df_pe > 0 && df_lof > 0 && ss_pure_error > 0) {
        LackOfFit lof;
        lof.df_pure_error = df_pe;
        lof.df_lack_of_fit = df_lof;
        const double ss_lof = std::max(0.0, sse - ss_pure_error);
        lof.f_statistic = (ss_lof / df_lof) / (ss_pure_error / df_pe);
        lof.p_value = gsl_cdf_fdist_Q(lof.f_statistic, df_lof, df_pe);
        fl.lack_of_fit = lof;
    }
    return fl;
}

double FailureLine::band_half_width(double sigma) const {
    const double var = se_tau_c * se_tau_c + 2 * sigma * cov_mu_b_tau_c + sigma * sigma * se_mu_b * se_mu_b;
    return t_quantile(confidence, n - 2) * std::sqrt(std::max(0.0, var));
}

nlohmann::json FailureLine::to_json() const {
    nlohmann::json j = {{"n", n},
                        {"distinct_normal_stresses", distinct_levels},
                        {"mu_b", mu_b},
                        {"mu_b_se", se_mu_b},
                        {"mu_b_ci", {mu_b_low, mu_b_high}},
                        {"phi_b_deg", phi_b_deg},
                        {"phi_b_se_deg", se_phi_b_deg},
                        {"tau_c_Pa", tau_c},
                        {"tau_c_se_Pa", se_tau_c},
                        {"tau_c_ci_Pa", {tau_c_low, tau_c_high}},
                        {"cov_mu_b_tau_c", cov_mu_b_tau_c},
                        {"confidence", confidence},
                        {"r_squared", r_squared},
                        {"residual_sd_Pa", residual_sd}};
    if (lack_of_fit)
        j["lack_of_fit"] = {{"F", lack_of_fit->f_statistic},
                            {"df_lack_of_fit", lack_of_fit->df_lack_of_fit},
                            {"df_pure_error", lack_of_fit->df_pure_error},
                            {"p_value", lack_of_fit->p_value}};
    else
        j["lack_of_fit"] = nullptr;
    return j;
}

}  // namespace demcal::analytics
