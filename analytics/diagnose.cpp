#include "analytics/diagnose.hpp"

#include "analytics/diagnose_model.hpp"
#include "analytics/discharge_models.hpp"
#include "analytics/regression.hpp"

#include <gsl/gsl_cdf.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>

namespace demcal::analytics {

namespace {

using namespace diagnosis;

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

// --- the search -------------------------------------------------------------------------------------------------

// The base model's parameters the data do not pin down, e.g. "k = 1.28 +/- 6.4e+05": a standard error that is not
// finite, or 0 where the fit has residuals (a column GSL's covariance drops: k = 1.27 +/- 0 from one condition), or
// more than kMaxRelativeStdError times the estimate (C = 0.62 +/- 1.1e5 where only the density varied). A model's own
// constants are never near 0, so the ratio is a fair test for them. Empty when every one is determined.
constexpr double kMaxRelativeStdError = 10;
std::string unidentified_parameters(const Model& m, const LeastSquaresFit& fit) {
    std::string why;
    for (std::size_t i = 0; i < fit.std_errors.size() && i < m.param_names.size(); ++i) {
        const double se = fit.std_errors[i], value = fit.params[i];
        const bool undetermined = !std::isfinite(se) || (se == 0 && fit.sse > 0) ||
                                  se > kMaxRelativeStdError * std::fabs(value);
        if (undetermined)
            why += (why.empty() ? "" : ", ") + m.param_names[i] + " = " + short_number(value) + " +/- " +
                   short_number(se) + " (1 SE)";
    }
    return why;
}

// The base model fitted to s.rows, restarted once when GSL stops at its iteration limit.
LeastSquaresFit fit_base(const Setting& s, const Model& m, std::vector<std::string>& undetermined) {
    LeastSquaresFit fit = fit_extended(s, m, m.start);
    if (!fit.converged) {
        // GSL also stops at its iteration limit when started at the optimum; only a restart that still improves the
        // sum of squares means the fit had not converged.
        const auto again = fit_rows(s, m, s.rows, fit.params);
        if (again.sse < fit.sse * (1 - 1e-8)) undetermined.push_back("the fit of " + m.name + " did not converge");
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

// x by regime (or x * z) is named only where its extra slopes explain more than x's plain term does, by a nested F
// test of the two fits at the family's alpha; otherwise x's plain term, when it is significant and predicts better
// than the model without it. Each candidate is tested against the current model only, where x's plain part carries
// the regime form too: an independent audit named a plain moisture effect "by regime" in 115-128 of 500 sets, of
// which 7-22 had slopes that differed significantly. Returns the index chosen.
int plain_unless_slopes_differ(const std::vector<CandidateTest>& tests, const std::vector<LeastSquaresFit>& fits,
                               int best, std::size_t n, std::size_t model_size, double alpha, double cv_now) {
    const CandidateTest& by_regime = tests[best];
    for (std::size_t i = 0; i < tests.size(); ++i) {
        const CandidateTest& plain = tests[i];
        if (plain.variable != by_regime.variable || !plain.regime.empty() || plain.kind == "physical") continue;
        const int extra = by_regime.extra_params - plain.extra_params;
        const int dof = static_cast<int>(n) - static_cast<int>(model_size) - by_regime.extra_params;
        const double sse_plain = fits[i].sse, sse_regime = fits[best].sse;
        if (extra <= 0 || dof <= 0 || !std::isfinite(sse_plain) || !std::isfinite(sse_regime)) return best;
        const double f = sse_regime > 0 ? ((sse_plain - sse_regime) / extra) / (sse_regime / dof)
                                        : std::numeric_limits<double>::infinity();
        const double p = f > 0 ? gsl_cdf_fdist_Q(f, extra, dof) : 1.0;
        if (p < alpha) return best;  // the slopes differ: the regime form stands
        const bool plain_helps = plain.p_holm < alpha && std::isfinite(plain.cv_rmse) && plain.cv_rmse > 0 &&
                                 plain.cv_rmse < cv_now;
        return plain_helps ? static_cast<int>(i) : best;
    }
    return best;
}

// The rounds of candidate tests on s.rows (F test, Holm, cross-validation), from the base model.
Search search_effects(const Setting& s, const Model& base, const DiagnoseOptions& options,
                      std::vector<std::string>& warnings, std::vector<std::string>& undetermined) {
    Search out{base, fit_base(s, base, undetermined), {}, 0, {}, {}};
    Model& m = out.model;
    LeastSquaresFit& fit = out.fit;
    fit = out.base_fit;
    const std::size_t n = s.rows.size();
    // Residuals are dimensionless (log ratios, or stresses over their scale): a base fit exact to rounding leaves no
    // scatter for an F test (0/0) and nothing to explain, whatever a candidate's fit does with the last bits.
    const double base_rms = std::sqrt(fit.sse / double(std::max<std::size_t>(n, 1)));
    if (std::isfinite(base_rms) && base_rms < kExactFitResidual) {
        out.cv_after = cross_validated_rmse(s, m, fit.params);
        undetermined.push_back("the " + m.name + " model fits every row to rounding (residual RMS " + short_number(base_rms) +
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
        if (best >= 0 && !tests[best].regime.empty())
            best = plain_unless_slopes_differ(tests, fits, best, n, m.size(), options.family_alpha, cv_now);
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

namespace {

// Conditions (rows with equal condition columns are replicates) and cross-validation folds (whole conditions).
void assign_conditions_and_folds(Setting& s, MeasuredKind kind, const DiagnoseOptions& options, DiagnoseResult& result) {
    const MeasuredData& data = s.data;
    const std::size_t n = data.rows();
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
}

// The regimes of the data, and the flow mode of each row when it is one.
void assign_regimes(Setting& s, MeasuredKind kind, const DiagnoseOptions& options, DiagnoseResult& result) {
    s.regimes = regimes_of(s.data, kind, options, result.flow_mode_rule);
    for (const auto& g : s.regimes)
        if (g.name == "flow_mode")
            for (int l : *g.level) result.flow_mode_of_row.push_back(g.level_names[l]);
    if (result.flow_mode_of_row.empty()) {
        result.flow_mode_rule.clear();
        if (options.wall_friction_deg)
            result.warnings.push_back("friction angles given, but the flow mode is no regime here: it needs conical "
                                      "rows whose angles span more than one mode");
    }
}

// Rows outside the rectangular Oldal model's validity limits, as a warning.
void warn_outside_oldal_rect_limits(const MeasuredData& data, DiagnoseResult& result) {
    std::string outside;
    int count = 0;
    for (std::size_t r = 0; r < data.rows(); ++r)
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

std::vector<std::size_t> rows_without(std::size_t n, const std::vector<std::size_t>& flagged) {
    std::vector<std::size_t> kept;
    for (std::size_t r = 0; r < n; ++r)
        if (!std::binary_search(flagged.begin(), flagged.end(), r)) kept.push_back(r);
    return kept;
}

// The effect search without the outliers. Outliers are flagged under the base model, the search runs without them,
// and the flags are taken again under the model it found (fitted to every row) until they settle: a row that only
// looked wild next to a missing effect is given back, a row that a wrong effect had absorbed is caught.
struct SearchWithoutOutliers {
    Search search;
    std::vector<std::size_t> flagged;
    std::vector<double> all_rows_fit;  // the model found, fitted to every row
};

SearchWithoutOutliers search_without_outliers(Setting& s, const Model& base, const DiagnoseOptions& options,
                                              DiagnoseResult& result) {
    const std::size_t n = s.data.rows();
    SearchWithoutOutliers out;
    out.flagged = flagged_rows(s, base, fit_base(s, base, result.undetermined).params, options.outlier_alpha);
    for (int pass = 0;; ++pass) {
        s.rows = rows_without(n, out.flagged);
        out.search = search_effects(s, base, options, result.warnings, result.undetermined);
        s.rows = all_rows(n);
        out.all_rows_fit = fit_rows(s, out.search.model, s.rows, out.search.fit.params).params;
        auto again = flagged_rows(s, out.search.model, out.all_rows_fit, options.outlier_alpha);
        if (again == out.flagged) break;
        if (pass == 2) {
            std::string excluded;
            for (auto r : out.flagged) excluded += (excluded.empty() ? "" : ", ") + std::to_string(s.data.lines[r]);
            result.warnings.push_back("the outlier flags did not settle in 3 passes; the last search excluded lines " +
                                      (excluded.empty() ? std::string("none") : excluded));
            break;
        }
        out.flagged = std::move(again);
    }
    return out;
}

// The outlier report: the final model with every row and without the flagged ones. Returns the fit to every row.
Scored report_outliers(Setting& s, const SearchWithoutOutliers& found, const DiagnoseOptions& options,
                       DiagnoseResult& result) {
    const std::size_t n = s.data.rows();
    const Model& model = found.search.model;
    auto& o = result.outliers;
    o.alpha = options.outlier_alpha;
    o.threshold = outlier_threshold(n, model.size(), options.outlier_alpha);
    s.rows = all_rows(n);
    Scored with_all = score(s, model, found.all_rows_fit);
    o.with_outliers = with_all.errors;
    const auto t_all = studentized_residuals(s, model, with_all.fit.params);
    for (auto r : found.flagged) o.rows.push_back({s.data.lines[r], s.y[r], with_all.fitted[r], t_all[r]});
    o.dropped = options.drop_outliers && !found.flagged.empty();
    if (!found.flagged.empty()) {
        s.rows = rows_without(n, found.flagged);
        o.without_outliers = score(s, model, found.search.fit.params).errors;
    } else {
        o.without_outliers = o.with_outliers;
    }
    return with_all;
}

// The reported fits before and after the effects: on every row, or without the flagged rows when asked. The
// effects' tests and CV come from the search (always without them).
void report_fits(Setting& s, const Model& base, const SearchWithoutOutliers& found, const Scored& with_all,
                 DiagnoseResult& result) {
    const std::size_t n = s.data.rows();
    const Search& search = found.search;
    const bool dropped = result.outliers.dropped;
    s.rows = dropped ? rows_without(n, found.flagged) : all_rows(n);
    const bool no_effect = search.model.terms.empty();  // then before and after are one fit
    const Scored before = no_effect && !dropped ? with_all : score(s, base, search.base_fit.params);
    const Scored after = no_effect ? before : dropped ? score(s, search.model, search.fit.params) : with_all;
    if (const std::string why = unidentified_parameters(base, before.fit); !why.empty())
        result.undetermined.push_back("some parameters of " + result.model + " are not identifiable from these data (" +
                                      why + ")");
    for (std::size_t i = 0; i < base.plausible.size() && i < before.fit.params.size(); ++i) {
        const auto [low, high] = base.plausible[i];
        const double v = before.fit.params[i];
        if (!(v >= low && v <= high))
            result.undetermined.push_back(result.model + "'s " + base.param_names[i] + " = " + short_number(v) +
                                          " lies outside its physical range [" + short_number(low) + ", " +
                                          short_number(high) + "]: the data are not of this model, or of another "
                                          "unit (a rate in g/s under W_kg_s?)");
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
}

}  // namespace

// Rows identical in every cell (the response too) are most often one measurement pasted twice: each counts as its
// own, narrowing every interval. Said, not refused: two runs can read the same to the digits recorded.
void warn_identical_rows(const MeasuredData& data, DiagnoseResult& result) {
    std::map<std::vector<std::string>, int> first_line;
    std::vector<std::string> pairs;
    std::size_t repeated = 0;
    for (std::size_t r = 0; r < data.rows(); ++r) {
        std::vector<std::string> cells;
        for (const auto& c : data.columns) cells.push_back(c.text[r]);
        const auto [it, fresh] = first_line.emplace(cells, data.lines[r]);
        if (fresh) continue;
        ++repeated;
        if (pairs.size() < 3) pairs.push_back(std::to_string(it->second) + " and " + std::to_string(data.lines[r]));
    }
    if (repeated == 0) return;
    std::string listed;
    for (const auto& p : pairs) listed += (listed.empty() ? "" : "; ") + p;
    result.warnings.push_back(std::to_string(repeated) + " duplicate row" + (repeated == 1 ? "" : "s") + ", equal to " +
                              (repeated == 1 ? "an earlier row" : "earlier rows") + " in every cell (lines " + listed +
                              (repeated > pairs.size() ? "; ..." : "") +
                              "): a measurement pasted twice counts twice and narrows every interval");
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
    assign_conditions_and_folds(s, kind, options, result);
    const Model base = base_model(model_name, data, s);
    assign_regimes(s, kind, options, result);
    result.residual_scale = base.relative ? "relative" : "absolute";
    if (n < base.size() + 2)
        throw std::invalid_argument(data.source + ": " + std::to_string(n) + " rows are too few to fit model " +
                                    model_name + " and test its residuals");
    if (model_name == "oldal-rect") warn_outside_oldal_rect_limits(data, result);
    warn_identical_rows(data, result);

    const SearchWithoutOutliers found = search_without_outliers(s, base, options, result);
    result.effects = found.search.effects;
    result.rounds = found.search.rounds;
    const Scored with_all = report_outliers(s, found, options, result);
    report_fits(s, base, found, with_all, result);
    // Repeated searches repeat their warnings.
    for (auto* notes : {&result.warnings, &result.undetermined}) {
        std::vector<std::string> unique;
        for (auto& w : *notes)
            if (std::find(unique.begin(), unique.end(), w) == unique.end()) unique.push_back(std::move(w));
        *notes = std::move(unique);
    }
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
    j["determined"] = undetermined.empty();
    j["undetermined"] = undetermined;
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

