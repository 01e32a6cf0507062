// Residual diagnosis: fit a model to measured data, examine its residuals against every column, and add the effect the
// model lacks when the evidence holds up on data the fit did not see.
//
// Statistics (chosen to hold up with a few dozen points, replicates and many candidate columns):
//  * fits by GSL nonlinear least squares; discharge models on log W (the noise of a rate is relative), the failure line
//    on tau (absolute);
//  * lack of fit against pure error, where conditions are replicated (a condition = equal values in the model's
//    condition columns: geometry, sizes, angle, density; sigma for shear data);
//  * each candidate effect (a physical one from the library or a generic term in a column) is a nested extension of
//    the current model: F test of the extra sum of squares, Holm's step-down correction over all candidates tried in
//    that round (family-wise error rate `family_alpha`);
//  * cross-validation with whole conditions left out (replicates never straddle folds, which would flatter the bigger
//    model); a candidate is added only when it is significant after Holm AND cuts the cross-validated RMSE by at
//    least `min_cv_improvement`; the best such candidate (lowest CV RMSE) is added, except that a physical effect
//    within `min_cv_improvement` of the best generic one is preferred (it names the mechanism); the search repeats.
//  * effects that depend on a regime: a covariate x whose effect differs by the flow mode (from the hopper angle),
//    by the levels of a column the user names, or continuously with a condition variable z (x*z term). x acts from 0
//    when it has an off state (vibration 0 Hz), else from its mean within each regime, so that the slopes cannot
//    stand in for a level difference between regimes. They are candidates like the others (same F test, Holm family,
//    CV rule); x's plain term replaces them when it predicts within min_cv_improvement.
//  * outliers: externally studentized residuals (leverage from the fit's Jacobian) against a Bonferroni threshold
//    over the rows; the effect search runs without the flagged rows, and the flags are taken again under the model
//    it found until they settle, so a single bad row can neither create an effect nor hide behind one.
#pragma once
#include "analytics/measured_data.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace demcal::analytics {

struct DiagnoseOptions {
    double family_alpha = 0.01;        // family-wise error rate of one round's candidate tests (Holm)
    double min_cv_improvement = 0.05;  // least relative drop of the CV RMSE for an effect to be kept
    int max_effects = 3;               // rounds of the search
    int max_folds = 10;                // conditions are spread over at most this many CV folds
    // Categorical columns whose levels may change a covariate's effect (the flow mode is always tried when the
    // hopper angle puts the rows in more than one mode).
    std::vector<std::string> regime_columns;
    // Both given: the flow mode comes from Jenike's mass-flow limit for these friction angles, else from the seed's
    // classes.
    std::optional<double> effective_friction_deg, wall_friction_deg;
    double outlier_alpha = 0.01;  // chance of flagging any row of a set without outliers (Bonferroni), as family_alpha
    bool drop_outliers = false;   // report the fits without the flagged rows (else: with all rows)
    // How refusals name the options above: as the caller's user gave them (a command line names its flags).
    struct Names {
        std::string regime_column = "regime column";
        std::string effective_friction = "effective_friction_deg", wall_friction = "wall_friction_deg";
    } names;
};

enum class FlowMode { mass, mixed, funnel };
std::string to_string(FlowMode mode);
// The seed's simulations and experiments (as Jenike's design chart predicted for its wheat): mass flow below 30 deg
// half angle, mixed flow from 30 to 40 deg, funnel flow above. With a known wall friction the limit is Jenike's, and
// the mixed band keeps the seed's width of 10 deg above it. 90 deg (flat bottom) is funnel flow.
constexpr double seed_mass_flow_limit_deg = 30, mixed_flow_band_deg = 10;
FlowMode flow_mode_of_angle(double half_angle_deg, double mass_flow_limit_deg = seed_mass_flow_limit_deg);
inline FlowMode flow_mode_by_seed_classes(double half_angle_deg) { return flow_mode_of_angle(half_angle_deg); }

struct ParameterEstimate {
    std::string name;
    double value = 0;
    double std_error = 0;  // from the fit's covariance; NaN when not identifiable from these data
};

struct ErrorSummary {
    double rmse = 0;     // in the response's unit (kg/s or Pa)
    double cv_rmse = 0;  // of predictions for conditions left out of the fit
    double mape = 0;     // mean absolute relative error [%]
};

struct LackOfFitTest {
    double f_statistic = 0;
    int df_lack_of_fit = 0, df_pure_error = 0;
    double p_value = 1;
};

// One candidate effect tried in one round.
struct CandidateTest {
    std::string variable;  // the column (or "row_order", the order of the rows in the file)
    std::string form;      // the term, e.g. "W *= exp(beta*(x - x0))"
    std::string kind;      // "physical", "nonlinearity" (a column the model uses), "missing variable", "drift",
                           // "regime" (x's effect per level of `regime`), "interaction" (x's effect linear in `regime`)
    std::string regime;    // "flow_mode", a categorical column or the z of an x*z term; empty for the other kinds
    int extra_params = 0;
    double f_statistic = 0, p_value = 1, p_holm = 1;
    double cv_rmse = 0;  // with this effect added
    bool accepted = false;
};

struct AddedEffect {
    std::string variable, form, kind, regime;
    std::vector<ParameterEstimate> params;
    double f_statistic = 0, p_value = 1, p_holm = 1;
    int candidates_tried = 0;
    double cv_rmse_before = 0, cv_rmse_after = 0;
};

// A row whose externally studentized residual exceeds the Bonferroni threshold under the final model.
struct Outlier {
    int line = 0;  // file line
    double observed = 0, fitted = 0;
    double studentized = 0;
};

struct OutlierReport {
    double alpha = 0.01, threshold = 0;  // |studentized residual| above threshold is flagged
    std::vector<Outlier> rows;
    // The final model fitted with every row / without the flagged rows (errors over the rows fitted).
    ErrorSummary with_outliers, without_outliers;
    bool dropped = false;  // the reported fits are those without them
};

struct DiagnoseResult {
    std::string model;
    std::string response;        // W_kg_s or tau_Pa
    std::string residual_scale;  // "relative" (fitted on log W) or "absolute"
    int n = 0, conditions = 0, folds = 0;
    std::vector<ParameterEstimate> params_before, params_after;
    ErrorSummary before, after;
    std::optional<LackOfFitTest> lack_of_fit_before, lack_of_fit_after;
    std::vector<AddedEffect> effects;
    std::vector<std::vector<CandidateTest>> rounds;  // every candidate of every round, for the evidence
    std::vector<int> lines;                          // file line of each row
    std::vector<double> observed, fitted_before, fitted_after;
    std::string flow_mode_rule;  // how the flow mode was told, when it was a regime candidate
    std::vector<std::string> flow_mode_of_row;  // "mass" | "mixed" | "funnel" per row, when it was
    OutlierReport outliers;
    std::vector<std::string> warnings;
    // Why the diagnosis is not determined by these data (a base fit that did not converge, rows fitted to rounding,
    // parameters not identifiable): empty when it is. The command then exits 1 unless asked to go on.
    std::vector<std::string> undetermined;
    // {"model", "n", "before": {...}, "effects": [...], "after": {...}} plus details (parameters, tests, rounds).
    nlohmann::json to_json() const;
};

// Models diagnose knows: beverloo, johanson, oldal, oldal-rect, failure-line.
const std::vector<std::string>& diagnose_models();
// The kind of data a model needs (discharge or shear); throws std::invalid_argument for an unknown model.
MeasuredKind data_kind_of(const std::string& model);

// Runs the diagnosis. Throws std::invalid_argument naming the problem when the data do not suit the model
// (e.g. rectangular rows for Beverloo, a flat bottom for Johanson, too few conditions to fit) or an option does not
// suit the data (an unknown regime column, one friction angle without the other).
DiagnoseResult diagnose(const MeasuredData& data, const std::string& model, const DiagnoseOptions& options = {});

}  // namespace demcal::analytics
