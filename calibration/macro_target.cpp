#include "calibration/macro_target.hpp"

#include "analytics/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace demcal::calibration {

LineKind line_kind_from_string(const std::string& text) {
    if (text == "peak") return LineKind::peak;
    if (text == "residual") return LineKind::residual;
    throw std::invalid_argument("line = '" + text + "' is not one of peak, residual");
}

std::string to_string(LineKind kind) { return kind == LineKind::peak ? "peak" : "residual"; }

const analytics::FailureLine& line_of(const FailureLineEvaluation& ev, LineKind kind) {
    const auto& line = kind == LineKind::peak ? ev.peak : ev.residual;
    if (!line) {
        std::ostringstream o;
        o << "no " << to_string(kind) << " failure line for campaign '" << ev.outcome.campaign.name << "': "
          << ev.simulations_failed << " of " << ev.outcome.runs.size() << " runs failed";
        for (const auto& r : ev.outcome.runs)
            if (r.state == orchestrator::RunState::failed) {
                o << " (first: " << r.cause << ": " << r.message << ", " << r.run_dir.string() << "/stderr.log)";
                break;
            }
        if (ev.outcome.interrupted) o << "; the campaign was interrupted";
        throw std::runtime_error(o.str());
    }
    return *line;
}

const std::vector<std::string>& macro_quantities() {
    static const std::vector<std::string> q{"mu_b", "tau_c"};
    return q;
}

namespace {
void check_quantity(const std::string& quantity) {
    if (quantity != "mu_b" && quantity != "tau_c")
        throw std::invalid_argument("target quantity '" + quantity + "' is not one of mu_b, tau_c");
}

// The targets a bulk material can have: an angle of internal friction below 85 deg (mu_b = 1e9, 89.99999994 deg,
// started a study) and a cohesion up to 100 MPa (beyond a weak rock's). `shown` names where the value came from.
constexpr double kMaxTargetMuB = 11.43;  // tan(85 deg)
constexpr double kMaxTargetTauC = 1e8;   // [Pa]
void check_target_value(const std::string& quantity, double value, const std::string& shown) {
    if (quantity == "mu_b" && !(value > 0 && value <= kMaxTargetMuB))
        throw std::invalid_argument(shown + ": mu_b must be > 0 and at most " + analytics::number_text(kMaxTargetMuB) +
                                    " (an angle of internal friction below 85 deg)");
    if (quantity == "tau_c" && !(value >= 0 && value <= kMaxTargetTauC))
        throw std::invalid_argument(shown + ": tau_c must be >= 0 and at most " + analytics::number_text(kMaxTargetTauC) +
                                    " Pa (a cohesion [Pa])");
}
}  // namespace

double macro_value(const analytics::FailureLine& line, const std::string& quantity) {
    check_quantity(quantity);
    return quantity == "mu_b" ? line.mu_b : line.tau_c;
}

double macro_std_error(const analytics::FailureLine& line, const std::string& quantity) {
    check_quantity(quantity);
    return quantity == "mu_b" ? line.se_mu_b : line.se_tau_c;
}

double macro_half_width(const analytics::FailureLine& line, const std::string& quantity) {
    check_quantity(quantity);
    return quantity == "mu_b" ? 0.5 * (line.mu_b_high - line.mu_b_low) : 0.5 * (line.tau_c_high - line.tau_c_low);
}

double MacroTarget::acceptance(double tolerance) const {
    return std::max(tolerance * std::fabs(value), half_width.value_or(0.0));
}

void refuse_empty_list_items(const std::string& text, const std::string& option) {
    if (text.empty()) return;
    if (analytics::trimmed(text).empty())
        throw std::invalid_argument(option + " = '" + analytics::shortened_text(text) + "' holds blanks only");
    if (analytics::has_empty_list_item(text))  // (an item of blanks only is empty too: "mu_b=0.5, ")
        throw std::invalid_argument(option + " = '" + analytics::shortened_text(text) +
                                    "' has an empty item (two commas in a row, one at an end, or blanks only)");
}

std::vector<MacroTarget> parse_targets(const std::string& text) {
    std::vector<MacroTarget> targets;
    refuse_empty_list_items(text, "target");
    std::stringstream items(text);
    std::string item;
    while (std::getline(items, item, ',')) {
        item = analytics::trimmed(item);  // "mu_b=0.6, tau_c=800", "mu_b = 0.6"
        const auto eq = item.find('=');
        if (eq == std::string::npos)
            throw std::invalid_argument("target item '" + item + "' is not of the form mu_b=VALUE or tau_c=VALUE");
        MacroTarget t;
        t.quantity = analytics::trimmed(item.substr(0, eq));
        check_quantity(t.quantity);
        const std::string value = analytics::trimmed(item.substr(eq + 1));
        const auto number = analytics::read_typed_number(value);
        if (!number.is_number)
            throw std::invalid_argument("target " + t.quantity + " = '" + analytics::shortened_text(value) +
                                        "' is not a number");
        if (number.defect)
            throw std::invalid_argument("target " + t.quantity + " = '" + analytics::shortened_text(value) + "' " +
                                        *number.defect);
        t.value = number.value;
        const std::string shown = "target " + t.quantity + " = " + analytics::shortened_text(value);
        check_target_value(t.quantity, t.value, shown);
        // a band of tol x |0| = 0 Pa: no simulated line ever meets it, and the loop divides by it
        if (t.quantity == "tau_c" && t.value == 0)
            throw std::invalid_argument(shown + ": a tolerance relative to 0 Pa is 0 Pa, which no simulated line "
                                        "meets; give a cohesion > 0, or --measured (its interval is the band)");
        for (const auto& other : targets)
            if (other.quantity == t.quantity) throw std::invalid_argument("target " + t.quantity + " is given twice");
        targets.push_back(t);
    }
    if (targets.empty()) throw std::invalid_argument("target = '" + text + "' names no quantity (mu_b=..,tau_c=..)");
    return targets;
}

std::vector<MacroTarget> targets_from_measured_line(std::span<const double> sigma, std::span<const double> tau,
                                                    double confidence) {
    for (std::size_t i = 0; i < sigma.size() && i < tau.size(); ++i) {
        const std::string point = "measured point " + std::to_string(i + 1) + " (" +
                                  analytics::number_text(sigma[i]) + ":" + analytics::number_text(tau[i]) + ")";
        analytics::check_measured_stress(sigma[i], point + " SIGMA");
        analytics::check_measured_stress(tau[i], point + " TAU");
    }
    // a line through 2 points leaves nothing to estimate its interval by, which is the calibration's band (one point
    // was told its stresses were not 20 % apart, probe 63)
    if (sigma.size() < 3)
        throw std::invalid_argument("the measured failure line has " + std::to_string(sigma.size()) +
                                    " point(s): a line and its " + analytics::number_text(100 * confidence) +
                                    " % interval need at least 3, at 2 or more normal stresses");
    analytics::check_normal_stress_spread(*std::min_element(sigma.begin(), sigma.end()),
                                          *std::max_element(sigma.begin(), sigma.end()),
                                          "the measured failure line's normal stresses");
    const auto line = analytics::fit_failure_line(sigma, tau, confidence);
    // a line may cross 0 a little below (tau_c < 0 within its interval is noise); wholly below 0 it is not a bulk
    // solid's (tau_c = -37 kPa from points whose shear stress rose faster than any friction explains)
    if (line.tau_c_high < 0)
        throw std::invalid_argument("the measured failure line's tau_c = " + analytics::number_text(line.tau_c) +
                                    " Pa, its 95 % interval up to " + analytics::number_text(line.tau_c_high) +
                                    " Pa: below 0, no bulk solid's cohesion (the points' stresses swapped or mistyped?)");
    std::vector<MacroTarget> targets;
    for (const auto& q : macro_quantities()) {
        targets.push_back({q, macro_value(line, q), macro_half_width(line, q)});
        // a measured line's own values: a shear stress 600,000 times the normal one gave mu_b = 6e5
        if (q == "mu_b" || targets.back().value > 0)  // (a measured line may cross 0 a little below: tau_c < 0 is noise)
            check_target_value(q, targets.back().value, "the measured failure line's " + q + " = " +
                                                            analytics::number_text(targets.back().value));
    }
    // the line's interval is the acceptance band: one on mu_b that holds 0 accepts every simulated line, and the
    // loop "converged" at its start (probe 62), the rule demcal scale holds its reference line to
    const double mu = macro_value(line, "mu_b"), half = macro_half_width(line, "mu_b");
    if (!(half < mu))
        throw std::invalid_argument(
            "the measured failure line's mu_b = " + analytics::number_text(mu, 4) + " +/- " +
            analytics::number_text(half, 4) + " (95 %): an interval that holds 0 accepts every simulated line, so no "
            "calibration to it means anything; measure more points or over a wider range of normal stresses, or give "
            "its values as --target mu_b=..,tau_c=.. (met within --tol)");
    return targets;
}

double round_significant(double value, int digits) {
    if (value == 0 || !std::isfinite(value)) return value;
    std::ostringstream o;
    o.precision(digits);
    o << value;
    return std::stod(o.str());
}

}  // namespace demcal::calibration
