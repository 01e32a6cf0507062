#include "analytics/diagnose_model.hpp"

#include "analytics/discharge_models.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

namespace demcal::analytics::diagnosis {

namespace {


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

}  // namespace

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

// The regimes the data and options define: the flow mode (conical hoppers whose angles span more than one mode) and
// each categorical column the user names.
std::vector<Regime> regimes_of(const MeasuredData& d, MeasuredKind kind, const DiagnoseOptions& options,
                               std::string& flow_mode_rule) {
    const std::size_t n = d.rows();
    std::vector<Regime> out;
    if (options.effective_friction_deg.has_value() != options.wall_friction_deg.has_value())
        throw std::invalid_argument(
            "flow mode by Jenike's limit needs both friction angles: " +
            (options.wall_friction_deg
                 ? options.names.wall_friction + "=" + short_number(*options.wall_friction_deg) + " given, " +
                       options.names.effective_friction + " missing"
                 : options.names.effective_friction + "=" + short_number(*options.effective_friction_deg) +
                       " given, " + options.names.wall_friction + " missing"));
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
        const std::string& field = options.names.regime_column;
        const auto* col = d.find(name);
        if (!col) {
            std::string known;
            for (const auto& c : d.columns) known += (known.empty() ? "" : ", ") + c.name;
            throw std::invalid_argument(field + " '" + name + "' is not in " + d.source + " (columns: " + known + ")");
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
            throw std::invalid_argument(
                field + " '" + name + "' has " +
                (g.level_names.empty() ? "no value" : "a single value '" + g.level_names[0] + "'") +
                ": no regimes to compare");
        if (g.level_names.size() > n / 3)
            throw std::invalid_argument(field + " '" + name + "' has " + std::to_string(g.level_names.size()) +
                                        " values for " + std::to_string(n) +
                                        " rows: too many for a slope per value (at most a third of the rows)");
        g.level = std::make_shared<const std::vector<int>>(std::move(level));
        out.push_back(std::move(g));
    }
    return out;
}

}  // namespace demcal::analytics::diagnosis
