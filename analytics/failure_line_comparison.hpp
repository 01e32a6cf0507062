// Do two failure lines (two engines, two labs) agree? Each parameter's difference against the uncertainty of both
// fits: a Welch t test (Satterthwaite's degrees of freedom) and the plainer criterion users quote, the difference
// against the two 95 % half-widths combined in quadrature.
#pragma once
#include "analytics/failure_line.hpp"

#include <nlohmann/json.hpp>

namespace demcal::analytics {

struct ParameterComparison {
    double a = 0, b = 0;              // the two estimates
    double difference = 0;            // a - b
    double standard_error = 0;        // sqrt(se_a^2 + se_b^2)
    double degrees_of_freedom = 0;    // Satterthwaite
    double p_value = 1;               // two-sided, H0: equal
    double combined_half_width = 0;   // sqrt(hw_a^2 + hw_b^2) of the two confidence intervals
    double confidence = 0.95;         // the level of both lines' intervals (JSON: combined_half_width_<percent>)
    bool within_combined_intervals() const { return std::abs(difference) <= combined_half_width; }
    nlohmann::json to_json() const;
};

struct FailureLineComparison {
    ParameterComparison mu_b, tau_c;
    bool agree() const { return mu_b.within_combined_intervals() && tau_c.within_combined_intervals(); }
    // An agreement means something only when the intervals could have told the lines apart: a combined half-width on
    // mu_b of at least half of mu_b agrees with anything (-r 1: 5.1 on mu_b 0.6). A difference is conclusive as is.
    bool conclusive() const { return !agree() || mu_b.combined_half_width < 0.5 * std::abs(0.5 * (mu_b.a + mu_b.b)); }
    nlohmann::json to_json() const;
};

// Throws std::invalid_argument when either line has fewer than 3 points (no uncertainty to compare with).
FailureLineComparison compare_failure_lines(const FailureLine& a, const FailureLine& b);

}  // namespace demcal::analytics
