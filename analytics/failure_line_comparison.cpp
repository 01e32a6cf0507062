#include "analytics/failure_line_comparison.hpp"

#include "analytics/number_text.hpp"

#include <gsl/gsl_cdf.h>

#include <cmath>
#include <stdexcept>

namespace demcal::analytics {

namespace {
ParameterComparison compare(double a, double se_a, double hw_a, double b, double se_b, double hw_b, int n_a,
                            int n_b, double confidence) {
    ParameterComparison c;
    c.confidence = confidence;
    c.a = a;
    c.b = b;
    c.difference = a - b;
    const double va = se_a * se_a, vb = se_b * se_b;
    c.standard_error = std::sqrt(va + vb);
    const double df_a = n_a - 2, df_b = n_b - 2;
    const double denom = (df_a > 0 ? va * va / df_a : 0) + (df_b > 0 ? vb * vb / df_b : 0);
    c.degrees_of_freedom = denom > 0 ? (va + vb) * (va + vb) / denom : df_a + df_b;
    c.combined_half_width = std::hypot(hw_a, hw_b);
    if (c.standard_error > 0) {
        const double t = std::abs(c.difference) / c.standard_error;
        c.p_value = 2 * gsl_cdf_tdist_Q(t, c.degrees_of_freedom);
    } else {
        c.p_value = c.difference == 0 ? 1.0 : 0.0;
    }
    return c;
}
}  // namespace

nlohmann::json ParameterComparison::to_json() const {
    return {{"a", a},
            {"b", b},
            {"difference", difference},
            {"standard_error", standard_error},
            {"degrees_of_freedom", degrees_of_freedom},
            {"p_value", p_value},
            // named by its level: 95 for crosscheck's lines, as before the level was carried
            {"combined_half_width_" + number_text(100 * confidence), combined_half_width},
            {"within_combined_intervals", within_combined_intervals()}};
}

nlohmann::json FailureLineComparison::to_json() const {
    return {{"mu_b", mu_b.to_json()}, {"tau_c", tau_c.to_json()}, {"agree", agree()}, {"conclusive", conclusive()}};
}

FailureLineComparison compare_failure_lines(const FailureLine& a, const FailureLine& b) {
    if (a.n < 3 || b.n < 3)
        throw std::invalid_argument("failure line comparison: each line needs at least 3 points (have " +
                                    std::to_string(a.n) + " and " + std::to_string(b.n) + ")");
    // hypot of a 95 % and a 90 % half-width is an interval of no level at all
    if (a.confidence != b.confidence)
        throw std::invalid_argument("failure line comparison: the lines' intervals are at " +
                                    number_text(100 * a.confidence) + " % and " + number_text(100 * b.confidence) +
                                    " %: compare lines fitted at one confidence level");
    FailureLineComparison c;
    c.mu_b = compare(a.mu_b, a.se_mu_b, 0.5 * (a.mu_b_high - a.mu_b_low), b.mu_b, b.se_mu_b,
                     0.5 * (b.mu_b_high - b.mu_b_low), a.n, b.n, a.confidence);
    c.tau_c = compare(a.tau_c, a.se_tau_c, 0.5 * (a.tau_c_high - a.tau_c_low), b.tau_c, b.se_tau_c,
                      0.5 * (b.tau_c_high - b.tau_c_low), a.n, b.n, a.confidence);
    return c;
}

}  // namespace demcal::analytics
