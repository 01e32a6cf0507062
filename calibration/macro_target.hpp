// What the calibration aims at and how one material's failure line is obtained: the shared vocabulary of the
// sensitivity study and the calibration loop.
#pragma once
#include "analytics/failure_line.hpp"
#include "calibration/failure_line_evaluation.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace demcal::calibration {

// Evaluates one material's failure line. In the program it runs (or reuses) a YADE shear campaign with fixed packing
// seeds (common random numbers: every material sees the same packings); tests pass analytic responses.
using FailureLineEvaluator = std::function<FailureLineEvaluation(const nlohmann::json& material)>;

// Which failure line a study or calibration works on.
enum class LineKind { peak, residual };
LineKind line_kind_from_string(const std::string& text);  // "peak" | "residual"; throws naming the value
std::string to_string(LineKind kind);
// The chosen line of an evaluation; throws std::runtime_error naming the material's failed runs when it has none.
const analytics::FailureLine& line_of(const FailureLineEvaluation& ev, LineKind kind);

// A macro quantity of a failure line: "mu_b" or "tau_c".
double macro_value(const analytics::FailureLine& line, const std::string& quantity);
double macro_std_error(const analytics::FailureLine& line, const std::string& quantity);
double macro_half_width(const analytics::FailureLine& line, const std::string& quantity);  // of its interval
const std::vector<std::string>& macro_quantities();  // {"mu_b", "tau_c"}

struct MacroTarget {
    std::string quantity;               // "mu_b" or "tau_c"
    double value = 0;                   // [-] or [Pa]
    std::optional<double> half_width;   // of the measured line's confidence interval, when the target is a line
    // Accepted distance |simulated - value|: the wider of tolerance * |value| and the target's own half-width.
    double acceptance(double tolerance) const;
};

// Parses "mu_b=0.55,tau_c=800"; throws std::invalid_argument naming the item.
// Refuses (std::invalid_argument naming `option`) a comma-separated list with an empty item: "a,,b", ",a", "a,".
void refuse_empty_list_items(const std::string& text, const std::string& option);

std::vector<MacroTarget> parse_targets(const std::string& text);
// Targets from a measured failure line (normal and shear stresses [Pa]), with its confidence half-widths.
std::vector<MacroTarget> targets_from_measured_line(std::span<const double> sigma, std::span<const double> tau,
                                                    double confidence = 0.95);

// Material JSON values: numbers rounded to `digits` significant digits so that stored materials read well and the
// same proposal hashes to the same runs.
double round_significant(double value, int digits = 6);

}  // namespace demcal::calibration
