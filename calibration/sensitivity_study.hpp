// Failure-line sensitivity study (seed section 3.1.1, Table 3.1): each micromechanical parameter is varied over a
// range around the base material with the others fixed; the failure line at each level gives mu_b and tau_c, whose
// responses are classified constant / linear / parabolic (analytics/response_shape) with the fitted coefficients and
// their significance. The base material is one level of every parameter, so it is evaluated (and stored) once.
#pragma once
#include "analytics/response_shape.hpp"
#include "calibration/campaign_evaluator.hpp"
#include "calibration/macro_target.hpp"

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace demcal::calibration {

// Most values per parameter a sensitivity study may take: the response shapes are at most quadratic (5 levels let a
// curvature be tested), so 101 levels (1 % of the span apart) resolve any shape the fits can tell; more is a typo
// (2e9 levels planned billions of runs). Refused by name (--levels) before any work.
inline constexpr int kMaxLevels = 101;

struct SensitivityOptions {
    std::vector<std::string> params;  // parameters to vary; empty = all micromechanical ones (orchestrator's list)
    int levels = 5;                   // values per parameter, base included when odd (>= 3)
    double relative_span = 0.5;       // default range base * (1 -+ span), moved inside the admissible range
    std::map<std::string, std::pair<double, double>> ranges;  // explicit [low, high] per parameter
    analytics::ResponseShapeOptions shape;
    LineKind line = LineKind::peak;
};

struct SensitivityLevel {
    double value = 0;         // of the varied parameter
    double mu_b = 0, se_mu_b = 0, mu_b_half_width = 0;
    double tau_c = 0, se_tau_c = 0, tau_c_half_width = 0;
    int simulations_run = 0, simulations_reused = 0;
    double cpu_s = 0;
};

struct ParameterSensitivity {
    std::string name;
    double base_value = 0;
    std::vector<SensitivityLevel> levels;  // ascending values
    analytics::ResponseShapeResult mu_b, tau_c;
    const analytics::ResponseShapeResult& response(const std::string& quantity) const;
    double low() const { return levels.front().value; }
    double high() const { return levels.back().value; }
};

// The campaign a study's failure lines ran on. Its responses hold for that campaign only: another engine, other
// normal stresses (a line over another range of a curved envelope) or another YADE script give other lines, so a
// calibration steered by the study must run the same one. Replicates and seeds only change the lines' precision.
struct StudyCampaign {
    std::string engine;                   // "yade" or "kernel"
    std::vector<double> normal_stresses;  // [Pa], ascending
    std::string template_sha256;          // SHA-256 of a --template YADE script's text; empty for the stock script
    std::optional<int> replicates;        // packings per stress (absent in a study written before demcal recorded it)
    std::optional<long> base_seed;        // the first packing's seed (likewise)
    static StudyCampaign of(const CampaignSettings& c);  // reads the template; throws std::runtime_error if it cannot
    // Empty when a calibration running `here` may use the study; else what differs, both values named.
    std::string difference_from(const StudyCampaign& here) const;
    // Empty when `here` shears the study's packings; else how they differ. Not a reason to refuse the study (its
    // responses are the material's), but its lines are then not the calibration's: none is reused, and the search
    // compares lines of other packings (their scatter included).
    std::string packing_difference_from(const StudyCampaign& here) const;
};

struct SensitivityStudy {
    nlohmann::json base_material;
    SensitivityOptions options;
    std::optional<StudyCampaign> campaign;  // absent in a study written before demcal recorded it
    std::vector<ParameterSensitivity> parameters;
    int evaluations = 0;  // failure lines computed or reused
    int simulations_run = 0, simulations_reused = 0;
    double cpu_s = 0;
    const ParameterSensitivity* find(const std::string& name) const;
    nlohmann::json to_json() const;
    // Reads a stored study (the level data) and refits its shapes with `shape` (the stored options when absent).
    static SensitivityStudy from_json(const nlohmann::json& j);
    // The seed's Table 3.1 for this material, as text: shape of each response with slope, curvature and p-values.
    std::string table() const;
};

// The values a parameter takes in the study: an explicit range as given, else base * (1 -+ span) moved inside the
// admissible interval and shrunk towards the base where the material would be invalid (a box under 4 particle
// lengths). Throws std::invalid_argument naming the parameter and the value when it is not a micromechanical
// parameter, when its base is 0 with no explicit range, or when a range leaves its admissible interval.
std::vector<double> sensitivity_levels(const nlohmann::json& base_material, const std::string& name,
                                       const SensitivityOptions& options);

// Every material the study would simulate, per parameter in study order ({name, [(value, material)]}), each
// checked as a run's material (its range, a box large enough for the particles), and the shape test's alpha: a study
// that would stop after hours of simulation stops here instead. Throws std::invalid_argument naming the field.
std::vector<std::pair<std::string, std::vector<std::pair<double, nlohmann::json>>>>
sensitivity_plan(const nlohmann::json& base_material, const SensitivityOptions& options);

// Fits the two responses of one parameter from its levels.
void fit_responses(ParameterSensitivity& p, const analytics::ResponseShapeOptions& shape);

using SensitivityProgress = std::function<void(const std::string& param, const SensitivityLevel& level)>;

// Runs the study: every level of every parameter through `evaluate`. The base material must be valid.
SensitivityStudy run_sensitivity_study(const nlohmann::json& base_material, const FailureLineEvaluator& evaluate,
                                       const SensitivityOptions& options, const SensitivityProgress& progress = {});

}  // namespace demcal::calibration
