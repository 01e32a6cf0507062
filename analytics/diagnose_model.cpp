#include "analytics/diagnose_model.hpp"

#include "analytics/discharge_models.hpp"
#include "analytics/failure_line.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>

namespace demcal::analytics::diagnosis {

double apply_effect(double w, double eta, bool relative, double scale) {
    return relative ? w * std::exp(eta) : w + scale * eta;
}

double residual(const Setting& s, const Model& m, std::size_t row, const double* p) {
    const double w = m.predict(row, p);
    if (m.relative) return (std::isfinite(w) && w > 0) ? std::log(s.y[row]) - std::log(w) : penalty_residual;
    return std::isfinite(w) ? (s.y[row] - w) / s.scale : penalty_residual;
}

LeastSquaresFit fit_rows(const Setting& s, const Model& m, const std::vector<std::size_t>& rows,
                         const std::vector<double>& start) {
    auto f = [&](const double* p, double* r) {
        for (std::size_t i = 0; i < rows.size(); ++i) r[i] = residual(s, m, rows[i], p);
    };
    return fit_least_squares(rows.size(), f, start);
}

std::vector<std::size_t> all_rows(std::size_t n) {
    std::vector<std::size_t> rows(n);
    std::iota(rows.begin(), rows.end(), 0);
    return rows;
}

// Fits a model whose last term is new, from the previous parameters and each of the new term's starting points.
LeastSquaresFit fit_extended(const Setting& s, const Model& m, const std::vector<double>& previous) {
    const auto& rows = s.rows;
    if (m.terms.empty() || previous.size() == m.size()) return fit_rows(s, m, rows, previous);
    LeastSquaresFit best;
    best.sse = std::numeric_limits<double>::infinity();
    for (const auto& tail : m.terms.back().starts) {
        auto start = previous;
        start.insert(start.end(), tail.begin(), tail.end());
        auto fit = fit_rows(s, m, rows, start);
        if (fit.sse < best.sse) best = fit;
    }
    return best;
}


// Errors over the rows fitted (s.rows).
Errors errors_of(const Setting& s, const std::vector<double>& predicted) {
    double sq = 0, ape = 0;
    int counted = 0;
    for (std::size_t i : s.rows) {
        const double w = std::isfinite(predicted[i]) ? predicted[i] : 0.0;
        sq += (s.y[i] - w) * (s.y[i] - w);
        if (s.y[i] != 0) {
            ape += std::abs((s.y[i] - w) / s.y[i]);
            ++counted;
        }
    }
    return {std::sqrt(sq / s.rows.size()), counted ? 100.0 * ape / counted : nan};
}

std::vector<double> predictions(const Setting& s, const Model& m, const std::vector<double>& p) {
    std::vector<double> out(s.y.size());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = m.predict(i, p.data());
    return out;
}

// RMSE of predictions for whole conditions left out of the fit.
double cross_validated_rmse(const Setting& s, const Model& m, const std::vector<double>& full_fit) {
    std::vector<double> predicted(s.y.size(), nan);
    for (int f = 0; f < s.folds; ++f) {
        std::vector<std::size_t> train, test;
        for (std::size_t i : s.rows) (s.fold[i] == f ? test : train).push_back(i);
        if (test.empty()) continue;
        auto start = full_fit;
        double* tp = start.data() + m.param_names.size();
        for (const auto& t : m.terms) {
            if (t.clear_unseen) t.clear_unseen(train, tp);
            tp += t.param_names.size();
        }
        std::vector<double> p = start;
        if (train.size() >= start.size()) p = fit_rows(s, m, train, start).params;
        for (auto i : test) predicted[i] = m.predict(i, p.data());
    }
    return errors_of(s, predicted).rmse;
}

std::optional<LackOfFitTest> lack_of_fit(const Setting& s, const Model& m, const std::vector<double>& p) {
    std::vector<double> sum(s.n_conditions, 0.0), sum_sq(s.n_conditions, 0.0);
    std::vector<int> count(s.n_conditions, 0);
    double sse = 0;
    for (std::size_t i : s.rows) {
        const double r = residual(s, m, i, p.data());
        sse += r * r;
        sum[s.condition[i]] += r;
        sum_sq[s.condition[i]] += r * r;
        ++count[s.condition[i]];
    }
    double pure = 0;
    int conditions = 0;
    for (int c = 0; c < s.n_conditions; ++c)
        if (count[c] > 0) {
            pure += sum_sq[c] - sum[c] * sum[c] / count[c];
            ++conditions;
        }
    LackOfFitTest t;
    t.df_pure_error = static_cast<int>(s.rows.size()) - conditions;
    t.df_lack_of_fit = conditions - static_cast<int>(p.size());
    if (t.df_pure_error <= 0 || t.df_lack_of_fit <= 0 || pure <= 0) return std::nullopt;
    t.f_statistic = ((sse - pure) / t.df_lack_of_fit) / (pure / t.df_pure_error);
    t.p_value = gsl_cdf_fdist_Q(std::max(t.f_statistic, 0.0), t.df_lack_of_fit, t.df_pure_error);
    return t;
}

std::vector<ParameterEstimate> estimates(const Model& m, const LeastSquaresFit& fit) {
    std::vector<ParameterEstimate> out;
    std::size_t i = 0;
    for (const auto& name : m.param_names) {
        out.push_back({name, fit.params[i], fit.std_errors[i]});
        ++i;
    }
    for (const auto& t : m.terms)
        for (std::size_t k = 0; k < t.param_names.size(); ++k, ++i)
            out.push_back({t.variable + ": " + t.param_names[k], fit.params[i] * t.param_scale[k],
                           fit.std_errors[i] * std::abs(t.param_scale[k])});
    return out;
}

// --- columns --------------------------------------------------------------------------------------------------

const std::vector<std::string>& condition_columns(MeasuredKind kind) {
    static const std::vector<std::string> discharge{"geometry", "D_m",   "b_m",         "c_m",
                                                    "outlet_m", "theta_deg", "d_p_m", "rho_b_kg_m3"};
    static const std::vector<std::string> shear{"sigma_Pa"};
    return kind == MeasuredKind::discharge ? discharge : shear;
}

std::string cell_key(const DataColumn& c, std::size_t row) {
    if (!c.numeric) return c.text[row];
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.12g", c.values[row]);
    return buf;
}

bool all_finite(const DataColumn& c) {
    return c.numeric && std::all_of(c.values.begin(), c.values.end(), [](double v) { return std::isfinite(v); });
}

bool is_constant(const DataColumn& c) {
    for (std::size_t r = 1; r < c.text.size(); ++r)
        if (cell_key(c, r) != cell_key(c, 0)) return false;
    return true;
}

double mean_of(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / v.size(); }
double sd_of(const std::vector<double>& v) {
    const double m = mean_of(v);
    double s = 0;
    for (double x : v) s += (x - m) * (x - m);
    return std::sqrt(s / (v.size() > 1 ? v.size() - 1 : 1));
}

std::string short_number(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

bool drift_like(const std::string& name) {
    return name.find("order") != std::string::npos || name.find("time") != std::string::npos ||
           name.find("date") != std::string::npos;
}

// --- base models ------------------------------------------------------------------------------------------------

namespace {

// Every row of the data on silos of `shape`, or the row that is not, named.
void require_shape(const std::string& model, const MeasuredData& d, const std::string& shape) {
    const auto& geometry = d.at("geometry").text;
    for (std::size_t r = 0; r < d.rows(); ++r)
        if (geometry[r] != shape)
            throw std::invalid_argument(d.where(r, "geometry") + ": '" + geometry[r] + "', but model " + model +
                                        " applies to " + shape + " silos only");
}

Model failure_line_model(const MeasuredData& d, Setting& s) {
    Model m;
    const auto& sigma = d.at("sigma_Pa").values;
    const auto& tau = d.at("tau_Pa").values;
    if (sigma.size() < 3)
        throw std::invalid_argument(d.source + ": " + std::to_string(sigma.size()) + " rows: a failure line needs at "
                                    "least 3 points on at least 2 normal stresses");
    if (is_constant(d.at("sigma_Pa")))
        throw std::invalid_argument(d.source + ": sigma_Pa: every row has the normal stress " + short_number(sigma.front()) +
                                    " Pa: a failure line needs at least two different normal stresses");
    const auto [lowest, highest] = std::minmax_element(sigma.begin(), sigma.end());
    check_normal_stress_spread(*lowest, *highest, d.source + ": sigma_Pa");  // 5000, 5000.0000001, ... gave mu_b = 3.7e8
    // a shear strength that falls with the normal stress is no bulk solid's: mu_b = -0.98 was reported as determined
    if (const FailureLine line = fit_failure_line(sigma, tau); line.mu_b_high < 0)
        throw std::invalid_argument(d.source + ": sigma_Pa, tau_Pa: the failure line's slope mu_b = " + short_number(line.mu_b) +
                                    " (95 % interval up to " + short_number(line.mu_b_high) +
                                    ") is negative: the shear strength falls as the normal stress rises, which no bulk "
                                    "solid's does (columns swapped, or a sign lost?)");
    m.relative = false;
    m.param_names = {"mu_b", "tau_c_Pa"};
    double c0 = 0, c1 = 0, c00, c01, c11, sse;
    gsl_fit_linear(sigma.data(), 1, tau.data(), 1, sigma.size(), &c0, &c1, &c00, &c01, &c11, &sse);
    m.start = {std::isfinite(c1) ? c1 : 0.5, std::isfinite(c0) ? c0 : 0.0};
    m.base = [&sigma](std::size_t r, const double* p) { return p[0] * sigma[r] + p[1]; };
    s.used = {"sigma_Pa"};
    return m;
}

// The columns every discharge model reads (validate_measured has checked they are there), by reference into the data.
struct DischargeColumns {
    const std::vector<double>& outlet;
    const std::vector<double>& dp;
    const std::vector<double>& rho;
};
DischargeColumns discharge_columns(const MeasuredData& d) {
    return {d.at("outlet_m").values, d.at("d_p_m").values, d.at("rho_b_kg_m3").values};
}

Model beverloo_model(const MeasuredData& d, Setting& s) {
    require_shape("beverloo", d, "conical");
    const DischargeColumns c = discharge_columns(d);
    Model m;
    m.param_names = {"C", "k"};
    m.start = {0.58, 1.5};
    // Nedderman's C 0.55-0.65 (0.5-0.7 over the literature) and k 1-3 (up to 2.9 for angular grains), widened
    m.plausible = {{0.3, 1.0}, {0.5, 4.0}};
    m.base = [c](std::size_t r, const double* p) {  // an outlet the annulus fills: no rate to fit (beverloo_rate: 0)
        return c.outlet[r] - p[1] * c.dp[r] > 0 ? beverloo_rate(c.outlet[r], c.dp[r], c.rho[r], p[0], p[1]) : nan;
    };
    s.used = {"outlet_m", "d_p_m", "rho_b_kg_m3"};
    return m;
}

// Oldal's arch model, one parameter: the arch's height over the outlet delta (> 0), from its usual 0.5.
Model arch_model(std::function<double(std::size_t row, double delta)> rate, std::set<std::string> used, Setting& s) {
    Model m;
    m.param_names = {"delta"};
    m.start = {0.5};
    m.base = [rate = std::move(rate)](std::size_t r, const double* p) { return p[0] > 0 ? rate(r, p[0]) : nan; };
    s.used = std::move(used);
    return m;
}

Model oldal_model(const MeasuredData& d, Setting& s) {
    require_shape("oldal", d, "conical");
    const DischargeColumns c = discharge_columns(d);
    return arch_model([c](std::size_t r, double delta) { return oldal_rate(c.outlet[r], c.dp[r], c.rho[r], delta); },
                      {"outlet_m", "d_p_m", "rho_b_kg_m3"}, s);
}

Model oldal_rect_model(const MeasuredData& d, Setting& s) {
    require_shape("oldal-rect", d, "rectangular");
    const auto& depth = d.at("b_m").values;
    const DischargeColumns c = discharge_columns(d);
    return arch_model(
        [&depth, c](std::size_t r, double delta) {
            return oldal_rectangular_rate(depth[r], c.outlet[r], c.dp[r], c.rho[r], delta);
        },
        {"b_m", "outlet_m", "d_p_m", "rho_b_kg_m3"}, s);
}

Model johanson_model(const MeasuredData& d, Setting& s) {
    const auto& geometry = d.at("geometry").text;
    const auto& outlet = d.at("outlet_m").values;
    const auto& rho = d.at("rho_b_kg_m3").values;
    const auto& theta = d.at("theta_deg").values;
    for (std::size_t r = 0; r < d.rows(); ++r)
        if (theta[r] >= 90)
            throw std::invalid_argument(d.where(r, "theta_deg") + ": 90 (flat bottom): Johanson's mass-flow "
                                        "model needs a hopper");
    const DataColumn* depth = d.find("b_m");
    Model m;
    m.param_names = {"scale"};
    m.start = {1.0};
    m.plausible = {{0.1, 10.0}};  // a factor on Johanson's own rate: beyond 10x the data are of another unit or model
    m.base = [&geometry, &outlet, &theta, &rho, depth](std::size_t r, const double* p) {
        return p[0] * (geometry[r] == "conical" ? johanson_conical_rate(outlet[r], theta[r], rho[r])
                                                : johanson_wedge_rate(depth->values[r], outlet[r], theta[r], rho[r]));
    };
    s.used = {"outlet_m", "theta_deg", "rho_b_kg_m3", "b_m"};
    return m;
}

}  // namespace

Model base_model(const std::string& name, const MeasuredData& d, Setting& s) {
    using Builder = Model (*)(const MeasuredData&, Setting&);
    static const std::map<std::string, Builder> builders = {{"failure-line", failure_line_model},
                                                            {"beverloo", beverloo_model},
                                                            {"oldal", oldal_model},
                                                            {"oldal-rect", oldal_rect_model},
                                                            {"johanson", johanson_model}};
    const auto it = builders.find(name);
    if (it == builders.end()) throw std::invalid_argument("unknown model " + name);
    Model m = it->second(d, s);
    m.name = name;
    return m;
}

}  // namespace demcal::analytics::diagnosis
