// Shape of a response y(x) measured at a few levels of one parameter: constant, linear or parabolic (the seed's
// Table 3.1 vocabulary), chosen by a proper model selection on weighted least-squares fits (GSL gsl_multifit_wlinear,
// weight of a point = 1 / its variance).
//
// Statistics:
//  * the three nested polynomials are fitted in the centred variable x - x_ref (x_ref = the base value of the
//    parameter), so the coefficients read b0 = response at the base, b1 = slope there, b2 = curvature;
//  * the point uncertainties are treated as relative weights (their common scale is estimated from the residuals), so
//    an underestimated failure-line standard error does not turn noise into a shape;
//  * F test (default): extra sum of squares of the quadratic term against the parabola's residual variance; if not
//    significant at alpha, the linear term against the line's residual variance; otherwise constant (the usual
//    backward selection of a polynomial degree, highest term first);
//  * AICc (alternative): the smallest corrected Akaike criterion, scale estimated, k = p + 1 parameters;
//  * every coefficient carries a Student-t p-value (n - p dof).
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace demcal::analytics {

enum class ResponseShape { constant, linear, parabolic };
std::string to_string(ResponseShape shape);

enum class ShapeCriterion { f_test, aicc };
std::string to_string(ShapeCriterion criterion);
// "f-test" or "aicc"; throws std::invalid_argument naming the value otherwise.
ShapeCriterion shape_criterion_from_string(const std::string& text);

struct ResponseShapeOptions {
    ShapeCriterion criterion = ShapeCriterion::f_test;
    double alpha = 0.05;  // significance level of each F test
    int max_degree = 2;   // highest shape considered: 2 = parabolic, 1 = linear (a trend that is a line or nothing)
};

struct Coefficient {
    double value = 0;
    double std_error = 0;
    double t_statistic = 0;
    double p_value = 1;  // two-sided, H0: coefficient = 0
};

// One weighted polynomial fit y = b0 + b1 (x - x_ref) [+ b2 (x - x_ref)^2].
struct PolynomialFit {
    int degree = 0;
    std::vector<Coefficient> coefficients;  // b0, b1, b2 up to the degree
    double chi_squared = 0;                 // weighted sum of squared residuals
    int dof = 0;                            // points - coefficients
    double aicc = 0;                        // +inf when n - k - 1 <= 0 (too few points for this degree)
    double value(double x, double x_ref) const;
    double slope(double x, double x_ref) const;  // dy/dx
};

struct NestedFTest {
    double f_statistic = 0;
    int df_num = 1, df_den = 0;
    double p_value = 1;  // 1 when it cannot be computed (no dof left, or no residual)
};

struct ResponseShapeResult {
    ResponseShape shape = ResponseShape::constant;
    ShapeCriterion criterion = ShapeCriterion::f_test;
    double alpha = 0.05;
    double x_ref = 0;
    int n = 0;
    std::vector<PolynomialFit> fits;           // degrees 0, 1, 2 (2 only with >= 4 points)
    NestedFTest linear_vs_constant;
    std::optional<NestedFTest> parabolic_vs_linear;
    const PolynomialFit& selected() const { return fits.at(static_cast<int>(shape)); }
    double value(double x) const { return selected().value(x, x_ref); }
    double slope(double x) const { return selected().slope(x, x_ref); }
    nlohmann::json to_json() const;
};

// Classifies y(x). sigma holds each point's standard error (> 0); an empty span gives equal weights.
// Needs at least 3 points on at least 3 distinct x; throws std::invalid_argument naming the problem otherwise
// (sizes, non-finite values, sigma <= 0).
ResponseShapeResult classify_response(std::span<const double> x, std::span<const double> y,
                                      std::span<const double> sigma, double x_ref,
                                      const ResponseShapeOptions& options = {});

}  // namespace demcal::analytics
