// The particle-enlargement study of the seed (section 3.2), end to end, over one failure-line evaluator (in the
// program: stored, cached, resumable shear campaigns):
//  1. at each radius with the base parameters: the failure line, the box-to-particle size ratio and the computing
//     cost per run (CPU and wall time, particles, steps, time step);
//  2. fits: cost(r) = C r^-D (seed fig. 3.5) for the CPU time and for the work (particles x steps), mu_b(r) and
//     tau_c(r) linear or constant by an F test (fig. 3.4);
//  3. at each radius above the reference (the smallest), the calibration loop on young_modulus and poisson_ratio
//     (a sensitivity study of both at that radius, then calibration/calibration_loop's NLopt search) aiming at the
//     reference failure line; then E(r) = A r + B and nu(r) = C r^-D through the reference and the calibrated radii
//     (eqs. 3.1-3.2, fig. 3.6);
//  4. verification: the materials the fitted laws give at every radius, their failure lines against the reference,
//     and the cost saved.
// In YADE's linear contact laws `poisson_ratio` is the stiffness ratio ks/kn, so nu(r) is a law for that ratio.
// Everything that did not converge or that the data cannot determine is listed in `problems`, with the reason.
#pragma once
#include "analytics/response_shape.hpp"
#include "analytics/scaling_law.hpp"
#include "calibration/calibration_loop.hpp"
#include "calibration/sensitivity_study.hpp"

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace demcal::calibration {

// Box size over the largest particle length (orchestrator::max_particle_length). Bounds of ASTM D3080 (direct shear
// of soils): specimen width at least 10 and thickness at least 6 largest particle diameters; on the seed's box
// (0.1 x 0.1 x 0.05 m) they pass 3 mm spheres and fail the 5 and 7 mm ones whose cohesion drifted (calibration/README).
struct BoxRatio {
    static constexpr double min_across = 10;  // min(box_length, box_width) / particle length
    static constexpr double min_height = 6;   // box_height / particle length
    double across = 0, height = 0;
    bool adequate() const { return across >= min_across && height >= min_height; }
    std::string warning() const;  // empty when adequate
    nlohmann::json to_json() const;
};
BoxRatio box_ratio(const nlohmann::json& material);

// Cost of one failure line's runs, per run: means over the runs done (CPU and wall time from the store; particle
// count, steps and time step from their result.json). A run without a measured CPU time (recovered after its
// orchestrator died) is left out of the CPU mean.
struct RunCost {
    int runs = 0;                   // runs with a CPU time
    double cpu_s = 0, cpu_sd = 0;   // mean and standard deviation per run
    double wall_s = 0;
    double particles = 0, steps = 0, timestep_s = 0;
    double particle_steps = 0;      // mean of particles x steps: the work, without the simulator's start-up
    nlohmann::json to_json() const;
};
RunCost run_cost(const FailureLineEvaluation& ev);

struct EnlargementOptions {
    std::vector<double> radii;           // [m], increasing; the first is the reference
    LineKind line = LineKind::peak;
    double tolerance = 0.05;             // relative distance to the reference line (the seed's 5 %)
    double confidence = 0.95;            // of every law's intervals
    analytics::ResponseShapeOptions trend{analytics::ShapeCriterion::f_test, 0.05, 1};  // mu_b(r), tau_c(r)
    SensitivityOptions study;            // levels, span, ranges of the per-radius study (params are set here)
    CalibrationOptions calibration;      // max_evaluations, strict, method...
    std::map<std::string, std::pair<double, double>> bounds;  // search bounds overriding the studied range
    bool fit_unconverged = false;        // fit the laws through the best points of unconverged calibrations too
    bool point_targets = false;          // aim at the reference's values with the tolerance only (not widened by
                                         // the reference line's own interval)
};

// The material of one radius: the base with particle_radius = r, validated (the box against the particle size).
nlohmann::json material_at_radius(const nlohmann::json& base, double radius);
// The two controlling parameters: young_modulus and poisson_ratio.
const std::vector<std::string>& enlargement_controls();

// Every check the study makes before its first run: the radii (at least 3, positive, increasing), each radius's
// material, study levels and search bounds, the options. Throws std::invalid_argument naming the field and value.
void check_enlargement(const nlohmann::json& base, const EnlargementOptions& options);
// Most failure lines the study can evaluate (bases, studies, calibration budgets, verification), for --max-runs.
double planned_failure_lines(const EnlargementOptions& options);  // a double: 2e9 evaluations overflowed an int

struct RadiusBase {
    double radius = 0;
    BoxRatio box;
    analytics::FailureLine line;
    RunCost cost;
};

struct RadiusCalibration {
    double radius = 0;
    CalibrationResult result;
    SensitivityStudy study;
    double young_modulus = 0, poisson_ratio = 0;  // of the best material
    bool converged() const { return result.status == CalibrationStatus::converged; }
};

struct RadiusVerification {
    double radius = 0;
    double young_modulus = 0, poisson_ratio = 0;  // the laws' values
    std::string not_run_because;                  // the laws give an inadmissible material (empty: it ran)
    analytics::FailureLine line;
    RunCost cost;
    double mu_b_deviation = 0, tau_c_deviation = 0;  // (value - reference) / reference
    bool within_tolerance = false;
    double cost_saved = 0;                           // 1 - CPU per run / the reference radius's base CPU per run
    BoxRatio box;
};

struct EnlargementStudy {
    nlohmann::json base_material;
    EnlargementOptions options;
    std::vector<RadiusBase> bases;                        // one per radius
    std::optional<analytics::ScalingLawFit> cpu_law;      // CPU per run = C r^-D
    std::optional<analytics::ScalingLawFit> work_law;     // particles x steps per run = C r^-D
    // mu_b(r), tau_c(r): linear, or constant when the slope's F test is not significant (x_ref = the reference radius)
    std::optional<analytics::ResponseShapeResult> mu_b_trend, tau_c_trend;
    std::vector<RadiusCalibration> calibrations;          // one per radius above the reference
    std::vector<double> law_radii, law_young_moduli, law_poisson_ratios;  // the points behind the two laws
    std::optional<analytics::ScalingLawFit> young_law, poisson_law;
    std::vector<RadiusVerification> verifications;
    std::vector<std::string> problems;                    // fits not converged or not determined, with the reason
    std::vector<std::string> warnings;                    // box ratios below the bounds
    int evaluations = 0, simulations_run = 0, simulations_reused = 0;
    int simulations_failed = 0, replacement_rounds = 0;   // over the distinct failure lines (campaign_evaluator)
    double cpu_s = 0;
    nlohmann::json to_json() const;
    std::string markdown() const;  // the per-radius data and the constants as Markdown tables
};

using EnlargementProgress = std::function<void(const std::string& line)>;

// Runs the study. Throws std::invalid_argument before any evaluation for bad input (check_enlargement).
EnlargementStudy run_enlargement_study(const nlohmann::json& base, const FailureLineEvaluator& evaluate,
                                       const EnlargementOptions& options, const EnlargementProgress& progress = {});

}  // namespace demcal::calibration
