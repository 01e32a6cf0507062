// The DEM model as a model (issue 26 item 3): measured silo discharge rates against the kernel's silo with a declared
// material, the residuals traced to a DEM effect the material lacks. Pure numerics: the kernel's predictions come in
// through a callback (app/diagnose_silo_dem.cpp runs them as a campaign of `demcal silo` runs).
//
// Method (each choice because an evaluation is a set of DEM runs, a few seconds each, with seed scatter):
//  * residuals on log rate (a rate's noise is relative, as in the analytical diagnosis); rows with equal geometry are
//    one condition; the noise scale is the measured repeat scatter (pooled within-condition variance s^2 of log rate,
//    df = rows - conditions); a condition mean's residual has variance s^2 (1/n_c + 1/K) with K prediction seeds (the
//    kernel's own seed scatter taken as that of the measurement: the measured data carry no other estimate of it);
//  * each candidate (a row of dem_effect_candidates(): a parameter written to one or more material fields) is run on
//    a coarse grid over its bounds plus its declared value, then a few refinement steps; the kernel's log rate per
//    condition is smoothed by a low-degree polynomial in the parameter (its search scale), so the fit does not chase
//    the seed scatter of single runs; the surrogate's SSE is minimised by GSL's Brent minimiser, and every proposal is
//    run (runs are cached by their material, so nothing runs twice);
//  * decision: chi2(p) = sum_c (mean_c - pred_c(p))^2 / var_c; F = chi2(declared) - chi2(fitted) against F(1, df)
//    (chi2(declared) and the declared CV RMSE: the better of the declared runs and the surrogate at the declared value,
//    so that a surrogate that misses the declared runs cannot make an effect of its own error)
//    (one parameter); Holm over the candidates; the candidate must also cut the leave-one-condition-out CV RMSE by
//    at least min_cv_gain; the lowest CV RMSE among those wins. A clean set (the declared material right) gets none;
//  * interval: the values whose chi2 is within the F(1, df) quantile of the minimum (profile of the SSE).
#pragma once
#include "analytics/measured_data.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace demcal::analytics {

enum class ParameterScale { linear, log };
std::string to_string(ParameterScale scale);

// A DEM effect the declared material may lack: one parameter, written to every listed field of the silo material.
struct DemEffectCandidate {
    std::string name;                 // e.g. "wall_friction"
    std::vector<std::string> fields;  // material JSON paths, "object.key", e.g. "grain_wall.friction"
    double lower = 0, upper = 0;      // bounds of the fitted value
    ParameterScale scale = ParameterScale::linear;  // log: the value spans decades (searched in log)
    std::string mechanism;            // what it stands for, and why these fields together
    // The value a material without the fields has (the silo material reader's default, e.g. no cohesion = 0); none:
    // a material must declare the fields for the candidate to be tried.
    std::optional<double> absent;
};

// The table of candidates diagnose tries, in order. Adding an effect is one row here; a material without a row's
// fields makes the candidate "not in this material" rather than an error, unless the row says what absent means.
const std::vector<DemEffectCandidate>& dem_effect_candidates();
// Defects of a table (empty: none): unique names, at least one "object.key" field, a field in one row only,
// finite lower < upper, log bounds > 0, an absent value inside the bounds.
std::vector<std::string> candidate_table_defects(const std::vector<DemEffectCandidate>& table);

// One measured condition: the silo geometry a row gives (NaN: not given, the silo options after -- decide).
struct SiloCondition {
    double theta_deg = NAN, outlet_m = NAN, diameter_m = NAN, body_height_m = NAN;
    std::string label() const;  // "theta30" or "theta30_outlet0.03_D0.07_H0.15" (a run folder's name part)
    bool operator==(const SiloCondition& o) const;
};

// Measured discharge rates, one row per run. Columns: theta_deg and rate_g_s (required), outlet_m, D_m, body_height_m
// (optional, conical silo; as demcal silo's --outlet, --diameter, --body-height), replicate (optional, any number:
// a label, not used). Any other column is refused, as is a missing or non-numeric cell, a number analytics'
// number rule refuses, a rate <= 0, an angle outside (0, 90) or a size <= 0: FILE: line L, column C: value.
struct SiloMeasurements {
    std::string source;
    std::vector<SiloCondition> conditions;     // in order of first appearance
    std::vector<std::size_t> condition_of_row;
    std::vector<double> rate_g_s;
    std::vector<int> lines;                    // file line of each row
    std::size_t rows() const { return rate_g_s.size(); }
};
const std::vector<std::string>& silo_measurement_columns();
SiloMeasurements silo_measurements_from(const MeasuredData& data);
SiloMeasurements read_silo_measurements(const std::string& path);

struct DemDiagnoseOptions {
    int grid_points = 5;        // coarse bracket: values evenly spaced over the bounds (search scale)
    int refine_steps = 3;       // proposals of the surrogate's minimiser, each one set of runs (then the fitted value)
    int prediction_seeds = 1;   // K: kernel runs (seeds) averaged per condition and value
    double alpha = 0.01;        // family-wise error of the candidates' F tests (Holm)
    double min_cv_gain = 0.05;  // least relative drop of the CV RMSE for an effect to be named
    double interval_level = 0.95;
};

// Rates [g/s] the kernel predicts at each of `values` (outer) for each condition (inner, in SiloMeasurements order).
using DemPredictor = std::function<std::vector<std::vector<double>>(const std::vector<double>& values)>;

struct DemCandidateSetup {
    DemEffectCandidate spec;
    std::optional<double> declared;  // the material's value of the fields; none: not available
    std::string unavailable;         // why not (field absent from the material, fields declared differently)
    DemPredictor predict;
};

struct DemCandidateResult {
    DemEffectCandidate spec;
    bool available = true;
    std::string unavailable;
    double declared = NAN, fitted = NAN;
    double interval_low = NAN, interval_high = NAN;
    bool interval_at_lower_bound = false, interval_at_upper_bound = false;
    std::vector<double> evaluated;          // values run, in order
    std::vector<double> sse_of_runs;        // row SSE of log residuals with the raw runs at each evaluated value
    double rmse_declared = NAN;             // the declared model, log scale: the better of its runs and the surrogate
    double cv_rmse_declared = NAN;          // = rmse_declared (nothing fitted)
    double rmse_fitted = NAN;               // raw runs at the fitted value
    double cv_rmse = NAN;                   // leave one condition out: refit, predict it (surrogate)
    double chi2_declared = NAN, chi2_fitted = NAN;
    double f_statistic = NAN, p_value = NAN, p_holm = NAN;
    bool significant = false, cv_gain = false, accepted = false;
    std::vector<double> rates_fitted;       // raw runs at the fitted value, per condition [g/s]
    std::vector<double> log_curve_fitted;   // the smoothed prediction at the fitted value, log rate per condition
    std::vector<double> fitted_without;     // per condition: the value refitted without it (CV)
    // values run at which some condition did not discharge (an arch or a jam: no rate to fit); the search is then
    // confined to the flowing side of the smallest such value beyond the declared one (spec's bounds narrowed)
    std::vector<double> stops_flow;
};

// What would tell the named effect from a rival. The rival test compares the chi2 of the two fits; with n_c measured
// repeats and K prediction seeds each condition weighs 1 / (s^2 (1/n_c + 1/K)), so if the data's means stay where
// they are, m times the repeats and the seeds multiply the observed difference by m (repeats alone approach a limit:
// the predictions' seed noise stays). The shares say where the two smoothed predictions differ most, and the
// expected difference sum d_c^2 / (s^2 (1/n_c + 1/K)) is what the data would show were the named effect exactly right
// (the T-optimality criterion of model discrimination, Atkinson and Fedorov 1975).
struct DemRivalSeparation {
    int rival = -1;                        // index into candidates
    double observed_chi2_difference = 0;   // the rival's chi2 minus the effect's
    double expected_chi2_difference = 0;   // were the effect exactly right, with these repeats and seeds
    double needed_chi2_difference = 0;     // the interval's F(1, df) quantile: the rival test's threshold
    double repeats_only_limit = 0;         // the observed difference with unlimited repeats, K seeds
    double multiplier = INFINITY;          // the smallest whole m (repeats and seeds times m) whose observed
                                           // difference times m passes the threshold at its own degrees of
                                           // freedom; inf: more than 1000, or no difference in the effect's favour
    std::vector<int> conditions;           // by share of the expected difference, largest first
    std::vector<double> shares;            // the same order, fractions summing to 1
};

struct DemDiagnosis {
    int n = 0, conditions = 0, df_pure_error = 0, prediction_seeds = 1;
    double noise_sd = NAN;  // measured repeat scatter, log rate (~ relative)
    std::vector<double> rates_declared;  // per condition [g/s]
    double rmse_before = NAN, rmse_before_g_s = NAN, chi2_before = NAN, lack_of_fit_p_before = NAN;
    std::vector<DemCandidateResult> candidates;
    int effect = -1;  // index into candidates of the effect named, -1: none
    std::vector<int> rivals;  // candidates that explain the data about as well as the effect (see diagnose_dem)
    std::vector<DemRivalSeparation> separations;  // one per rival, same order
    double rmse_after = NAN, rmse_after_g_s = NAN, cv_rmse_after = NAN, lack_of_fit_p_after = NAN;
    std::vector<double> rates_after;  // per condition [g/s] (= declared when no effect)
    std::vector<std::string> warnings;
    nlohmann::json to_json(const SiloMeasurements& data) const;
};

// Throws std::invalid_argument when the data cannot be diagnosed (fewer than 3 conditions, no repeats).
DemDiagnosis diagnose_dem(const SiloMeasurements& data, const std::vector<double>& rates_declared,
                          const std::vector<DemCandidateSetup>& candidates, const DemDiagnoseOptions& options);

// Values of a candidate's search: `points` evenly spaced in its scale over [lower, upper].
std::vector<double> candidate_grid(const DemEffectCandidate& c, int points);
// A value as it is run: 4 significant digits, so that a cache key (the material) is stable across proposals.
double run_value(double value);

// The data's own conditions for a diagnosis, before any run: at least 3 conditions (the cross-validation leaves one
// out) and repeats of one at least with different rates (the noise scale). Throws std::invalid_argument naming the
// file.
void check_diagnosable_data(const SiloMeasurements& data);

// The largest factor between the measured rates and the declared material's predictions (geometric mean over the
// rows) that a diagnosis takes on: the table's effects move a rate by tens of percent, a unit mistake by 60 (per
// minute), 1000 (kg/s under rate_g_s) or 3600 (per hour).
inline constexpr double kRateScaleLimit = 10;
// Why the measured rates cannot be diagnosed against the declared material's predictions `declared_g_s` (one per
// condition): their geometric-mean ratio beyond kRateScaleLimit either way; "" when within.
std::string rate_scale_mismatch(const SiloMeasurements& data, const std::vector<double>& declared_g_s);

}  // namespace demcal::analytics
