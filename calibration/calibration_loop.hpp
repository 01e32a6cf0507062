// The semi-automatic calibration loop (seed section 3.1.2), without a person in it: from a starting material and
// measured targets (mu_b, tau_c), find values of a few controlling micro parameters whose simulated failure line
// matches.
//
// Default search ("surrogate"): the sensitivity study's fitted responses (analytics/response_shape) are the model
// of how each controlling parameter moves mu_b and tau_c (a response classified constant by its F test steers by its
// fitted line: not significant is not zero). Anchored at the latest simulated point and corrected by a
// Broyden (secant) update after each simulation, the model is searched over the parameters' bounds with NLopt
// (GN_DIRECT_L over the whole box, then LN_BOBYQA / LN_COBYLA to polish); only the proposed point is simulated.
// Why not NLopt directly on the simulations: BOBYQA needs 2n + 1 evaluations before its first model step (5 for two
// parameters) and a DEM objective is noisy; the study has already paid for a model, so each further failure line is
// one step of a quasi-Newton iteration, typically 2-4 in all.
//
// Baselines ("coordinate": compass search halving its step; "grid": a plain grid over the same bounds) use the same
// evaluator, bounds and acceptance rule, for the benchmark.
//
// Stopping: every target within max(tolerance * |target|, the target's own interval half-width), or (option) inside
// the simulated line's confidence interval; a proposal that repeats an evaluated point on a bound ends as
// "unreachable", naming the bound; a budget of evaluations ends anything else. The search is deterministic given its
// evaluations, so re-running it over a campaign store replays every finished evaluation from the store (resume).
#pragma once
#include "calibration/macro_target.hpp"
#include "calibration/sensitivity_study.hpp"

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace demcal::calibration {

struct ControlParameter {
    std::string name;       // a micromechanical parameter
    double low = 0, high = 0;  // search bounds [unit of the parameter]
};

enum class SearchMethod { surrogate, coordinate, grid };
SearchMethod search_method_from_string(const std::string& text);  // surrogate | coordinate | grid
std::string to_string(SearchMethod method);

struct CalibrationOptions {
    double tolerance = 0.02;                // relative distance to each target that counts as reached
    bool accept_simulated_interval = true;  // also stop when a target lies inside the simulated interval
    int max_evaluations = 12;               // failure lines, the start included (surrogate, coordinate)
    SearchMethod method = SearchMethod::surrogate;
    bool sequential = false;                // seed order: slope first (control 0), then cohesion (control 1)
    int grid_points = 9;                    // per parameter (grid)
    LineKind line = LineKind::peak;
};

struct CalibrationIteration {
    int evaluation = 0;                     // 1-based count of failure lines
    std::string phase;                      // start, joint, slope, cohesion, coordinate, grid; "(bracketed)" added
                                            // to a secant step between evaluations that bracket the targets
    std::map<std::string, double> values;   // the controlling parameters
    double mu_b = 0, mu_b_half_width = 0, tau_c = 0, tau_c_half_width = 0;
    double mismatch = 0;                    // max over targets of |simulated - target| / acceptance (<= 1: reached)
    bool accepted = false;
    std::string accepted_by;                // "tolerance", "target's interval" (a measured target's own interval, wider than the tolerance), "simulated interval"
    int simulations_run = 0, simulations_reused = 0;
    double cpu_s = 0;
    nlohmann::json to_json() const;
};

enum class CalibrationStatus { converged, unreachable, not_converged };
std::string to_string(CalibrationStatus status);

struct CalibrationResult {
    CalibrationStatus status = CalibrationStatus::not_converged;
    std::string message;
    SearchMethod method = SearchMethod::surrogate;
    std::vector<ControlParameter> controls;
    std::vector<MacroTarget> targets;
    double tolerance = 0.02;
    nlohmann::json material;                 // the best material found (the accepted one when converged)
    std::vector<CalibrationIteration> iterations;
    int best = -1;                           // index into iterations
    int evaluations = 0, simulations_run = 0, simulations_reused = 0;
    double cpu_s = 0;
    nlohmann::json to_json() const;
};

using IterationCallback = std::function<void(const CalibrationIteration&)>;

// Picks one controlling parameter per target from the study: the set whose signed effects (response change across
// its studied range, in units of each target's acceptance) form the best-conditioned square matrix (largest
// |determinant|), each assigned to the target it moves most. Responses classified constant count as no effect.
// `candidates` empty: every studied parameter except timestep_fraction (numerical, not physical).
// `bounds` overrides the studied range as search bounds. Throws std::invalid_argument when no set moves the targets.
std::vector<ControlParameter> choose_controls(const SensitivityStudy& study, const std::vector<MacroTarget>& targets,
                                              double tolerance, const std::vector<std::string>& candidates = {},
                                              const std::map<std::string, std::pair<double, double>>& bounds = {});

// The checks calibrate() makes before its first evaluation, for a caller to make before it runs anything else
// (a sensitivity study, a campaign): the options' values, and a control's bounds (a material parameter, low < high,
// `start` inside, both ends admissible values of a run's material). Throw std::invalid_argument naming the field.
void check_calibration_options(const CalibrationOptions& options);
void check_control(const nlohmann::json& start, const ControlParameter& control);

// Runs the calibration from `start` (whose control values must lie inside the bounds). The surrogate method needs
// `study` holding every control; the baselines ignore it. Throws std::invalid_argument for bad options or controls.
CalibrationResult calibrate(const nlohmann::json& start, const std::vector<MacroTarget>& targets,
                            const std::vector<ControlParameter>& controls, const SensitivityStudy* study,
                            const FailureLineEvaluator& evaluate, const CalibrationOptions& options,
                            const IterationCallback& on_iteration = {});

}  // namespace demcal::calibration
