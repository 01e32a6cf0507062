#include "analytics/dem_diagnosis.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>
#include <gsl/gsl_multifit.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

namespace demcal::analytics {

std::string to_string(ParameterScale scale) { return scale == ParameterScale::log ? "log" : "linear"; }

const std::vector<DemEffectCandidate>& dem_effect_candidates() {
    static const std::vector<DemEffectCandidate> table{
        {"rolling_friction",
         {"grain_grain.rolling_friction", "grain_wall.rolling_friction"},
         1e-3,
         0.3,
         ParameterScale::log,
         "rolling resistance of the grain (its shape's departure from the clump's spheres): a property of the grain, so "
         "grain-grain and grain-wall together; the rates alone cannot tell the two apart (one parameter per candidate)",
         std::nullopt},
        {"wall_friction",
         {"grain_wall.friction"},
         0.05,
         0.9,
         ParameterScale::linear,
         "particle-wall sliding friction (wall material, roughness, wear): it sets whether the hopper flows in mass "
         "flow, so it acts most at steep hoppers",
         std::nullopt},
        // from 0.3: at 0.1 the reduced silo at 10 deg nearly jammed (1042 of its grains out after 4.5 s instead of
        // all in under 1 s), a run of many minutes for a grain no wheat is
        {"restitution",
         {"grain_grain.restitution"},
         0.3,
         0.95,
         ParameterScale::linear,
         "grain-grain restitution (energy lost in collisions; grain-grain contacts dominate the flowing bed, the "
         "grain-wall one keeps its declared value)",
         std::nullopt},
        // JKR pull-off 1.5 pi gamma R*, whatever the stiffness: at 0.3 J/m^2 and R* 0.75 mm (two 1.5 mm members)
        // 1.06 mN, three times a wheat grain's weight per contact, which arches the 105 mm silo's bed above 10 deg
        // (examples/cohesive_arch, at a hundredth of the stiffness); 0 is the cohesionless law, the default
        {"cohesion",
         {"grain_grain.surface_energy_J_m2"},
         0.0,
         0.3,
         ParameterScale::linear,
         "grain-grain cohesion (moisture, fines, fat: JKR surface energy), which slows and finally arches the flow; the "
         "grain-wall adhesion keeps its declared value",
         0.0},
        // the grain family of kernel/silo/wheat.hpp at the seed's volume: 1.2 is nearly a sphere, 2.5 a long grain
        // (wheat kernels measure about 1.6-2.3); 11/6 is the seed's clump, what a material without the field has
        {"grain_elongation",
         {"grain.aspect_ratio"},
         1.2,
         2.5,
         ParameterScale::linear,
         "grain shape: the length / width of the 3-sphere grain at the declared volume (variety, a clump built from "
         "another grain's photographs); an elongated grain interlocks and aligns, a rounder one rolls",
         11.0 / 6.0},
    };
    return table;
}

std::vector<std::string> candidate_table_defects(const std::vector<DemEffectCandidate>& table) {
    std::vector<std::string> defects;
    std::set<std::string> names, fields;
    for (const auto& c : table) {
        const std::string who = "candidate '" + c.name + "'";
        if (c.name.empty() || c.name.find_first_of(" \t,") != std::string::npos)
            defects.push_back(who + ": a name must be one word");
        if (!names.insert(c.name).second) defects.push_back(who + ": name used twice");
        if (c.fields.empty()) defects.push_back(who + ": no material field");
        for (const auto& f : c.fields) {
            const auto dot = f.find('.');
            if (dot == std::string::npos || dot == 0 || dot + 1 == f.size() || f.find('.', dot + 1) != std::string::npos)
                defects.push_back(who + ": field '" + f + "' is not object.key");
            if (!fields.insert(f).second) defects.push_back(who + ": field '" + f + "' belongs to two candidates");
        }
        if (!(std::isfinite(c.lower) && std::isfinite(c.upper) && c.lower < c.upper))
            defects.push_back(who + ": bounds must be finite with lower < upper");
        if (c.scale == ParameterScale::log && !(c.lower > 0)) defects.push_back(who + ": log scale needs lower > 0");
        if (c.absent && !(*c.absent >= c.lower && *c.absent <= c.upper))
            defects.push_back(who + ": the absent value must lie within the bounds (it is the declared value then)");
    }
    return defects;
}

namespace {

double to_search(double v, ParameterScale s) { return s == ParameterScale::log ? std::log(v) : v; }
double from_search(double t, ParameterScale s) { return s == ParameterScale::log ? std::exp(t) : t; }

std::string invalid_cell(const MeasuredData& d, std::size_t row, const std::string& column, const std::string& why) {
    return d.where(row, column) + ": value '" + shortened_text(d.at(column).text[row]) + "' " + why;
}

// Two conditions whose values agree to 0.01 % but not exactly (theta 30 and 30.0000001) are one silo written two ways
// (a rounding in a spreadsheet): taken as two, each got its own runs and the leave-one-out held one half of a
// condition out. No experiment sets an angle or a size to 0.01 %: refused, both lines named, not merged silently.
constexpr double kConditionResolution = 1e-4;
void check_apart_from_others(const MeasuredData& d, std::size_t row, const SiloCondition& c,
                             const SiloMeasurements& m) {
    auto near = [](double a, double b) {
        return (std::isnan(a) && std::isnan(b)) || std::fabs(a - b) <= kConditionResolution * std::max(std::fabs(a), std::fabs(b));
    };
    for (std::size_t k = 0; k < m.conditions.size(); ++k) {
        const SiloCondition& o = m.conditions[k];
        if (!(near(c.theta_deg, o.theta_deg) && near(c.outlet_m, o.outlet_m) && near(c.diameter_m, o.diameter_m) &&
              near(c.body_height_m, o.body_height_m)))
            continue;
        std::size_t first = 0;
        while (m.condition_of_row[first] != k) ++first;
        throw std::invalid_argument(d.where(row, "theta_deg") + ": the condition " + c.label() + " differs from " +
                                    o.label() + " (line " + std::to_string(m.lines[first]) + ") by less than " +
                                    number_text(100 * kConditionResolution) +
                                    " %: one silo written two ways? Write its values alike (repeats of one condition "
                                    "are rows with the same values)");
    }
}

}  // namespace

std::vector<double> candidate_grid(const DemEffectCandidate& c, int points) {
    std::vector<double> values;
    const double a = to_search(c.lower, c.scale), b = to_search(c.upper, c.scale);
    for (int k = 0; k < points; ++k)
        values.push_back(run_value(from_search(points == 1 ? 0.5 * (a + b) : a + (b - a) * k / (points - 1), c.scale)));
    return values;
}

double run_value(double value) {
    // through its 4-digit text, so that the value is the double nearest to what a report prints (0.1235, not
    // 0.12350000000000001)
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return std::strtod(text, nullptr);
}

// --- measured data ------------------------------------------------------------------------------------------------

std::string SiloCondition::label() const {
    std::string s = "theta" + number_text(theta_deg, 10);
    if (std::isfinite(outlet_m)) s += "_outlet" + number_text(outlet_m, 10);
    if (std::isfinite(diameter_m)) s += "_D" + number_text(diameter_m, 10);
    if (std::isfinite(body_height_m)) s += "_H" + number_text(body_height_m, 10);
    return s;
}

bool SiloCondition::operator==(const SiloCondition& o) const {
    auto same = [](double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; };
    return same(theta_deg, o.theta_deg) && same(outlet_m, o.outlet_m) && same(diameter_m, o.diameter_m) &&
           same(body_height_m, o.body_height_m);
}

const std::vector<std::string>& silo_measurement_columns() {
    static const std::vector<std::string> columns{"theta_deg", "rate_g_s", "outlet_m", "D_m", "body_height_m",
                                                  "replicate"};
    return columns;
}

SiloMeasurements silo_measurements_from(const MeasuredData& d) {
    const auto& known = silo_measurement_columns();
    std::string known_list;
    for (const auto& k : known) known_list += (known_list.empty() ? "" : ", ") + k;
    for (const auto& c : d.columns)
        if (std::find(known.begin(), known.end(), c.name) == known.end())
            throw std::invalid_argument(d.source + ": line 1, column " + shortened_text(c.name) +
                                        ": unknown column for the silo-dem model (known: " + known_list + ")");
    for (const char* required : {"theta_deg", "rate_g_s"})
        if (!d.find(required))
            throw std::invalid_argument(d.source + ": line 1: column " + required + " is missing (silo-dem needs " +
                                        "theta_deg and rate_g_s)");
    if (d.rows() == 0) throw std::invalid_argument(d.source + ": no data rows");
    // every cell a usable number (parse_csv applied the number rule to the cells that read as numbers)
    for (const auto& c : d.columns)
        for (std::size_t r = 0; r < d.rows(); ++r) {
            const TypedNumber n = read_typed_number(c.text[r]);
            if (c.text[r].empty()) throw std::invalid_argument(d.where(r, c.name) + ": empty cell");
            if (!n.is_number) throw std::invalid_argument(invalid_cell(d, r, c.name, "is not a number"));
            if (n.defect) throw std::invalid_argument(invalid_cell(d, r, c.name, *n.defect));
        }
    SiloMeasurements m;
    m.source = d.source;
    auto value = [&](const char* column, std::size_t r) {
        const DataColumn* c = d.find(column);
        return c ? read_typed_number(c->text[r]).value : NAN;
    };
    for (std::size_t r = 0; r < d.rows(); ++r) {
        SiloCondition c{value("theta_deg", r), value("outlet_m", r), value("D_m", r), value("body_height_m", r)};
        if (!(c.theta_deg > 0 && c.theta_deg < 90))
            throw std::invalid_argument(invalid_cell(d, r, "theta_deg", "must be in (0, 90) deg (a conical hopper)"));
        for (const char* size : {"outlet_m", "D_m", "body_height_m"})
            if (d.find(size) && !(value(size, r) > 0))
                throw std::invalid_argument(invalid_cell(d, r, size, "must be > 0 m"));
        const double rate = value("rate_g_s", r);
        if (!(rate > 0)) throw std::invalid_argument(invalid_cell(d, r, "rate_g_s", "must be > 0 g/s"));
        auto it = std::find(m.conditions.begin(), m.conditions.end(), c);
        if (it == m.conditions.end()) {
            check_apart_from_others(d, r, c, m);
            it = m.conditions.insert(m.conditions.end(), c);
        }
        m.condition_of_row.push_back(std::size_t(it - m.conditions.begin()));
        m.rate_g_s.push_back(rate);
        m.lines.push_back(d.lines[r]);
    }
    return m;
}

SiloMeasurements read_silo_measurements(const std::string& path) {
    std::istringstream in(read_input_file(path, "data file " + shortened_text(path, 200), kMaxMeasuredDataBytes));
    return silo_measurements_from(parse_csv(in, path));
}

// --- the diagnosis --------------------------------------------------------------------------------------------------

namespace {

// Measured log rates by condition: means, counts, pooled within-condition variance.
struct ConditionStats {
    std::vector<double> log_rate;        // per row
    std::vector<double> mean;            // per condition
    std::vector<int> count;              // per condition
    double pure_error_ss = 0;
    int df_pure_error = 0;
    double s2 = NAN;
};

ConditionStats condition_stats(const SiloMeasurements& d) {
    ConditionStats s;
    const std::size_t C = d.conditions.size();
    s.mean.assign(C, 0);
    s.count.assign(C, 0);
    for (std::size_t i = 0; i < d.rows(); ++i) {
        s.log_rate.push_back(std::log(d.rate_g_s[i]));
        s.mean[d.condition_of_row[i]] += s.log_rate.back();
        ++s.count[d.condition_of_row[i]];
    }
    for (std::size_t c = 0; c < C; ++c) s.mean[c] /= s.count[c];
    for (std::size_t i = 0; i < d.rows(); ++i) {
        const double e = s.log_rate[i] - s.mean[d.condition_of_row[i]];
        s.pure_error_ss += e * e;
    }
    s.df_pure_error = int(d.rows()) - int(C);
    s.s2 = s.df_pure_error > 0 ? s.pure_error_ss / s.df_pure_error : NAN;
    return s;
}

// Row SSE and RMSE of log residuals for predicted log rates per condition.
double row_sse(const SiloMeasurements& d, const ConditionStats& s, const std::vector<double>& log_pred) {
    double sse = 0;
    for (std::size_t i = 0; i < d.rows(); ++i) {
        const double e = s.log_rate[i] - log_pred[d.condition_of_row[i]];
        sse += e * e;
    }
    return sse;
}

double chi2_of(const ConditionStats& s, const std::vector<double>& log_pred, int K) {
    double chi2 = 0;
    for (std::size_t c = 0; c < s.mean.size(); ++c) {
        const double var = s.s2 * (1.0 / s.count[c] + 1.0 / K);
        chi2 += (s.mean[c] - log_pred[c]) * (s.mean[c] - log_pred[c]) / var;
    }
    return chi2;
}

std::vector<double> logs(const std::vector<double>& rates) {
    std::vector<double> l;
    for (double r : rates) l.push_back(std::log(r));
    return l;
}

double rmse_g_s(const SiloMeasurements& d, const std::vector<double>& rates) {
    double ss = 0;
    for (std::size_t i = 0; i < d.rows(); ++i) ss += std::pow(d.rate_g_s[i] - rates[d.condition_of_row[i]], 2);
    return std::sqrt(ss / double(d.rows()));
}

// The kernel's log rate per condition as a polynomial in the parameter's search scale, mapped to [-1, 1] over the
// bounds: the seed scatter of single runs averaged out, so that neither the fit nor the CV chases it.
class Surrogate {
public:
    Surrogate(const DemEffectCandidate& spec, const std::map<double, std::vector<double>>& runs) : spec_(spec) {
        const std::size_t npts = runs.size();
        degree_ = int(std::clamp<std::size_t>((npts - 1) / 2, 1, 3));
        const std::size_t p = std::size_t(degree_) + 1;
        const std::size_t C = runs.begin()->second.size();
        gsl_matrix* X = gsl_matrix_alloc(npts, p);
        gsl_vector* y = gsl_vector_alloc(npts);
        gsl_vector* beta = gsl_vector_alloc(p);
        gsl_matrix* cov = gsl_matrix_alloc(p, p);
        gsl_multifit_linear_workspace* w = gsl_multifit_linear_alloc(npts, p);
        std::size_t row = 0;
        for (const auto& [value, rates] : runs) {
            double power = 1;
            for (std::size_t k = 0; k < p; ++k, power *= unit(value)) gsl_matrix_set(X, row, k, power);
            ++row;
        }
        coefficients_.assign(C, std::vector<double>(p, 0));
        for (std::size_t c = 0; c < C; ++c) {
            row = 0;
            for (const auto& [value, rates] : runs) gsl_vector_set(y, row++, std::log(rates[c]));
            double chisq = 0;
            gsl_multifit_linear(X, y, beta, cov, &chisq, w);
            for (std::size_t k = 0; k < p; ++k) coefficients_[c][k] = gsl_vector_get(beta, k);
        }
        gsl_multifit_linear_free(w);
        gsl_matrix_free(cov);
        gsl_vector_free(beta);
        gsl_vector_free(y);
        gsl_matrix_free(X);
    }

    double unit(double value) const {
        const double a = to_search(spec_.lower, spec_.scale), b = to_search(spec_.upper, spec_.scale);
        return 2 * (to_search(value, spec_.scale) - a) / (b - a) - 1;
    }
    double value_of_unit(double u) const {
        const double a = to_search(spec_.lower, spec_.scale), b = to_search(spec_.upper, spec_.scale);
        return from_search(a + (u + 1) / 2 * (b - a), spec_.scale);
    }
    // log rate of every condition at unit position u
    std::vector<double> at_unit(double u) const {
        std::vector<double> l;
        for (const auto& beta : coefficients_) {
            double v = 0, power = 1;
            for (double b : beta) v += b * power, power *= u;
            l.push_back(v);
        }
        return l;
    }
    int degree() const { return degree_; }

private:
    DemEffectCandidate spec_;
    int degree_ = 1;
    std::vector<std::vector<double>> coefficients_;
};

struct MinimiseData {
    const std::function<double(double)>* f;
};
double call_objective(double u, void* p) { return (*static_cast<MinimiseData*>(p)->f)(u); }

// Minimum of f over [-1, 1]: a scan of 201 points, then GSL's Brent minimiser in the best point's bracket.
double minimise_on_unit(const std::function<double(double)>& f) {
    constexpr int n = 201;
    int best = 0;
    double best_f = INFINITY;
    for (int k = 0; k < n; ++k)
        if (const double v = f(-1 + 2.0 * k / (n - 1)); v < best_f) best_f = v, best = k;
    if (best == 0 || best == n - 1) return -1 + 2.0 * best / (n - 1);
    const double lo = -1 + 2.0 * (best - 1) / (n - 1), hi = -1 + 2.0 * (best + 1) / (n - 1),
                 mid = -1 + 2.0 * best / (n - 1);
    if (!(f(mid) < f(lo) && f(mid) < f(hi))) return mid;  // flat: the scan's point is as good as any
    MinimiseData data{&f};
    gsl_function F{&call_objective, &data};
    gsl_min_fminimizer* m = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    gsl_error_handler_t* old = gsl_set_error_handler_off();
    double x = mid;
    if (gsl_min_fminimizer_set(m, &F, mid, lo, hi) == GSL_SUCCESS) {
        for (int it = 0; it < 60; ++it) {
            if (gsl_min_fminimizer_iterate(m) != GSL_SUCCESS) break;
            x = gsl_min_fminimizer_x_minimum(m);
            if (gsl_min_test_interval(gsl_min_fminimizer_x_lower(m), gsl_min_fminimizer_x_upper(m), 1e-6, 0) ==
                GSL_SUCCESS)
                break;
        }
    }
    gsl_set_error_handler(old);
    gsl_min_fminimizer_free(m);
    return x;
}

std::vector<double> holm(const std::vector<double>& p) {
    std::vector<std::size_t> order(p.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](auto a, auto b) { return p[a] < p[b]; });
    std::vector<double> adjusted(p.size());
    double running = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
        running = std::max(running, std::min(1.0, double(order.size() - k) * p[order[k]]));
        adjusted[order[k]] = running;
    }
    return adjusted;
}

// The p quantile of F(1, nu), as the square of Student's t quantile at (1 + p) / 2 (T^2 ~ F(1, nu)). GSL's F
// quantile at (0.95, 1, nu) fails to converge for most nu above 270 (betainv.c: "inverse failed to converge"), which
// GSL's default handler turns into an abort: diagnose silo-dem crashed when a rival's separation design needed many
// repeats. The t quantile has no such failure.
double f1_quantile(double p, double nu) {
    const double t = gsl_cdf_tdist_Pinv(0.5 + p / 2, nu);
    return t * t;
}

constexpr int kMaxSeparationMultiplier = 1000;  // beyond: not a design anyone would run

DemRivalSeparation rival_separation(const ConditionStats& s, int K, const DemCandidateResult& effect,
                                    const DemCandidateResult& rival, int rival_index, double level) {
    DemRivalSeparation sep;
    sep.rival = rival_index;
    sep.needed_chi2_difference = f1_quantile(level, double(s.df_pure_error));
    std::vector<double> part;
    for (std::size_t c = 0; c < s.mean.size(); ++c) {
        const double var = s.s2 * (1.0 / s.count[c] + 1.0 / K);
        const double d = effect.log_curve_fitted[c] - rival.log_curve_fitted[c];
        const double miss_e = s.mean[c] - effect.log_curve_fitted[c], miss_r = s.mean[c] - rival.log_curve_fitted[c];
        const double observed = (miss_r * miss_r - miss_e * miss_e) / var;
        part.push_back(d * d / var);
        sep.expected_chi2_difference += part.back();
        sep.observed_chi2_difference += observed;
        sep.repeats_only_limit += observed * (1.0 + double(K) / s.count[c]);  // var -> s^2 / K
    }
    if (sep.observed_chi2_difference > 0) {
        // m times the repeats also gives the pure error m N - C degrees of freedom, which lowers the threshold
        const int rows = std::accumulate(s.count.begin(), s.count.end(), 0), conditions = int(s.count.size());
        for (int m = 1; m <= kMaxSeparationMultiplier; ++m)
            if (m * sep.observed_chi2_difference >= f1_quantile(level, double(m * rows - conditions))) {
                sep.multiplier = m;
                break;
            }
    }
    if (sep.expected_chi2_difference > 0) {
        for (std::size_t c = 0; c < part.size(); ++c) sep.conditions.push_back(int(c));
        std::stable_sort(sep.conditions.begin(), sep.conditions.end(), [&](int a, int b) { return part[a] > part[b]; });
        for (int c : sep.conditions) sep.shares.push_back(part[std::size_t(c)] / sep.expected_chi2_difference);
    }
    return sep;
}

// The separation in words: how many repeats and seeds, where the two differ most.
std::string separation_advice(const DemRivalSeparation& sep, const SiloMeasurements& data, const ConditionStats& s,
                              int K, const std::string& effect) {
    if (!(sep.expected_chi2_difference > 1e-12 * sep.needed_chi2_difference))
        return "their predictions coincide at every condition measured: no number of repeats separates them here; "
               "other conditions or another measured quantity can";
    const int repeats = *std::min_element(s.count.begin(), s.count.end());
    std::string where;
    for (std::size_t j = 0; j < sep.conditions.size() && j < 2; ++j)
        where += (j ? ", " : "") + data.conditions[std::size_t(sep.conditions[j])].label() + " (" +
                 number_text(100 * sep.shares[j], 2) + " %)";
    std::string text = "the chi2 difference is " + number_text(sep.observed_chi2_difference, 3) + " against the " +
                       number_text(sep.needed_chi2_difference, 3) + " needed; ";
    if (!std::isfinite(sep.multiplier)) {
        text += sep.observed_chi2_difference > 0 ? "more than 1000 times the repeats would be needed"
                                                 : "these rates do not favour " + effect + " over it at all";
    } else {
        text += "if it grows in proportion, " + number_text(sep.multiplier, 4) + " times the repeats (" +
                std::to_string(repeats) + " -> " + number_text(repeats * sep.multiplier, 4) +
                " per condition) and the prediction seeds (--seeds " + std::to_string(K) + " -> " +
                number_text(K * sep.multiplier, 4) + ") would separate them";
        if (sep.repeats_only_limit < sep.needed_chi2_difference)
            text += " (more repeats alone reach at most " + number_text(sep.repeats_only_limit, 3) +
                    ": the predictions' own seed noise stays)";
    }
    text += "; their predictions differ most at " + where;
    // T-optimal view: were the effect exactly right, the data would sit on its curve, at this distance from the rival's
    if (sep.expected_chi2_difference >= sep.needed_chi2_difference &&
        sep.observed_chi2_difference < sep.needed_chi2_difference)
        text += "; were " + effect + " exactly right, these repeats would already show about " +
                number_text(sep.expected_chi2_difference, 3) + ": the rates lie between the two predictions";
    return text;
}

// The statistics of the conditions, once the data are known to be diagnosable: 3 conditions at least (the
// cross-validation leaves one out and refits one parameter), repeats (the noise scale is their scatter), and a
// declared material that discharges wherever the data have a rate.
ConditionStats checked_condition_stats(const SiloMeasurements& data) {
    const std::size_t C = data.conditions.size();
    if (C < 3)
        throw std::invalid_argument(data.source + ": " + std::to_string(C) +
                                    " distinct condition(s); the cross-validation leaves one out and refits one "
                                    "parameter: give at least 3");
    ConditionStats s = condition_stats(data);
    if (s.df_pure_error < 1 || !(s.s2 > 0))
        throw std::invalid_argument(data.source + ": no repeats (rows of one condition with different rates): the noise "
                                    "scale is the measured repeat scatter; give repeats of at least one condition");
    return s;
}

ConditionStats diagnosable_stats(const SiloMeasurements& data, const std::vector<double>& rates_declared) {
    const std::size_t C = data.conditions.size();
    ConditionStats s = checked_condition_stats(data);
    if (rates_declared.size() != C) throw std::logic_error("diagnose_dem: one declared rate per condition");
    for (std::size_t k = 0; k < rates_declared.size(); ++k)
        if (!(rates_declared[k] > 0))
            throw std::invalid_argument("the declared material does not discharge at " + data.conditions[k].label() +
                                        " (no steady rate: an arch or a jam), where the data have a rate");
    return s;
}

// A candidate's runs: each value run once through its predictor, the rates of the values at which every condition
// flows, and (in the candidate's record) the values run, their SSE, and those that stopped the flow.
class CandidateRuns {
public:
    CandidateRuns(DemCandidateResult& c, const DemCandidateSetup& setup, const SiloMeasurements& data,
                  const ConditionStats& s, const std::vector<double>& rates_declared)
        : c_(c), setup_(setup), data_(data), s_(s), rates_{{c.declared, rates_declared}} {}

    // Runs the values not run before (nor known to stop the flow), in one call of the predictor.
    void run(const std::vector<double>& values) {
        std::vector<double> fresh;
        for (double v : values)
            if (!rates_.count(v) && !stops(v) && std::find(fresh.begin(), fresh.end(), v) == fresh.end())
                fresh.push_back(v);
        if (fresh.empty()) return;
        const auto rates = setup_.predict(fresh);
        for (std::size_t k = 0; k < fresh.size(); ++k) {
            c_.evaluated.push_back(fresh[k]);
            const auto& r_k = rates.at(k);
            if (std::any_of(r_k.begin(), r_k.end(), [](double x) { return !(x > 0); })) {
                c_.stops_flow.push_back(fresh[k]);
                c_.sse_of_runs.push_back(NAN);
                continue;
            }
            rates_[fresh[k]] = r_k;
            c_.sse_of_runs.push_back(row_sse(data_, s_, logs(r_k)));
        }
    }
    bool flows_at(double v) const { return rates_.count(v) > 0; }
    const std::vector<double>& rates_at(double v) const { return rates_.at(v); }
    // value -> rates per condition, of the values that flow (ascending)
    std::map<double, std::vector<double>>& flowing() { return rates_; }

private:
    bool stops(double v) const { return std::find(c_.stops_flow.begin(), c_.stops_flow.end(), v) != c_.stops_flow.end(); }
    DemCandidateResult& c_;
    const DemCandidateSetup& setup_;
    const SiloMeasurements& data_;
    const ConditionStats& s_;
    std::map<double, std::vector<double>> rates_;
};

// Where some values stopped the flow: the search is confined to the flowing side of the declared value (up to the last
// flowing value before the nearest stop), after filling in a grid too coarse to leave 3 flowing values there. Returns
// false, with the reason in c.unavailable, when fewer than 3 remain; else narrows c.spec's bounds to them.
bool confine_to_flowing_side(DemCandidateResult& c, CandidateRuns& runs) {
    if (c.stops_flow.empty()) return true;
    double upper = c.spec.upper, lower = c.spec.lower;
    auto find_stops = [&] {
        for (double v : c.stops_flow) {
            if (v > c.declared) upper = std::min(upper, v);
            if (v < c.declared) lower = std::max(lower, v);
        }
    };
    auto beyond_a_stop = [&](double v) {
        return (v >= upper && upper < c.spec.upper) || (v <= lower && lower > c.spec.lower);
    };
    find_stops();
    // Fewer than 3 flowing values (a coarse grid whose first step past the declared value already stops the flow):
    // the gaps between them and toward each stop are halved, a few rounds, before the candidate is given up (at 2000
    // grains the cohesion grid 0, 0.1, 0.2, 0.3 J/m^2 stopped from 0.2 and was not tried).
    constexpr int kFillRounds = 3;
    for (int round = 0; round < kFillRounds; ++round) {
        std::vector<double> edges;  // the flowing values and the stops around them, ascending
        if (lower > c.spec.lower) edges.push_back(lower);
        for (const auto& [v, rates] : runs.flowing())
            if (!beyond_a_stop(v)) edges.push_back(v);
        const std::size_t flowing = edges.size() - (lower > c.spec.lower ? 1 : 0);
        if (flowing >= 3) break;
        if (upper < c.spec.upper) edges.push_back(upper);
        std::vector<double> halves;
        for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
            const double a = edges[k], b = edges[k + 1];
            const bool geometric = c.spec.scale == ParameterScale::log && a > 0 && b > 0;
            halves.push_back(run_value(geometric ? std::sqrt(a * b) : 0.5 * (a + b)));
        }
        runs.run(halves);
        find_stops();
    }
    auto& kept = runs.flowing();
    for (auto it = kept.begin(); it != kept.end();) it = beyond_a_stop(it->first) ? kept.erase(it) : std::next(it);
    if (kept.size() < 3) {
        c.available = false;
        c.unavailable = "the flow stops at " + number_text(upper < c.spec.upper ? upper : lower) +
                        ", leaving fewer than 3 flowing values to fit";
        return false;
    }
    c.spec.lower = kept.begin()->first;
    c.spec.upper = kept.rbegin()->first;
    return true;
}

// The SSE of the condition means about a surrogate's curve as a function of the unit coordinate, all conditions or
// all but `without` (the cross-validation's refit).
std::function<double(double)> sse_on(const Surrogate& g, const ConditionStats& s, std::optional<std::size_t> without) {
    return [&g, &s, without](double u) {
        const auto l = g.at_unit(u);
        double sse = 0;
        for (std::size_t k = 0; k < s.mean.size(); ++k)
            if (!without || *without != k) sse += s.count[k] * (s.mean[k] - l[k]) * (s.mean[k] - l[k]);
        return sse;
    };
}

// The surrogate's minimum run and the surrogate refitted, until its minimum is a value already run (or stops the
// flow: not monotone), at most `steps` times.
void refine_on_surrogate(const DemCandidateResult& c, CandidateRuns& runs, const ConditionStats& s, int steps) {
    for (int step = 0; step < steps; ++step) {
        const Surrogate g(c.spec, runs.flowing());
        const double proposal = run_value(g.value_of_unit(minimise_on_unit(sse_on(g, s, std::nullopt))));
        if (runs.flows_at(proposal)) break;  // the surrogate's minimum has been run: converged
        runs.run({proposal});
        if (!runs.flows_at(proposal)) break;  // it stopped the flow (the flow is not monotone in the parameter)
    }
}

// The interval of the fitted value: the connected range around the fit where chi2 stays within delta_chi2 of its
// minimum, scanned on the surrogate.
void fill_interval(DemCandidateResult& c, const Surrogate& g, const ConditionStats& s, int K, double u_fit,
                   double delta_chi2) {
    constexpr int n_scan = 801;
    auto chi2_u = [&](double u) { return chi2_of(s, g.at_unit(u), K); };
    const double chi2_min = std::min(c.chi2_fitted, chi2_u(u_fit));
    const double step = 2.0 / (n_scan - 1);
    double lo = u_fit, hi = u_fit;
    while (lo - step >= -1 && chi2_u(lo - step) <= chi2_min + delta_chi2) lo -= step;
    while (hi + step <= 1 && chi2_u(hi + step) <= chi2_min + delta_chi2) hi += step;
    c.interval_at_lower_bound = lo - step < -1;
    c.interval_at_upper_bound = hi + step > 1;
    c.interval_low = g.value_of_unit(lo);
    c.interval_high = g.value_of_unit(hi);
}

// Leave one condition out: refit on the others' surrogate SSE, predict the one left out; the CV RMSE and whether it
// gains enough on the declared model's.
void fill_cross_validation(DemCandidateResult& c, const Surrogate& g, const SiloMeasurements& data,
                           const ConditionStats& s, double min_cv_gain) {
    double cv_ss = 0;
    for (std::size_t k = 0; k < data.conditions.size(); ++k) {
        const double u_k = minimise_on_unit(sse_on(g, s, k));
        c.fitted_without.push_back(g.value_of_unit(u_k));
        const double l = g.at_unit(u_k)[k];
        for (std::size_t i = 0; i < data.rows(); ++i)
            if (data.condition_of_row[i] == k) cv_ss += (s.log_rate[i] - l) * (s.log_rate[i] - l);
    }
    c.cv_rmse = std::sqrt(cv_ss / double(data.rows()));
    c.cv_gain = c.cv_rmse <= (1 - min_cv_gain) * c.cv_rmse_declared;
}

// One candidate searched, fitted and scored against the declared model: its grid (confined to where the bed flows),
// the surrogate's refinement, the fit run for real, the F test, the interval and the cross-validation. Returns false
// (c.unavailable says why) when it cannot be fitted.
bool assess_candidate(DemCandidateResult& c, const DemCandidateSetup& setup, const SiloMeasurements& data,
                      const ConditionStats& s, const DemDiagnosis& r, const DemDiagnoseOptions& o, double delta_chi2) {
    c.declared = *setup.declared;
    CandidateRuns runs(c, setup, data, s, r.rates_declared);
    runs.run(candidate_grid(c.spec, o.grid_points));
    if (!confine_to_flowing_side(c, runs)) return false;
    refine_on_surrogate(c, runs, s, o.refine_steps);
    const Surrogate g(c.spec, runs.flowing());
    const double u_fit = minimise_on_unit(sse_on(g, s, std::nullopt));
    c.fitted = run_value(g.value_of_unit(u_fit));
    runs.run({c.fitted});
    if (!runs.flows_at(c.fitted)) {
        c.available = false;
        c.unavailable = "the fitted value " + number_text(c.fitted) + " stops the flow in a condition";
        return false;
    }
    const int K = r.prediction_seeds;
    c.rates_fitted = runs.rates_at(c.fitted);
    c.rmse_fitted = std::sqrt(row_sse(data, s, logs(c.rates_fitted)) / r.n);
    const double u_declared = std::clamp(g.unit(c.declared), -1.0, 1.0);
    const auto l_declared = g.at_unit(u_declared), l_fit = g.at_unit(u_fit);
    // The declared model is measured twice: its own runs, and the smoothed curve at the declared value. Where the
    // curve misses those runs (a response it cannot follow: nearly flat, then a steep fall toward arching), the gain
    // from the declared value to the fit would be partly the curve's own error; so the declared model is taken as the
    // better of the two (seen: a clean two-outlet set got cohesion "named" with its CV RMSE up from 2.96 to 3.88 %,
    // 2026-12-02).
    c.rmse_declared = c.cv_rmse_declared = std::min(std::sqrt(row_sse(data, s, l_declared) / r.n), r.rmse_before);
    c.chi2_declared = std::min(chi2_of(s, l_declared, K), r.chi2_before);
    c.chi2_fitted = chi2_of(s, l_fit, K);
    c.log_curve_fitted = l_fit;
    c.f_statistic = std::max(0.0, c.chi2_declared - c.chi2_fitted);
    c.p_value = gsl_cdf_fdist_Q(c.f_statistic, 1.0, double(s.df_pure_error));
    fill_interval(c, g, s, K, u_fit, delta_chi2);
    fill_cross_validation(c, g, data, s, o.min_cv_gain);
    return true;
}

// Holm's correction over the tested candidates, and the effect named: the significant one with a CV gain and the
// lowest CV RMSE (none: the declared model stays).
void name_effect(DemDiagnosis& r, const std::vector<std::size_t>& tested, double alpha) {
    std::vector<double> p;
    for (std::size_t k : tested) p.push_back(r.candidates[k].p_value);
    const auto adjusted = holm(p);
    for (std::size_t j = 0; j < tested.size(); ++j) {
        DemCandidateResult& c = r.candidates[tested[j]];
        c.p_holm = adjusted[j];
        c.significant = c.p_holm < alpha;
        if (c.significant && c.cv_gain && (r.effect < 0 || c.cv_rmse < r.candidates[std::size_t(r.effect)].cv_rmse))
            r.effect = int(tested[j]);
    }
    if (r.effect >= 0) r.candidates[std::size_t(r.effect)].accepted = true;
}

// The scores with the effect (or the declared model) as the final model.
void score_after(DemDiagnosis& r, const SiloMeasurements& data, const ConditionStats& s) {
    const std::size_t C = data.conditions.size();
    if (r.effect >= 0) {
        const DemCandidateResult& e = r.candidates[std::size_t(r.effect)];
        r.rates_after = e.rates_fitted;
        r.cv_rmse_after = e.cv_rmse;
    } else {
        r.rates_after = r.rates_declared;
        r.cv_rmse_after = r.rmse_before;
    }
    const auto log_after = logs(r.rates_after);
    r.rmse_after = std::sqrt(row_sse(data, s, log_after) / r.n);
    r.rmse_after_g_s = rmse_g_s(data, r.rates_after);
    const int df_after = int(C) - (r.effect >= 0 ? 1 : 0);
    r.lack_of_fit_p_after = gsl_cdf_fdist_Q(chi2_of(s, log_after, r.prediction_seeds) / double(df_after),
                                            double(df_after), double(s.df_pure_error));
}

// Rivals: other significant candidates whose fit is not worse than the effect's by more than the interval's chi2
// quantile. The rates then cannot tell them apart: the effect is the likelier one, not the proven one. Each gets its
// separation design and a warning.
void find_rivals(DemDiagnosis& r, const SiloMeasurements& data, const ConditionStats& s,
                 const std::vector<std::size_t>& tested, double interval_level, double delta_chi2) {
    const int K = r.prediction_seeds;
    const auto& e = r.candidates[std::size_t(r.effect)];
    for (std::size_t k : tested) {
        const auto& c = r.candidates[k];
        if (int(k) == r.effect || !c.significant || !c.cv_gain) continue;
        if (c.chi2_fitted - e.chi2_fitted < delta_chi2) {
            r.rivals.push_back(int(k));
            const auto sep = rival_separation(s, K, e, c, int(k), interval_level);
            r.separations.push_back(sep);
            r.warnings.push_back(c.spec.name + " = " + number_text(c.fitted, 4) + " explains the data nearly as well "
                                 "as " + e.spec.name + " (CV RMSE " + number_text(c.cv_rmse, 3) + " against " +
                                 number_text(e.cv_rmse, 3) + ", chi2 " + number_text(c.chi2_fitted, 3) +
                                 " against " + number_text(e.chi2_fitted, 3) + "): these rates cannot tell the two "
                                 "apart; " + separation_advice(sep, data, s, K, e.spec.name));
        }
    }
}

}  // namespace

DemDiagnosis diagnose_dem(const SiloMeasurements& data, const std::vector<double>& rates_declared,
                          const std::vector<DemCandidateSetup>& setups, const DemDiagnoseOptions& o) {
    const ConditionStats s = diagnosable_stats(data, rates_declared);
    const std::size_t C = data.conditions.size();
    const int K = std::max(1, o.prediction_seeds);
    DemDiagnosis r;
    r.n = int(data.rows());
    r.conditions = int(C);
    r.df_pure_error = s.df_pure_error;
    r.prediction_seeds = K;
    r.noise_sd = std::sqrt(s.s2);
    r.rates_declared = rates_declared;
    const auto log_declared = logs(rates_declared);
    r.rmse_before = std::sqrt(row_sse(data, s, log_declared) / r.n);
    r.rmse_before_g_s = rmse_g_s(data, rates_declared);
    r.chi2_before = chi2_of(s, log_declared, K);
    r.lack_of_fit_p_before = gsl_cdf_fdist_Q(r.chi2_before / double(C), double(C), double(s.df_pure_error));
    const double delta_chi2 = f1_quantile(o.interval_level, double(s.df_pure_error));

    std::vector<std::size_t> tested;
    for (const DemCandidateSetup& setup : setups) {
        DemCandidateResult c;
        c.spec = setup.spec;
        if (!setup.declared) {
            c.available = false;
            c.unavailable = setup.unavailable;
        } else if (assess_candidate(c, setup, data, s, r, o, delta_chi2)) {
            tested.push_back(r.candidates.size());
        }
        r.candidates.push_back(std::move(c));
    }
    name_effect(r, tested, o.alpha);
    score_after(r, data, s);
    if (r.effect >= 0) {
        find_rivals(r, data, s, tested, o.interval_level, delta_chi2);
        const auto& e = r.candidates[std::size_t(r.effect)];
        if (e.interval_at_lower_bound || e.interval_at_upper_bound)
            r.warnings.push_back(e.spec.name + ": the interval reaches the candidate's bound; the value may lie "
                                 "beyond it");
    }
    if (r.effect < 0 && r.lack_of_fit_p_before < o.alpha)
        r.warnings.push_back("the declared material misses the data beyond their repeat scatter (lack of fit p = " +
                             number_text(r.lack_of_fit_p_before, 3) +
                             "), but no single candidate explains it: an effect outside the table, or several at once");
    return r;
}

nlohmann::json DemDiagnosis::to_json(const SiloMeasurements& data) const {
    using nlohmann::json;
    auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    json condition_rows = json::array();
    for (std::size_t c = 0; c < data.conditions.size(); ++c) {
        const auto& k = data.conditions[c];
        json rows = json::array();
        for (std::size_t i = 0; i < data.rows(); ++i)
            if (data.condition_of_row[i] == c) rows.push_back({{"line", data.lines[i]}, {"rate_g_s", data.rate_g_s[i]}});
        condition_rows.push_back({{"label", k.label()}, {"theta_deg", k.theta_deg}, {"outlet_m", num(k.outlet_m)},
                              {"D_m", num(k.diameter_m)}, {"body_height_m", num(k.body_height_m)},
                              {"rate_declared_g_s", rates_declared[c]}, {"rate_after_g_s", rates_after[c]},
                              {"measured", rows}});
    }
    json cands = json::array();
    for (const auto& c : candidates) {
        json j{{"name", c.spec.name}, {"fields", c.spec.fields}, {"bounds", {c.spec.lower, c.spec.upper}},
               {"scale", to_string(c.spec.scale)}, {"mechanism", c.spec.mechanism}, {"available", c.available}};
        if (!c.available) {
            j["unavailable"] = c.unavailable;
        } else {
            j.update({{"declared", c.declared},
                      {"fitted", c.fitted},
                      {"interval", {c.interval_low, c.interval_high}},
                      {"interval_reaches_bound", c.interval_at_lower_bound || c.interval_at_upper_bound},
                      {"evaluated", c.evaluated},
                      {"sse_of_runs", c.sse_of_runs},
                      {"stops_flow", c.stops_flow},
                      {"rmse_declared", num(c.rmse_declared)},
                      {"rmse_fitted", num(c.rmse_fitted)},
                      {"cv_rmse_declared", num(c.cv_rmse_declared)},
                      {"cv_rmse", num(c.cv_rmse)},
                      {"chi2_declared", num(c.chi2_declared)},
                      {"chi2_fitted", num(c.chi2_fitted)},
                      {"f_statistic", num(c.f_statistic)},
                      {"p_value", num(c.p_value)},
                      {"p_holm", num(c.p_holm)},
                      {"significant", c.significant},
                      {"cv_gain", c.cv_gain},
                      {"accepted", c.accepted},
                      {"fitted_without_condition", c.fitted_without}});
        }
        cands.push_back(j);
    }
    json effect_json = nullptr;
    if (effect >= 0) {
        const auto& e = candidates[std::size_t(effect)];
        effect_json = {{"name", e.spec.name},       {"fields", e.spec.fields},   {"declared", e.declared},
                       {"fitted", e.fitted},        {"interval", {e.interval_low, e.interval_high}},
                       {"p_holm", e.p_holm},        {"cv_rmse_after", e.cv_rmse}};
        json rival_names = json::array();
        for (int k : rivals) rival_names.push_back(candidates[std::size_t(k)].spec.name);
        effect_json["rivals"] = rival_names;
        json separations_json = json::array();
        for (const auto& sep : separations) {
            json where = json::array();
            for (std::size_t j = 0; j < sep.conditions.size(); ++j)
                where.push_back({{"condition", data.conditions[std::size_t(sep.conditions[j])].label()},
                                 {"share", sep.shares[j]}});
            separations_json.push_back({{"rival", candidates[std::size_t(sep.rival)].spec.name},
                                        {"observed_chi2_difference", sep.observed_chi2_difference},
                                        {"expected_chi2_difference", sep.expected_chi2_difference},
                                        {"needed_chi2_difference", sep.needed_chi2_difference},
                                        {"repeats_only_limit", sep.repeats_only_limit},
                                        {"repeats_and_seeds_multiplier", num(sep.multiplier)},
                                        {"conditions_by_share", where}});
        }
        effect_json["rival_separation"] = separations_json;
    }
    return {{"model", "silo-dem"},
            {"n", n},
            {"condition_count", conditions},
            {"df_pure_error", df_pure_error},
            {"noise_sd_log", noise_sd},
            {"prediction_seeds", prediction_seeds},
            {"before", {{"rmse", rmse_before}, {"cv_rmse", rmse_before}, {"rmse_g_s", rmse_before_g_s},
                        {"chi2", chi2_before}, {"lack_of_fit_p", lack_of_fit_p_before}}},
            {"effect", effect_json},
            {"after", {{"rmse", rmse_after}, {"cv_rmse", cv_rmse_after}, {"rmse_g_s", rmse_after_g_s},
                       {"lack_of_fit_p", lack_of_fit_p_after}}},
            {"candidates", cands},
            {"conditions", condition_rows},
            {"warnings", warnings}};
}

void check_diagnosable_data(const SiloMeasurements& data) { checked_condition_stats(data); }

std::string rate_scale_mismatch(const SiloMeasurements& data, const std::vector<double>& declared_g_s) {
    if (declared_g_s.size() != data.conditions.size())
        throw std::invalid_argument("rate_scale_mismatch: one declared rate per condition");
    double log_sum = 0;
    int n = 0;
    for (std::size_t row = 0; row < data.rows(); ++row) {
        const double declared = declared_g_s[data.condition_of_row[row]];
        if (!(declared > 0) || !(data.rate_g_s[row] > 0)) continue;  // a clogged prediction: no ratio
        log_sum += std::log(data.rate_g_s[row] / declared);
        ++n;
    }
    if (n == 0) return "";
    const double ratio = std::exp(log_sum / n);
    if (ratio <= kRateScaleLimit && ratio >= 1 / kRateScaleLimit) return "";
    return "the measured rates are " + number_text(ratio, 3) + " times the declared material's (geometric mean over " +
           std::to_string(n) + " rows of " + data.source + "); no effect of the table moves a rate by a factor of " +
           number_text(kRateScaleLimit, 3) + ": another unit (kg/s under rate_g_s?) or another silo";
}

}  // namespace demcal::analytics
