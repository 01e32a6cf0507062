#include "analytics/diagnose.hpp"

#include "analytics/discharge_models.hpp"
#include "analytics/regression.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>

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

struct Setting {
    const MeasuredData& data;
    std::vector<double> y;
    double scale = 1;                // absolute residuals are divided by it (conditioning only)
    std::vector<int> condition;      // condition index of each row
    int n_conditions = 0;
    std::vector<int> fold;           // CV fold of each row
    int folds = 0;
    std::set<std::string> used;      // columns the model's formula uses
};

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

std::vector<std::size_t> all_rows(const Setting& s) {
    std::vector<std::size_t> rows(s.y.size());
    std::iota(rows.begin(), rows.end(), 0);
    return rows;
}

// Fits a model whose last term is new, from the previous parameters and each of the new term's starting points.
LeastSquaresFit fit_extended(const Setting& s, const Model& m, const std::vector<double>& previous) {
    const auto rows = all_rows(s);
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

Errors errors_of(const Setting& s, const std::vector<double>& predicted) {
    double sq = 0, ape = 0;
    int counted = 0;
    for (std::size_t i = 0; i < s.y.size(); ++i) {
        const double w = std::isfinite(predicted[i]) ? predicted[i] : 0.0;
        sq += (s.y[i] - w) * (s.y[i] - w);
        if (s.y[i] != 0) {
            ape += std::abs((s.y[i] - w) / s.y[i]);
            ++counted;
        }
    }
    return {std::sqrt(sq / s.y.size()), counted ? 100.0 * ape / counted : nan};
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
        for (std::size_t i = 0; i < s.y.size(); ++i) (s.fold[i] == f ? test : train).push_back(i);
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
    for (std::size_t i = 0; i < s.y.size(); ++i) {
        const double r = residual(s, m, i, p.data());
        sse += r * r;
        sum[s.condition[i]] += r;
        sum_sq[s.condition[i]] += r * r;
        ++count[s.condition[i]];
    }
    double pure = 0;
    for (int c = 0; c < s.n_conditions; ++c) pure += sum_sq[c] - sum[c] * sum[c] / count[c];
    LackOfFitTest t;
    t.df_pure_error = static_cast<int>(s.y.size()) - s.n_conditions;
    t.df_lack_of_fit = s.n_conditions - static_cast<int>(p.size());
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
                    const double z = (x[r] - x0) / sd;
                    return rel ? w * std::exp(tp[0] * z) : w + scale * tp[0] * z;
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
                const double b = l == 0 ? 0.0 : tp[l - 1];
                return rel ? w * std::exp(b) : w + scale * b;
            };
            t.clear_unseen = [shared_level, levels](const std::vector<std::size_t>& rows, double* tp) {
                std::vector<bool> seen(levels, false);
                for (auto r : rows) seen[(*shared_level)[r]] = true;
                for (int l = 1; l < levels; ++l)
                    if (!seen[l]) tp[l - 1] = 0.0;
            };
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
    if (m.relative && dp && (m.name == "oldal" || m.name == "oldal-rect" || m.name == "johanson") &&
        !done.count("d_p_m")) {
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
            const double z = ((*order)[r] - x0) / sd;
            return rel ? w * std::exp(tp[0] * z) : w + scale * tp[0] * z;
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

DiagnoseResult diagnose(const MeasuredData& data, const std::string& model_name, const DiagnoseOptions& options) {
    const MeasuredKind kind = data_kind_of(model_name);
    validate_measured(data, kind);
    Setting s{data, {}, 1.0, {}, 0, {}, 0, {}};
    DiagnoseResult result;
    result.model = model_name;
    result.response = kind == MeasuredKind::discharge ? "W_kg_s" : "tau_Pa";
    s.y = data.at(result.response).values;
    const std::size_t n = data.rows();
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

    Model m = base_model(model_name, data, s);
    result.residual_scale = m.relative ? "relative" : "absolute";
    if (n < m.size() + 2)
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

    LeastSquaresFit fit = fit_extended(s, m, m.start);
    if (!fit.converged) {
        // GSL also stops at its iteration limit when started at the optimum; only a restart that still improves the
        // sum of squares means the fit had not converged.
        const auto again = fit_rows(s, m, all_rows(s), fit.params);
        if (again.sse < fit.sse * (1 - 1e-8))
            result.warnings.push_back("the fit of " + model_name + " did not converge");
        if (again.sse < fit.sse) fit = again;
    }
    for (double se : fit.std_errors)
        if (!std::isfinite(se)) {
            result.warnings.push_back("some parameters of " + model_name +
                                      " are not identifiable from these data (singular covariance)");
            break;
        }
    result.params_before = estimates(m, fit);
    result.fitted_before = predictions(s, m, fit.params);
    const auto e0 = errors_of(s, result.fitted_before);
    result.before = {e0.rmse, cross_validated_rmse(s, m, fit.params), e0.mape};
    result.lack_of_fit_before = lack_of_fit(s, m, fit.params);

    double cv_now = result.before.cv_rmse;
    std::set<std::string> done;
    for (int round = 0; round < options.max_effects; ++round) {
        auto terms = candidates(s, m, done, result.warnings, round == 0);
        if (terms.empty()) break;
        std::vector<CandidateTest> tests;
        std::vector<LeastSquaresFit> fits;
        for (const auto& t : terms) {
            Model bigger = m;
            bigger.terms.push_back(t);
            CandidateTest c{t.variable, t.form, t.kind, static_cast<int>(t.param_names.size()), 0, 1, 1, nan, false};
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
        // A physical effect from the library is preferred to a generic term that predicts about as well (within
        // min_cv_improvement): it names the mechanism, and the generic one is often its approximation.
        if (best >= 0 && tests[best].kind != "physical")
            for (std::size_t i = 0; i < tests.size(); ++i)
                if (tests[i].kind == "physical" && tests[i].p_holm < options.family_alpha &&
                    tests[i].cv_rmse < (1.0 - options.min_cv_improvement) * cv_now &&
                    tests[i].cv_rmse <= (1.0 + options.min_cv_improvement) * tests[best].cv_rmse)
                    best = static_cast<int>(i);
        if (best >= 0) tests[best].accepted = true;
        result.rounds.push_back(tests);
        if (best < 0) break;

        m.terms.push_back(terms[best]);
        fit = fits[best];
        AddedEffect e;
        e.variable = terms[best].variable;
        e.form = terms[best].form;
        e.kind = terms[best].kind;
        const auto all = estimates(m, fit);
        e.params.assign(all.end() - static_cast<long>(terms[best].param_names.size()), all.end());
        for (auto& p : e.params) p.name = p.name.substr(e.variable.size() + 2);
        e.f_statistic = tests[best].f_statistic;
        e.p_value = tests[best].p_value;
        e.p_holm = tests[best].p_holm;
        e.candidates_tried = static_cast<int>(tests.size());
        e.cv_rmse_before = cv_now;
        e.cv_rmse_after = tests[best].cv_rmse;
        cv_now = e.cv_rmse_after;
        result.effects.push_back(e);
        done.insert(e.variable);
    }

    result.params_after = estimates(m, fit);
    result.fitted_after = predictions(s, m, fit.params);
    const auto e1 = errors_of(s, result.fitted_after);
    result.after = {e1.rmse, cv_now, e1.mape};
    result.lack_of_fit_after = lack_of_fit(s, m, fit.params);
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
                         {"extra_params", c.extra_params},
                         {"f_statistic", c.f_statistic},
                         {"p_value", c.p_value},
                         {"p_holm", c.p_holm},
                         {"cv_rmse", finite_or_null(c.cv_rmse)},
                         {"accepted", c.accepted}});
        rounds_json.push_back(r);
    }
    j["rounds"] = rounds_json;
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
