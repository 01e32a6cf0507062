#include "analytics/diagnose.hpp"

#include "analytics/discharge_models.hpp"
#include "analytics/regression.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>
#include <gsl/gsl_linalg.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <stdexcept>

namespace demcal::analytics {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
// Below this RMS of the dimensionless residuals a fit is exact to rounding (doubles carry about 1e-16).
constexpr double kExactFitResidual = 1e-9;
// Residual given to a prediction the model cannot make (non-positive rate, outlet blocked by the annulus): large
// enough that the optimiser steps back, finite so that GSL keeps going.
constexpr double penalty_residual = 30.0;

// An effect added to a model: it maps the prediction so far to a new one.
struct Term {
    std::string variable, form, kind;
    std::vector<std::string> param_names;
    std::vector<double> param_scale;             // reported value = fitted value * scale (fits run on O(1) numbers)
    std::vector<std::vector<double>> starts;     // starting points tried for this term's parameters
    // tp: this term's parameters, bp: the base model's parameters.
    std::function<double(double prediction, std::size_t row, const double* tp, const double* bp)> apply;
    // Zeroes the parameters that the rows cannot inform (levels of a category absent from a CV training set).
    std::function<void(const std::vector<std::size_t>& rows, double* tp)> clear_unseen;
    std::string regime = {};  // see CandidateTest::regime
};

struct Model {
    std::string name;
    bool relative = true;  // residuals on log scale
    std::vector<std::string> param_names;
    std::vector<double> start;
    std::function<double(std::size_t row, const double* p)> base;
    std::vector<Term> terms;

    std::size_t size() const {
        std::size_t n = param_names.size();
        for (const auto& t : terms) n += t.param_names.size();
        return n;
    }
    double predict(std::size_t row, const double* p) const {
        double w = base(row, p);
        const double* tp = p + param_names.size();
        for (const auto& t : terms) {
            w = t.apply(w, row, tp, p);
            tp += t.param_names.size();
        }
        return w;
    }
};

// A partition of the rows under which a covariate's effect may differ.
struct Regime {
    std::string name;    // "flow_mode" or the categorical column
    std::string source;  // the column the levels come from (not tried as the covariate of its own regime)
    std::vector<std::string> level_names;
    std::shared_ptr<const std::vector<int>> level;  // level of each row
};

struct Setting {
    const MeasuredData& data;
    std::vector<double> y;
    double scale = 1;                // absolute residuals are divided by it (conditioning only)
    std::vector<int> condition;      // condition index of each row
    int n_conditions = 0;
    std::vector<int> fold;           // CV fold of each row
    int folds = 0;
    std::set<std::string> used;      // columns the model's formula uses
    std::vector<std::size_t> rows;   // the rows fitted and scored: all, or all but the flagged outliers
    std::vector<Regime> regimes;
};

// A term's effect eta on the prediction: a factor exp(eta) on a rate (relative residuals), an offset scale*eta on a
// stress (absolute residuals, fitted in units of scale).
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

struct Errors {
    double rmse = 0, mape = 0;
};

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

Model base_model(const std::string& name, const MeasuredData& d, Setting& s) {
    Model m;
    m.name = name;
    if (name == "failure-line") {
        const auto& sigma = d.at("sigma_Pa").values;
        const auto& tau = d.at("tau_Pa").values;
        if (is_constant(d.at("sigma_Pa")))
            throw std::invalid_argument("sigma_Pa: every row has the normal stress " + short_number(sigma.front()) +
                                        " Pa: a failure line needs at least two different normal stresses");
        m.relative = false;
        m.param_names = {"mu_b", "tau_c_Pa"};
        double c0 = 0, c1 = 0, c00, c01, c11, sse;
        gsl_fit_linear(sigma.data(), 1, tau.data(), 1, sigma.size(), &c0, &c1, &c00, &c01, &c11, &sse);
        m.start = {std::isfinite(c1) ? c1 : 0.5, std::isfinite(c0) ? c0 : 0.0};
        m.base = [&sigma](std::size_t r, const double* p) { return p[0] * sigma[r] + p[1]; };
        s.used = {"sigma_Pa"};
        return m;
    }
    const auto& geometry = d.at("geometry").text;
    const auto& outlet = d.at("outlet_m").values;
    const auto& dp = d.at("d_p_m").values;
    const auto& rho = d.at("rho_b_kg_m3").values;
    const auto& theta = d.at("theta_deg").values;
    auto require_shape = [&](const std::string& shape) {
        for (std::size_t r = 0; r < d.rows(); ++r)
            if (geometry[r] != shape)
                throw std::invalid_argument(d.where(r, "geometry") + ": '" + geometry[r] + "', but model " + name +
                                            " applies to " + shape + " silos only");
    };
    if (name == "beverloo") {
        require_shape("conical");
        m.param_names = {"C", "k"};
        m.start = {0.58, 1.5};
        m.base = [&](std::size_t r, const double* p) {
            const double e = outlet[r] - p[1] * dp[r];
            return e > 0 ? p[0] * rho[r] * std::sqrt(standard_gravity) * std::pow(e, 2.5) : nan;
        };
        s.used = {"outlet_m", "d_p_m", "rho_b_kg_m3"};
    } else if (name == "oldal") {
        require_shape("conical");
        m.param_names = {"delta"};
        m.start = {0.5};
        m.base = [&](std::size_t r, const double* p) {
            return p[0] > 0 ? oldal_rate(outlet[r], dp[r], rho[r], p[0]) : nan;
        };
        s.used = {"outlet_m", "d_p_m", "rho_b_kg_m3"};
    } else if (name == "oldal-rect") {
        require_shape("rectangular");
        const auto& depth = d.at("b_m").values;
        m.param_names = {"delta"};
        m.start = {0.5};
        m.base = [&](std::size_t r, const double* p) {
            return p[0] > 0 ? oldal_rectangular_rate(depth[r], outlet[r], dp[r], rho[r], p[0]) : nan;
        };
        s.used = {"b_m", "outlet_m", "d_p_m", "rho_b_kg_m3"};
    } else if (name == "johanson") {
        for (std::size_t r = 0; r < d.rows(); ++r)
            if (theta[r] >= 90)
                throw std::invalid_argument(d.where(r, "theta_deg") + ": 90 (flat bottom): Johanson's mass-flow "
                                            "model needs a hopper");
        const auto* depth = d.find("b_m");
        m.param_names = {"scale"};
        m.start = {1.0};
        m.base = [&, depth](std::size_t r, const double* p) {
            return p[0] * (geometry[r] == "conical"
                               ? johanson_conical_rate(outlet[r], theta[r], rho[r])
                               : johanson_wedge_rate(depth->values[r], outlet[r], theta[r], rho[r]));
        };
        s.used = {"outlet_m", "theta_deg", "rho_b_kg_m3", "b_m"};
    } else {
        throw std::invalid_argument("unknown model " + name);
    }
    return m;
}

// --- candidate effects ------------------------------------------------------------------------------------------

// For Term::clear_unseen: zeroes the parameter of every level (from first_level on, at tp[level - first_level]) that
// the training rows do not contain.
std::function<void(const std::vector<std::size_t>&, double*)> unseen_levels_cleared(
    std::shared_ptr<const std::vector<int>> level, int levels, int first_level) {
    return [level, levels, first_level](const std::vector<std::size_t>& rows, double* tp) {
        std::vector<bool> seen(levels, false);
        for (auto r : rows) seen[(*level)[r]] = true;
        for (int l = first_level; l < levels; ++l)
            if (!seen[l]) tp[l - first_level] = 0.0;
    };
}

// Where a regime slope of x is measured from, row by row. A covariate with an off state (0 in the data, e.g. vibration
// off) acts from 0: the regimes agree when it is off. Any other covariate is centred within each level (`level`, or
// one level when null), so that its slopes cannot stand in for a difference in level between the regimes (an angle
// effect), which is the business of the base model and of other candidates.
struct SlopeOrigin {
    std::shared_ptr<const std::vector<double>> of_row;
    std::string text;  // for the form
};

SlopeOrigin slope_origin(const std::vector<double>& x, const std::shared_ptr<const std::vector<int>>& level) {
    const std::size_t n = x.size();
    if (*std::min_element(x.begin(), x.end()) == 0.0)
        return {std::make_shared<const std::vector<double>>(n, 0.0), "x_ref = 0 (off)"};
    const int levels = level ? *std::max_element(level->begin(), level->end()) + 1 : 1;
    std::vector<double> sum(levels, 0.0), count(levels, 0.0);
    for (std::size_t r = 0; r < n; ++r) {
        const int l = level ? (*level)[r] : 0;
        sum[l] += x[r];
        count[l] += 1;
    }
    std::vector<double> origin(n);
    for (std::size_t r = 0; r < n; ++r) {
        const int l = level ? (*level)[r] : 0;
        origin[r] = sum[l] / count[l];
    }
    std::string text = level ? "x_ref = mean of x in each level" : "x_ref = mean of x = " + short_number(origin[0]);
    return {std::make_shared<const std::vector<double>>(std::move(origin)), std::move(text)};
}

// x's effect per level of a regime: eta = beta[level] * (x - x_ref).
Term regime_term(const Setting& s, const Model& m, const DataColumn& col, const Regime& g) {
    const auto& x = col.values;
    const double sd = sd_of(x);
    const auto origin = slope_origin(x, g.level);
    const std::string levels = [&] {
        std::string out;
        for (const auto& l : g.level_names) out += (out.empty() ? "" : "|") + l;
        return out;
    }();
    const std::string eta = "beta[" + g.name + "]*(x - x_ref)";
    Term t{col.name,
           (m.relative ? "W *= exp(" + eta + ")" : "tau += " + eta) + ", " + origin.text + ", " + g.name + " in " +
               levels,
           "regime", {}, {}, {std::vector<double>(g.level_names.size(), 0.0)}, nullptr, nullptr, g.name};
    for (const auto& l : g.level_names) {
        t.param_names.push_back("beta[" + l + "]");
        t.param_scale.push_back((m.relative ? 1.0 : s.scale) / sd);
    }
    const bool rel = m.relative;
    const double scale = s.scale;
    t.apply = [&x, x_ref = origin.of_row, sd, level = g.level, rel, scale](double w, std::size_t r, const double* tp,
                                                                           const double*) {
        return apply_effect(w, tp[(*level)[r]] * (x[r] - (*x_ref)[r]) / sd, rel, scale);
    };
    t.clear_unseen = unseen_levels_cleared(g.level, static_cast<int>(g.level_names.size()), 0);
    return t;
}

// x's effect changing continuously with a condition variable z: eta = (beta + gamma*(z - z0)) * (x - x_ref).
Term interaction_term(const Setting& s, const Model& m, const DataColumn& x_col, const DataColumn& z_col) {
    const auto& x = x_col.values;
    const auto& z = z_col.values;
    const double sd_x = sd_of(x);
    const auto origin = slope_origin(x, nullptr);
    const double z0 = mean_of(z), sd_z = sd_of(z);
    const std::string eta = "(beta + gamma*(z - z0))*(x - x_ref)";
    const double unit = m.relative ? 1.0 : s.scale;
    Term t{x_col.name,
           (m.relative ? "W *= exp(" + eta + ")" : "tau += " + eta) + ", z = " + z_col.name +
               ", z0 = " + short_number(z0) + ", " + origin.text,
           "interaction", {"beta", "gamma"}, {unit / sd_x, unit / (sd_x * sd_z)}, {{0.0, 0.0}}, nullptr, nullptr,
           z_col.name};
    const bool rel = m.relative;
    const double scale = s.scale;
    t.apply = [&x, &z, x_ref = origin.of_row, sd_x, z0, sd_z, rel, scale](double w, std::size_t r, const double* tp,
                                                                          const double*) {
        return apply_effect(w, (tp[0] + tp[1] * (z[r] - z0) / sd_z) * (x[r] - (*x_ref)[r]) / sd_x, rel, scale);
    };
    return t;
}

// Candidates whose covariate x acts differently by regime or along a condition variable. x: a numeric covariate that
// describes the run, not the set-up (condition columns are the model's business), not yet an effect.
std::vector<Term> regime_candidates(const Setting& s, const Model& m, const std::set<std::string>& done) {
    const auto& d = s.data;
    const MeasuredKind kind = m.relative ? MeasuredKind::discharge : MeasuredKind::shear;
    const auto& conditions = condition_columns(kind);
    auto is_condition = [&](const std::string& name) {
        return std::find(conditions.begin(), conditions.end(), name) != conditions.end();
    };
    auto varies = [](const DataColumn& c) { return all_finite(c) && !is_constant(c); };
    std::vector<Term> out;
    for (const auto& x : d.columns) {
        if (!x.numeric || x.name == (m.relative ? "W_kg_s" : "tau_Pa") || is_condition(x.name) ||
            s.used.count(x.name) || done.count(x.name) || !varies(x))
            continue;
        for (const auto& g : s.regimes)
            if (g.source != x.name) out.push_back(regime_term(s, m, x, g));
        for (const auto& z : conditions)
            if (const auto* zc = d.find(z); zc && varies(*zc)) out.push_back(interaction_term(s, m, x, *zc));
    }
    return out;
}

std::vector<Term> candidates(const Setting& s, const Model& m, const std::set<std::string>& done,
                             std::vector<std::string>& warnings, bool first_round) {
    const auto& d = s.data;
    const std::size_t n = d.rows();
    const std::string response = m.relative ? "W_kg_s" : "tau_Pa";
    const std::string y = m.relative ? "W" : "tau";
    std::vector<Term> out;
    bool some_column_orders_rows = false;

    for (const auto& col : d.columns) {
        if (col.name == response || done.count(col.name) || is_constant(col)) continue;
        if (col.numeric) {
            if (!all_finite(col)) continue;  // a geometry-specific size in a mixed file
            bool monotone = true;
            for (std::size_t r = 1; r < n; ++r) monotone = monotone && col.values[r] >= col.values[r - 1];
            some_column_orders_rows = some_column_orders_rows || monotone;
            const auto& x = col.values;
            const double x0 = mean_of(x), sd = sd_of(x);
            const bool positive = std::all_of(x.begin(), x.end(), [](double v) { return v > 0; });
            if (s.used.count(col.name) && positive && m.relative) {
                Term t{col.name, y + " *= (x/x0)^beta, x0 = " + short_number(x0), "nonlinearity", {"beta"}, {1.0},
                       {{0.0}}, nullptr, nullptr};
                t.apply = [&x, x0](double w, std::size_t r, const double* tp, const double*) {
                    return w * std::pow(x[r] / x0, tp[0]);
                };
                out.push_back(t);
            } else if (!s.used.count(col.name)) {
                // Fitted per standard deviation of x, reported per unit of x.
                Term t{col.name,
                       m.relative ? "W *= exp(beta*(x - x0)), x0 = " + short_number(x0)
                                  : "tau += beta*(x - x0), x0 = " + short_number(x0),
                       drift_like(col.name) ? "drift" : "missing variable",
                       {"beta"},
                       {m.relative ? 1.0 / sd : s.scale / sd},
                       {{0.0}},
                       nullptr,
                       nullptr};
                const bool rel = m.relative;
                const double scale = s.scale;
                t.apply = [&x, x0, sd, rel, scale](double w, std::size_t r, const double* tp, const double*) {
                    return apply_effect(w, tp[0] * (x[r] - x0) / sd, rel, scale);
                };
                out.push_back(t);
            }
        } else {
            std::map<std::string, int> level_of;  // levels in order of appearance; the first is the reference
            std::vector<int> level(n);
            std::vector<std::string> names;
            for (std::size_t r = 0; r < n; ++r) {
                auto [it, added] = level_of.emplace(col.text[r], static_cast<int>(level_of.size()));
                if (added) names.push_back(col.text[r]);
                level[r] = it->second;
            }
            const int levels = static_cast<int>(level_of.size());
            if (levels > static_cast<int>(n) / 3) {
                if (first_round)
                    warnings.push_back("column " + col.name + " has " + std::to_string(levels) +
                                       " levels for " + std::to_string(n) + " rows: treated as an identifier, not tested");
                continue;
            }
            Term t{col.name, m.relative ? "W *= exp(b[level]), b[" + names[0] + "] = 0" : "tau += b[level], b[" + names[0] + "] = 0",
                   "missing variable", {}, {}, {std::vector<double>(levels - 1, 0.0)}, nullptr, nullptr};
            for (int l = 1; l < levels; ++l) {
                t.param_names.push_back("b[" + names[l] + "]");
                t.param_scale.push_back(m.relative ? 1.0 : s.scale);
            }
            const bool rel = m.relative;
            const double scale = s.scale;
            auto shared_level = std::make_shared<std::vector<int>>(level);
            t.apply = [shared_level, rel, scale](double w, std::size_t r, const double* tp, const double*) {
                const int l = (*shared_level)[r];
                return apply_effect(w, l == 0 ? 0.0 : tp[l - 1], rel, scale);
            };
            t.clear_unseen = unseen_levels_cleared(shared_level, levels, 1);
            out.push_back(t);
        }
    }

    // Physical effects from the library.
    const auto* theta = d.find("theta_deg");
    if (m.relative && theta && !s.used.count("theta_deg") && !done.count("theta_deg") && !is_constant(*theta)) {
        const auto& th = theta->values;
        Term t{"theta_deg", "W *= (tan(theta) tan(phi_d))^-0.35 if theta < 90 - phi_d (Rose-Tanaka)", "physical",
               {"phi_d_deg"}, {1.0}, {{30.0}, {45.0}, {60.0}, {75.0}}, nullptr, nullptr};
        t.apply = [&th](double w, std::size_t r, const double* tp, const double*) {
            if (!(tp[0] > 0.5 && tp[0] < 89.5)) return nan;
            return w * rose_tanaka_factor(th[r], tp[0]);
        };
        out.push_back(t);
    }
    const auto* dp = d.find("d_p_m");
    // (a d_p that does not vary only rescales every rate: the base model's own constants absorb it)
    if (m.relative && dp && (m.name == "oldal" || m.name == "oldal-rect" || m.name == "johanson") &&
        !done.count("d_p_m") && !is_constant(*dp)) {
        // Oldal's effective outlet is d - d_p (k0 = 1), Johanson has none (k0 = 0); the annulus k d_p generalises both.
        const double k0 = m.name == "johanson" ? 0.0 : 1.0;
        const auto& outlet = d.at("outlet_m").values;
        const auto& geometry = d.at("geometry").text;
        const auto& p = dp->values;
        Term t{"d_p_m", "W *= ((B - k d_p)/(B - " + std::to_string(static_cast<int>(k0)) +
                            " d_p))^e, e = 2.5 circular, 1.5 slot (empty annulus)",
               "physical", {"k"}, {1.0}, {{k0 + 0.5}}, nullptr, nullptr};
        t.apply = [&outlet, &geometry, &p, k0](double w, std::size_t r, const double* tp, const double*) {
            const double e = geometry[r] == "conical" ? 2.5 : 1.5;
            const double num = outlet[r] - tp[0] * p[r], den = outlet[r] - k0 * p[r];
            return num > 0 ? w * std::pow(num / den, e) : nan;
        };
        out.push_back(t);
    }
    if (!m.relative && !done.count("sigma_Pa")) {
        const auto& sigma = d.at("sigma_Pa").values;
        const double s0 = mean_of(sigma);
        Term t{"sigma_Pa", "tau = mu_b*s0*(sigma/s0)^n + tau_c, s0 = " + short_number(s0) + " (curved yield locus)",
               "physical", {"n"}, {1.0}, {{1.0}, {0.8}, {1.2}}, nullptr, nullptr};
        t.apply = [&sigma, s0](double w, std::size_t r, const double* tp, const double* bp) {
            if (!(tp[0] > 0)) return nan;
            return w + bp[0] * (s0 * std::pow(sigma[r] / s0, tp[0]) - sigma[r]);
        };
        out.push_back(t);
    }
    for (auto& t : regime_candidates(s, m, done)) out.push_back(std::move(t));
    // Drift in the order of the file, unless a column (a run number, a time) already orders the rows.
    if (!some_column_orders_rows && !done.count("row_order") && n > 2) {
        auto order = std::make_shared<std::vector<double>>(n);
        std::iota(order->begin(), order->end(), 0.0);
        const double x0 = (n - 1) / 2.0, sd = sd_of(*order);
        const bool rel = m.relative;
        const double scale = s.scale;
        Term t{"row_order", rel ? "W *= exp(beta*(row - row0)) (drift in file order)" : "tau += beta*(row - row0) (drift in file order)",
               "drift", {"beta_per_row"}, {rel ? 1.0 / sd : scale / sd}, {{0.0}}, nullptr, nullptr};
        t.apply = [order, x0, sd, rel, scale](double w, std::size_t r, const double* tp, const double*) {
            return apply_effect(w, tp[0] * ((*order)[r] - x0) / sd, rel, scale);
        };
        out.push_back(t);
    }
    return out;
}

void holm(std::vector<CandidateTest>& tests) {
    std::vector<std::size_t> idx(tests.size());
    std::iota(idx.begin(), idx.end(), 0);
    std::sort(idx.begin(), idx.end(), [&](auto a, auto b) { return tests[a].p_value < tests[b].p_value; });
    double running = 0;
    const double m = static_cast<double>(tests.size());
    for (std::size_t j = 0; j < idx.size(); ++j) {
        running = std::max(running, std::min(1.0, (m - j) * tests[idx[j]].p_value));
        tests[idx[j]].p_holm = running;
    }
}

// --- regimes ----------------------------------------------------------------------------------------------------

// The regimes the data and options define: the flow mode (conical hoppers whose angles span more than one mode) and
// each categorical column the user names.
std::vector<Regime> regimes_of(const MeasuredData& d, MeasuredKind kind, const DiagnoseOptions& options,
                               std::string& flow_mode_rule) {
    const std::size_t n = d.rows();
    std::vector<Regime> out;
    if (options.effective_friction_deg.has_value() != options.wall_friction_deg.has_value())
        throw std::invalid_argument(
            "flow mode by Jenike's limit needs both friction angles: " +
            (options.wall_friction_deg ? "wall_friction_deg=" + short_number(*options.wall_friction_deg) +
                                             " given, effective_friction_deg missing"
                                       : "effective_friction_deg=" + short_number(*options.effective_friction_deg) +
                                             " given, wall_friction_deg missing"));
    double limit = seed_mass_flow_limit_deg;
    flow_mode_rule = "seed classes: mass below 30 deg, mixed 30-40 deg, funnel above 40 deg";
    if (options.wall_friction_deg) {
        try {
            limit = jenike_mass_flow_limit_deg(*options.effective_friction_deg, *options.wall_friction_deg);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(std::string("flow mode by Jenike's limit: ") + e.what());
        }
        flow_mode_rule = "Jenike's limit " + short_number(limit) + " deg (delta_e " +
                         short_number(*options.effective_friction_deg) + ", phi_w " +
                         short_number(*options.wall_friction_deg) + "): mass below it, mixed up to " +
                         short_number(limit + mixed_flow_band_deg) + " deg, funnel above";
    }
    const auto* theta = d.find("theta_deg");
    const auto* geometry = d.find("geometry");
    const bool conical = kind == MeasuredKind::discharge && theta && geometry &&
                         std::all_of(geometry->text.begin(), geometry->text.end(),
                                     [](const std::string& g) { return g == "conical"; });
    if (conical) {
        Regime g{"flow_mode", "theta_deg", {}, nullptr};
        std::vector<int> mode(n);
        for (std::size_t r = 0; r < n; ++r) mode[r] = static_cast<int>(flow_mode_of_angle(theta->values[r], limit));
        // Levels in the order mass, mixed, funnel; only the modes present.
        std::vector<int> index(3, -1);
        for (int k = 0; k < 3; ++k)
            if (std::find(mode.begin(), mode.end(), k) != mode.end()) {
                index[k] = static_cast<int>(g.level_names.size());
                g.level_names.push_back(to_string(static_cast<FlowMode>(k)));
            }
        for (auto& v : mode) v = index[v];
        g.level = std::make_shared<const std::vector<int>>(std::move(mode));
        if (g.level_names.size() > 1) out.push_back(std::move(g));
    }
    for (const auto& name : options.regime_columns) {
        const auto* col = d.find(name);
        if (!col) {
            std::string known;
            for (const auto& c : d.columns) known += (known.empty() ? "" : ", ") + c.name;
            throw std::invalid_argument("regime column '" + name + "' is not in " + d.source + " (columns: " + known +
                                        ")");
        }
        Regime g{name, name, {}, nullptr};
        std::map<std::string, int> level_of;
        std::vector<int> level(n);
        for (std::size_t r = 0; r < n; ++r) {
            auto [it, added] = level_of.emplace(col->text[r], static_cast<int>(level_of.size()));
            if (added) g.level_names.push_back(col->text[r]);
            level[r] = it->second;
        }
        if (g.level_names.size() < 2)
            throw std::invalid_argument("regime column '" + name + "' has a single value '" + g.level_names[0] +
                                        "': no regimes to compare");
        if (g.level_names.size() > n / 3)
            throw std::invalid_argument("regime column '" + name + "' has " + std::to_string(g.level_names.size()) +
                                        " values for " + std::to_string(n) +
                                        " rows: too many for a slope per value (at most a third of the rows)");
        g.level = std::make_shared<const std::vector<int>>(std::move(level));
        out.push_back(std::move(g));
    }
    return out;
}

// --- outliers ---------------------------------------------------------------------------------------------------

// Externally studentized residuals of s.rows under the fit p to s.rows (the deletion formulas of least squares, with
// the leverages of the Jacobian at p); NaN where a row's leverage is 1 (it alone fixes a parameter).
std::vector<double> studentized_residuals(const Setting& s, const Model& m, const std::vector<double>& p) {
    const std::size_t n = s.rows.size(), k = p.size();
    std::vector<double> t(n, nan);
    if (n < k + 2) return t;
    std::vector<double> e(n);
    double sse = 0;
    for (std::size_t i = 0; i < n; ++i) {
        e[i] = residual(s, m, s.rows[i], p.data());
        sse += e[i] * e[i];
    }
    // Jacobian by central differences, then its SVD: the leverage of row i is the squared norm of row i of U over the
    // singular values that are not zero.
    gsl_matrix* u = gsl_matrix_alloc(n, k);
    gsl_matrix* v = gsl_matrix_alloc(k, k);
    gsl_vector* sv = gsl_vector_alloc(k);
    gsl_vector* work = gsl_vector_alloc(k);
    std::vector<double> q = p;
    for (std::size_t j = 0; j < k; ++j) {
        const double h = 1e-6 * std::max(1.0, std::abs(p[j]));
        q[j] = p[j] + h;
        std::vector<double> up(n);
        for (std::size_t i = 0; i < n; ++i) up[i] = residual(s, m, s.rows[i], q.data());
        q[j] = p[j] - h;
        for (std::size_t i = 0; i < n; ++i)
            gsl_matrix_set(u, i, j, (up[i] - residual(s, m, s.rows[i], q.data())) / (2 * h));
        q[j] = p[j];
    }
    gsl_linalg_SV_decomp(u, v, sv, work);
    const double tolerance = gsl_vector_get(sv, 0) * 1e-10 * static_cast<double>(n);
    const double dof = static_cast<double>(n - k);
    for (std::size_t i = 0; i < n; ++i) {
        double h = 0;
        for (std::size_t j = 0; j < k; ++j)
            if (gsl_vector_get(sv, j) > tolerance) h += gsl_matrix_get(u, i, j) * gsl_matrix_get(u, i, j);
        if (h > 1 - 1e-9) continue;
        const double s2 = (sse - e[i] * e[i] / (1 - h)) / (dof - 1);  // residual variance without row i
        if (s2 > 0) t[i] = e[i] / std::sqrt(s2 * (1 - h));
    }
    gsl_vector_free(work);
    gsl_vector_free(sv);
    gsl_matrix_free(v);
    gsl_matrix_free(u);
    return t;
}

// The Bonferroni threshold for |t| over the n rows of a fit with k parameters.
double outlier_threshold(std::size_t n, std::size_t k, double alpha) {
    return n >= k + 2 ? gsl_cdf_tdist_Qinv(alpha / (2.0 * n), static_cast<double>(n - k - 1)) : nan;
}

// Rows (indices into the data) of s.rows whose studentized residual under the fit p is beyond the threshold.
std::vector<std::size_t> flagged_rows(const Setting& s, const Model& m, const std::vector<double>& p, double alpha) {
    const auto t = studentized_residuals(s, m, p);
    const double limit = outlier_threshold(s.rows.size(), p.size(), alpha);
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < t.size(); ++i)
        if (std::abs(t[i]) > limit) out.push_back(s.rows[i]);
    return out;
}

// --- the search -------------------------------------------------------------------------------------------------

// The base model fitted to s.rows, restarted once when GSL stops at its iteration limit.
LeastSquaresFit fit_base(const Setting& s, const Model& m, std::vector<std::string>& warnings) {
    LeastSquaresFit fit = fit_extended(s, m, m.start);
    if (!fit.converged) {
        // GSL also stops at its iteration limit when started at the optimum; only a restart that still improves the
        // sum of squares means the fit had not converged.
        const auto again = fit_rows(s, m, s.rows, fit.params);
        if (again.sse < fit.sse * (1 - 1e-8)) warnings.push_back("the fit of " + m.name + " did not converge");
        if (again.sse < fit.sse) fit = again;
    }
    return fit;
}

struct Search {
    Model model;  // the base model with the effects added
    LeastSquaresFit base_fit, fit;
    double cv_after = 0;  // CV RMSE of the model found, on the rows searched
    std::vector<AddedEffect> effects;
    std::vector<std::vector<CandidateTest>> rounds;
};

// The rounds of candidate tests on s.rows (F test, Holm, cross-validation), from the base model.
Search search_effects(const Setting& s, const Model& base, const DiagnoseOptions& options,
                      std::vector<std::string>& warnings) {
    Search out{base, fit_base(s, base, warnings), {}, 0, {}, {}};
    Model& m = out.model;
    LeastSquaresFit& fit = out.fit;
    fit = out.base_fit;
    const std::size_t n = s.rows.size();
    // Residuals are dimensionless (log ratios, or stresses over their scale): a base fit exact to rounding leaves no
    // scatter for an F test (0/0) and nothing to explain, whatever a candidate's fit does with the last bits.
    const double base_rms = std::sqrt(fit.sse / double(std::max<std::size_t>(n, 1)));
    if (std::isfinite(base_rms) && base_rms < kExactFitResidual) {
        out.cv_after = cross_validated_rmse(s, m, fit.params);
        warnings.push_back("the " + m.name + " model fits every row to rounding (residual RMS " + short_number(base_rms) +
                           "): the data carry no scatter to test an effect against (identical or noiseless rows?); "
                           "no effect was searched");
        return out;
    }
    out.cv_after = cross_validated_rmse(s, m, fit.params);
    double& cv_now = out.cv_after;
    std::set<std::string> done;
    for (int round = 0; round < options.max_effects; ++round) {
        auto terms = candidates(s, m, done, warnings, round == 0);
        if (terms.empty()) break;
        std::vector<CandidateTest> tests;
        std::vector<LeastSquaresFit> fits;
        for (const auto& t : terms) {
            Model bigger = m;
            bigger.terms.push_back(t);
            CandidateTest c{t.variable, t.form, t.kind, t.regime, static_cast<int>(t.param_names.size()),
                            0,          1,      1,      nan,      false};
            const int dof = static_cast<int>(n) - static_cast<int>(bigger.size());
            LeastSquaresFit f = dof > 0 ? fit_extended(s, bigger, fit.params) : LeastSquaresFit{};
            if (dof > 0 && std::isfinite(f.sse) && f.sse < fit.sse) {
                c.f_statistic = ((fit.sse - f.sse) / c.extra_params) / (f.sse / dof);
                c.p_value = f.sse > 0 ? gsl_cdf_fdist_Q(c.f_statistic, c.extra_params, dof) : 0.0;
            }
            tests.push_back(c);
            fits.push_back(f);
        }
        holm(tests);
        int best = -1;
        for (std::size_t i = 0; i < tests.size(); ++i) {
            if (tests[i].p_holm >= options.family_alpha) continue;  // CV only for the significant ones: it is dearer
            Model bigger = m;
            bigger.terms.push_back(terms[i]);
            tests[i].cv_rmse = cross_validated_rmse(s, bigger, fits[i].params);
            if (tests[i].cv_rmse < (1.0 - options.min_cv_improvement) * cv_now &&
                (best < 0 || tests[i].cv_rmse < tests[best].cv_rmse))
                best = static_cast<int>(i);
        }
        // A simpler or more telling candidate that predicts about as well as the best (within min_cv_improvement)
        // replaces it: x's own plain term replaces x by regime or x*z (extra slopes fitted to a plain effect's noise
        // would call it regime-dependent), and a physical effect from the library replaces a generic term (it names
        // the mechanism; the generic one is often its approximation).
        auto prefer = [&](auto&& qualifies) {
            for (std::size_t i = 0; i < tests.size(); ++i)
                if (qualifies(tests[i]) && tests[i].p_holm < options.family_alpha &&
                    tests[i].cv_rmse < (1.0 - options.min_cv_improvement) * cv_now &&
                    tests[i].cv_rmse <= (1.0 + options.min_cv_improvement) * tests[best].cv_rmse) {
                    best = static_cast<int>(i);
                    return;
                }
        };
        if (best >= 0 && !tests[best].regime.empty()) {
            const std::string x = tests[best].variable;
            prefer([&x](const CandidateTest& c) {
                return c.variable == x && c.regime.empty() && c.kind != "physical";
            });
        }
        if (best >= 0 && tests[best].kind != "physical")
            prefer([](const CandidateTest& c) { return c.kind == "physical"; });
        if (best >= 0) tests[best].accepted = true;
        out.rounds.push_back(tests);
        if (best < 0) break;

        m.terms.push_back(terms[best]);
        fit = fits[best];
        AddedEffect e;
        e.variable = terms[best].variable;
        e.form = terms[best].form;
        e.kind = terms[best].kind;
        e.regime = terms[best].regime;
        e.f_statistic = tests[best].f_statistic;
        e.p_value = tests[best].p_value;
        e.p_holm = tests[best].p_holm;
        e.candidates_tried = static_cast<int>(tests.size());
        e.cv_rmse_before = cv_now;
        e.cv_rmse_after = tests[best].cv_rmse;
        cv_now = e.cv_rmse_after;
        out.effects.push_back(e);
        done.insert(e.variable);
    }
    return out;
}

// A model fitted to s.rows with its errors (in-sample, cross-validated) and lack of fit.
struct Scored {
    LeastSquaresFit fit;
    ErrorSummary errors;
    std::optional<LackOfFitTest> lack_of_fit;
    std::vector<double> fitted;  // every row of the data (rows outside s.rows: predictions)
};

Scored score(const Setting& s, const Model& m, const std::vector<double>& start) {
    Scored out;
    out.fit = fit_rows(s, m, s.rows, start);
    out.fitted = predictions(s, m, out.fit.params);
    const auto e = errors_of(s, out.fitted);
    out.errors = {e.rmse, cross_validated_rmse(s, m, out.fit.params), e.mape};
    out.lack_of_fit = lack_of_fit(s, m, out.fit.params);
    return out;
}

nlohmann::json errors_json(const ErrorSummary& e) {
    return {{"rmse", e.rmse}, {"cv_rmse", e.cv_rmse}, {"mape", e.mape}};
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json params_json(const std::vector<ParameterEstimate>& ps) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& p : ps) j.push_back({{"name", p.name}, {"value", p.value}, {"std_error", finite_or_null(p.std_error)}});
    return j;
}

nlohmann::json lof_json(const std::optional<LackOfFitTest>& t) {
    if (!t) return nullptr;
    return {{"f_statistic", t->f_statistic}, {"df_lack_of_fit", t->df_lack_of_fit},
            {"df_pure_error", t->df_pure_error}, {"p_value", t->p_value}};
}

}  // namespace

const std::vector<std::string>& diagnose_models() {
    static const std::vector<std::string> names{"beverloo", "johanson", "oldal", "oldal-rect", "failure-line"};
    return names;
}

MeasuredKind data_kind_of(const std::string& model) {
    if (model == "failure-line") return MeasuredKind::shear;
    if (std::find(diagnose_models().begin(), diagnose_models().end(), model) != diagnose_models().end())
        return MeasuredKind::discharge;
    std::string known;
    for (const auto& n : diagnose_models()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("model '" + model + "' unknown; expected one of " + known);
}

std::string to_string(FlowMode mode) {
    switch (mode) {
        case FlowMode::mass: return "mass";
        case FlowMode::mixed: return "mixed";
        case FlowMode::funnel: return "funnel";
    }
    return "?";
}

FlowMode flow_mode_of_angle(double half_angle_deg, double mass_flow_limit_deg) {
    if (half_angle_deg < mass_flow_limit_deg) return FlowMode::mass;
    if (half_angle_deg <= mass_flow_limit_deg + mixed_flow_band_deg) return FlowMode::mixed;
    return FlowMode::funnel;
}

DiagnoseResult diagnose(const MeasuredData& data, const std::string& model_name, const DiagnoseOptions& options) {
    const MeasuredKind kind = data_kind_of(model_name);
    validate_measured(data, kind);
    Setting s{data, {}, 1.0, {}, 0, {}, 0, {}, {}, {}};
    DiagnoseResult result;
    result.model = model_name;
    result.response = kind == MeasuredKind::discharge ? "W_kg_s" : "tau_Pa";
    s.y = data.at(result.response).values;
    const std::size_t n = data.rows();
    s.rows = all_rows(n);
    result.n = static_cast<int>(n);
    result.lines = data.lines;
    result.observed = s.y;
    if (kind == MeasuredKind::shear) {
        const double sd = sd_of(s.y);
        s.scale = sd > 0 ? sd : std::max(1.0, std::abs(mean_of(s.y)));
    }

    // Conditions: rows with equal condition columns are replicates.
    std::map<std::string, int> condition_of;
    s.condition.resize(n);
    for (std::size_t r = 0; r < n; ++r) {
        std::string key;
        for (const auto& c : condition_columns(kind))
            if (const auto* col = data.find(c)) key += cell_key(*col, r) + "|";
        auto [it, added] = condition_of.emplace(key, static_cast<int>(condition_of.size()));
        s.condition[r] = it->second;
    }
    s.n_conditions = static_cast<int>(condition_of.size());
    result.conditions = s.n_conditions;
    s.fold.resize(n);
    if (s.n_conditions >= 3) {
        s.folds = std::min(s.n_conditions, options.max_folds);
        for (std::size_t r = 0; r < n; ++r) s.fold[r] = s.condition[r] % s.folds;
    } else {
        s.folds = static_cast<int>(std::min<std::size_t>(n, options.max_folds));
        for (std::size_t r = 0; r < n; ++r) s.fold[r] = static_cast<int>(r % s.folds);
        result.warnings.push_back("fewer than 3 distinct conditions: cross-validation leaves out single rows, "
                                  "which flatters larger models");
    }
    result.folds = s.folds;

    const Model base = base_model(model_name, data, s);
    s.regimes = regimes_of(data, kind, options, result.flow_mode_rule);
    for (const auto& g : s.regimes)
        if (g.name == "flow_mode")
            for (int l : *g.level) result.flow_mode_of_row.push_back(g.level_names[l]);
    if (result.flow_mode_of_row.empty()) {
        result.flow_mode_rule.clear();
        if (options.wall_friction_deg)
            result.warnings.push_back("friction angles given, but the flow mode is no regime here: it needs conical "
                                      "rows whose angles span more than one mode");
    }
    result.residual_scale = base.relative ? "relative" : "absolute";
    if (n < base.size() + 2)
        throw std::invalid_argument(data.source + ": " + std::to_string(n) + " rows are too few to fit model " +
                                    model_name + " and test its residuals");
    if (model_name == "oldal-rect") {
        std::string outside;
        int count = 0;
        for (std::size_t r = 0; r < n; ++r)
            if (!oldal_rectangular_limit_violations(data.at("b_m").values[r], data.at("c_m").values[r],
                                                    data.at("outlet_m").values[r])
                     .empty()) {
                ++count;
                if (count <= 10) outside += (outside.empty() ? "" : ", ") + std::to_string(data.lines[r]);
            }
        if (count)
            result.warnings.push_back(std::to_string(count) + " rows outside the validity limits of the rectangular "
                                      "Oldal model (1 <= c/b <= 4, 0.15 <= a/c <= 0.7), lines " + outside +
                                      (count > 10 ? ", ..." : ""));
    }

    // Outliers are flagged under the base model, the search runs without them, and the flags are taken again under
    // the model it found (fitted to every row) until they settle: a row that only looked wild next to a missing
    // effect is given back, a row that a wrong effect had absorbed is caught.
    std::vector<std::size_t> flagged = flagged_rows(s, base, fit_base(s, base, result.warnings).params,
                                                    options.outlier_alpha);
    Search search;
    std::vector<double> all_rows_fit;
    for (int pass = 0;; ++pass) {
        s.rows.clear();
        for (std::size_t r = 0; r < n; ++r)
            if (!std::binary_search(flagged.begin(), flagged.end(), r)) s.rows.push_back(r);
        search = search_effects(s, base, options, result.warnings);
        s.rows = all_rows(n);
        all_rows_fit = fit_rows(s, search.model, s.rows, search.fit.params).params;
        auto again = flagged_rows(s, search.model, all_rows_fit, options.outlier_alpha);
        if (again == flagged) break;
        if (pass == 2) {
            std::string excluded;
            for (auto r : flagged) excluded += (excluded.empty() ? "" : ", ") + std::to_string(data.lines[r]);
            result.warnings.push_back("the outlier flags did not settle in 3 passes; the last search excluded lines " +
                                      (excluded.empty() ? std::string("none") : excluded));
            break;
        }
        flagged = std::move(again);
    }
    result.effects = search.effects;
    result.rounds = search.rounds;

    // The outlier report: the final model with every row and without the flagged ones.
    auto& o = result.outliers;
    o.alpha = options.outlier_alpha;
    o.threshold = outlier_threshold(n, search.model.size(), options.outlier_alpha);
    const Scored with_all = score(s, search.model, all_rows_fit);
    o.with_outliers = with_all.errors;
    const auto t_all = studentized_residuals(s, search.model, with_all.fit.params);
    for (auto r : flagged) o.rows.push_back({data.lines[r], s.y[r], with_all.fitted[r], t_all[r]});
    std::vector<std::size_t> kept;
    for (std::size_t r = 0; r < n; ++r)
        if (!std::binary_search(flagged.begin(), flagged.end(), r)) kept.push_back(r);
    o.dropped = options.drop_outliers && !flagged.empty();
    if (!flagged.empty()) {
        s.rows = kept;
        o.without_outliers = score(s, search.model, search.fit.params).errors;
    } else {
        o.without_outliers = o.with_outliers;
    }

    // The reported fits: on every row, or without the flagged rows when asked. The effects' tests and CV come from
    // the search (always without them).
    s.rows = o.dropped ? kept : all_rows(n);
    const bool no_effect = search.model.terms.empty();  // then before and after are one fit
    const Scored before = no_effect && !o.dropped ? with_all : score(s, base, search.base_fit.params);
    const Scored after = no_effect ? before : o.dropped ? score(s, search.model, search.fit.params) : with_all;
    for (double se : before.fit.std_errors)
        if (!std::isfinite(se)) {
            result.warnings.push_back("some parameters of " + model_name +
                                      " are not identifiable from these data (singular covariance)");
            break;
        }
    result.params_before = estimates(base, before.fit);
    result.fitted_before = before.fitted;
    result.before = before.errors;
    result.lack_of_fit_before = before.lack_of_fit;
    result.params_after = estimates(search.model, after.fit);
    result.fitted_after = after.fitted;
    result.after = after.errors;
    result.lack_of_fit_after = after.lack_of_fit;
    // Each effect's parameters as fitted with the others (the reported fit).
    auto p = result.params_after.begin() + static_cast<long>(base.param_names.size());
    for (std::size_t k = 0; k < result.effects.size(); ++k) {
        auto& e = result.effects[k];
        const auto count = static_cast<long>(search.model.terms[k].param_names.size());
        e.params.assign(p, p + count);
        for (auto& q : e.params) q.name = q.name.substr(e.variable.size() + 2);
        p += count;
    }
    // Repeated searches repeat their warnings.
    std::vector<std::string> unique;
    for (auto& w : result.warnings)
        if (std::find(unique.begin(), unique.end(), w) == unique.end()) unique.push_back(std::move(w));
    result.warnings = std::move(unique);
    return result;
}

nlohmann::json DiagnoseResult::to_json() const {
    nlohmann::json j{{"model", model}, {"n", n}, {"before", errors_json(before)}, {"effects", nlohmann::json::array()},
                     {"after", errors_json(after)}};
    for (const auto& e : effects) {
        nlohmann::json params = nlohmann::json::object(), se = nlohmann::json::object();
        for (const auto& p : e.params) {
            params[p.name] = p.value;
            se[p.name] = finite_or_null(p.std_error);
        }
        j["effects"].push_back({{"variable", e.variable},
                                {"form", e.form},
                                {"kind", e.kind},
                                {"regime", e.regime.empty() ? nlohmann::json(nullptr) : nlohmann::json(e.regime)},
                                {"params", params},
                                {"std_errors", se},
                                {"f_statistic", e.f_statistic},
                                {"p_value", e.p_value},
                                {"p_holm", e.p_holm},
                                {"candidates_tried", e.candidates_tried},
                                {"cv_rmse_before", e.cv_rmse_before},
                                {"cv_rmse_after", e.cv_rmse_after}});
    }
    j["response"] = response;
    j["residual_scale"] = residual_scale;
    j["conditions"] = conditions;
    j["cv_folds"] = folds;
    j["params_before"] = params_json(params_before);
    j["params_after"] = params_json(params_after);
    j["lack_of_fit_before"] = lof_json(lack_of_fit_before);
    j["lack_of_fit_after"] = lof_json(lack_of_fit_after);
    nlohmann::json rounds_json = nlohmann::json::array();
    for (const auto& round : rounds) {
        nlohmann::json r = nlohmann::json::array();
        for (const auto& c : round)
            r.push_back({{"variable", c.variable},
                         {"form", c.form},
                         {"kind", c.kind},
                         {"regime", c.regime.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.regime)},
                         {"extra_params", c.extra_params},
                         {"f_statistic", c.f_statistic},
                         {"p_value", c.p_value},
                         {"p_holm", c.p_holm},
                         {"cv_rmse", finite_or_null(c.cv_rmse)},
                         {"accepted", c.accepted}});
        rounds_json.push_back(r);
    }
    j["rounds"] = rounds_json;
    j["flow_mode_rule"] = flow_mode_rule.empty() ? nlohmann::json(nullptr) : nlohmann::json(flow_mode_rule);
    nlohmann::json flagged = nlohmann::json::array();
    for (const auto& o : outliers.rows)
        flagged.push_back({{"line", o.line},
                           {"observed", o.observed},
                           {"fitted", finite_or_null(o.fitted)},
                           {"studentized_residual", finite_or_null(o.studentized)}});
    j["outliers"] = {{"alpha", outliers.alpha},
                     {"threshold", finite_or_null(outliers.threshold)},
                     {"rows", flagged},
                     {"with_outliers", errors_json(outliers.with_outliers)},
                     {"without_outliers", errors_json(outliers.without_outliers)},
                     {"dropped", outliers.dropped}};
    j["warnings"] = warnings;
    nlohmann::json rows = nlohmann::json::array();
    for (std::size_t i = 0; i < observed.size(); ++i)
        rows.push_back({{"line", lines[i]},
                        {"observed", observed[i]},
                        {"fitted_before", finite_or_null(fitted_before[i])},
                        {"fitted_after", finite_or_null(fitted_after[i])}});
    j["rows"] = rows;
    return j;
}

}  // namespace demcal::analytics
