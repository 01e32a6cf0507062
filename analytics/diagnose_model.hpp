// The pieces of `diagnose` (analytics/diagnose.cpp): the model a diagnosis fits (a base model and the effects added
// to it), the setting it is fitted in (the data, conditions, folds, regimes, rows), the fitting and scoring helpers and
// the base models (diagnose_model.cpp), the candidate effects and regimes (diagnose_candidates.cpp) and the outlier
// flags (diagnose_outliers.cpp). Internal to analytics: the public interface is analytics/diagnose.hpp.
#pragma once
#include "analytics/diagnose.hpp"
#include "analytics/measured_data.hpp"
#include "analytics/regression.hpp"

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace demcal::analytics::diagnosis {

inline constexpr double nan = std::numeric_limits<double>::quiet_NaN();
// Below this RMS of the dimensionless residuals a fit is exact to rounding (doubles carry about 1e-16).
inline constexpr double kExactFitResidual = 1e-9;
// Residual given to a prediction the model cannot make (non-positive rate, outlet blocked by the annulus): large
// enough that the optimiser steps back, finite so that GSL keeps going.
inline constexpr double penalty_residual = 30.0;

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
    // The base parameters' physical ranges [low, high], where the model has one (empty: none checked). A fitted value
    // outside is no property of a bulk solid: a unit slip in the data (rates in g/s under W_kg_s gave C = 589).
    std::vector<std::pair<double, double>> plausible;
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

struct Errors {
    double rmse = 0, mape = 0;
};

// --- fitting and scoring (diagnose_model.cpp) ---
// A term's effect eta on the prediction: a factor exp(eta) on a rate (relative residuals), an offset scale*eta on a
// stress (absolute residuals, fitted in units of scale).
double apply_effect(double w, double eta, bool relative, double scale);
double residual(const Setting& s, const Model& m, std::size_t row, const double* p);
LeastSquaresFit fit_rows(const Setting& s, const Model& m, const std::vector<std::size_t>& rows,
                         const std::vector<double>& start);
std::vector<std::size_t> all_rows(std::size_t n);
// Fits a model whose last term is new, from the previous parameters and each of the new term's starting points.
LeastSquaresFit fit_extended(const Setting& s, const Model& m, const std::vector<double>& previous);
// Errors over the rows fitted (s.rows).
Errors errors_of(const Setting& s, const std::vector<double>& predicted);
std::vector<double> predictions(const Setting& s, const Model& m, const std::vector<double>& p);
// RMSE of predictions for whole conditions left out of the fit.
double cross_validated_rmse(const Setting& s, const Model& m, const std::vector<double>& full_fit);
std::optional<LackOfFitTest> lack_of_fit(const Setting& s, const Model& m, const std::vector<double>& p);
std::vector<ParameterEstimate> estimates(const Model& m, const LeastSquaresFit& fit);

// --- columns ---
const std::vector<std::string>& condition_columns(MeasuredKind kind);
std::string cell_key(const DataColumn& c, std::size_t row);
bool all_finite(const DataColumn& c);
bool is_constant(const DataColumn& c);
double mean_of(const std::vector<double>& v);
double sd_of(const std::vector<double>& v);
std::string short_number(double v);
bool drift_like(const std::string& name);

// The model named `name` (failure-line, beverloo, oldal, oldal-rect, johanson) over the data; sets s.used.
Model base_model(const std::string& name, const MeasuredData& d, Setting& s);

// --- candidate effects and regimes (diagnose_candidates.cpp) ---
// Every effect not yet in the model (`done`: its variables) that the data can test.
std::vector<Term> candidates(const Setting& s, const Model& m, const std::set<std::string>& done,
                             std::vector<std::string>& warnings, bool first_round);
// The regimes the data and options define: the flow mode (conical hoppers whose angles span more than one mode) and
// each categorical column the user names.
std::vector<Regime> regimes_of(const MeasuredData& d, MeasuredKind kind, const DiagnoseOptions& options,
                               std::string& flow_mode_rule);

// --- outliers (diagnose_outliers.cpp) ---
// Externally studentized residuals of s.rows under the fit p to s.rows; NaN where a row's leverage is 1.
std::vector<double> studentized_residuals(const Setting& s, const Model& m, const std::vector<double>& p);
// The Bonferroni threshold for |t| over the n rows of a fit with k parameters.
double outlier_threshold(std::size_t n, std::size_t k, double alpha);
// Rows (indices into the data) of s.rows whose studentized residual under the fit p is beyond the threshold.
std::vector<std::size_t> flagged_rows(const Setting& s, const Model& m, const std::vector<double>& p, double alpha);

}  // namespace demcal::analytics::diagnosis
