#include "analytics/response_shape.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_multifit.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

namespace demcal::analytics {

std::string to_string(ResponseShape shape) {
    switch (shape) {
        case ResponseShape::constant: return "constant";
        case ResponseShape::linear: return "linear";
        case ResponseShape::parabolic: return "parabolic";
    }
    return "?";
}

std::string to_string(ShapeCriterion criterion) { return criterion == ShapeCriterion::f_test ? "f-test" : "aicc"; }

ShapeCriterion shape_criterion_from_string(const std::string& text) {
    if (text == "f-test") return ShapeCriterion::f_test;
    if (text == "aicc") return ShapeCriterion::aicc;
    throw std::invalid_argument("criterion = '" + text + "' is not one of f-test, aicc");
}

double PolynomialFit::value(double x, double x_ref) const {
    const double d = x - x_ref;
    double y = 0, power = 1;
    for (const auto& c : coefficients) {
        y += c.value * power;
        power *= d;
    }
    return y;
}

double PolynomialFit::slope(double x, double x_ref) const {
    const double d = x - x_ref;
    double s = 0;
    for (std::size_t k = 1; k < coefficients.size(); ++k) s += static_cast<double>(k) * coefficients[k].value * std::pow(d, k - 1);
    return s;
}

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// Weighted fit of degree `degree` in the scaled variable u = (x - x_ref) / scale; coefficients returned in x units.
PolynomialFit fit_polynomial(const std::vector<double>& u, std::span<const double> y, const std::vector<double>& w,
                             int degree, double scale) {
    const std::size_t n = u.size(), p = static_cast<std::size_t>(degree) + 1;
    gsl_matrix* X = gsl_matrix_alloc(n, p);
    gsl_vector* wv = gsl_vector_alloc(n);
    gsl_vector* yv = gsl_vector_alloc(n);
    gsl_vector* c = gsl_vector_alloc(p);
    gsl_matrix* cov = gsl_matrix_alloc(p, p);
    for (std::size_t i = 0; i < n; ++i) {
        double power = 1;
        for (std::size_t k = 0; k < p; ++k) {
            gsl_matrix_set(X, i, k, power);
            power *= u[i];
        }
        gsl_vector_set(wv, i, w[i]);
        gsl_vector_set(yv, i, y[i]);
    }
    double chisq = 0;
    gsl_multifit_linear_workspace* work = gsl_multifit_linear_alloc(n, p);
    gsl_multifit_wlinear(X, wv, yv, c, cov, &chisq, work);
    gsl_multifit_linear_free(work);

    PolynomialFit fit;
    fit.degree = degree;
    fit.chi_squared = chisq;
    fit.dof = static_cast<int>(n - p);
    // Weights are relative: scale the covariance by the residual variance (undefined without residual dof).
    const double variance_scale = fit.dof > 0 ? chisq / fit.dof : nan;
    double unit = 1;  // converts a coefficient of u^k into one of (x - x_ref)^k
    for (std::size_t k = 0; k < p; ++k) {
        Coefficient coef;
        coef.value = gsl_vector_get(c, k) / unit;
        coef.std_error = std::sqrt(gsl_matrix_get(cov, k, k) * variance_scale) / unit;
        if (fit.dof > 0 && coef.std_error > 0) {
            coef.t_statistic = coef.value / coef.std_error;
            coef.p_value = 2 * gsl_cdf_tdist_Q(std::fabs(coef.t_statistic), fit.dof);
        } else if (fit.dof > 0 && coef.value != 0) {  // exact fit: the coefficient is certainly not zero
            coef.t_statistic = inf;
            coef.p_value = 0;
        }
        fit.coefficients.push_back(coef);
        unit *= scale;
    }
    const double k_params = static_cast<double>(p) + 1;  // coefficients + the estimated scale
    const double nd = static_cast<double>(n);
    const double floor = 1e-300;  // an exact fit would give log(0)
    fit.aicc = (nd - k_params - 1 > 0)
                   ? nd * std::log(std::max(chisq, floor) / nd) + 2 * k_params +
                         2 * k_params * (k_params + 1) / (nd - k_params - 1)
                   : inf;
    gsl_matrix_free(X);
    gsl_vector_free(wv);
    gsl_vector_free(yv);
    gsl_vector_free(c);
    gsl_matrix_free(cov);
    return fit;
}

// `negligible`: a sum of squares at the level of rounding errors (identical responses give 1e-30, not 0).
NestedFTest nested_f_test(const PolynomialFit& smaller, const PolynomialFit& larger, double negligible) {
    NestedFTest t;
    t.df_num = larger.degree - smaller.degree;
    t.df_den = larger.dof;
    if (t.df_den <= 0) return t;
    const double extra_ss = smaller.chi_squared - larger.chi_squared;
    if (extra_ss <= negligible) return t;  // the extra term explains nothing
    const double extra = extra_ss / t.df_num;
    const double residual = larger.chi_squared / t.df_den;
    if (larger.chi_squared > negligible) {
        t.f_statistic = extra / residual;
        t.p_value = gsl_cdf_fdist_Q(t.f_statistic, t.df_num, t.df_den);
    } else {  // the larger model is exact and the smaller is not
        t.f_statistic = inf;
        t.p_value = 0;
    }
    return t;
}

nlohmann::json coefficient_json(const Coefficient& c) {
    auto finite_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    return {{"value", c.value},
            {"std_error", finite_or_null(c.std_error)},
            {"t", finite_or_null(c.t_statistic)},
            {"p_value", c.p_value}};
}

nlohmann::json f_test_json(const NestedFTest& t) {
    return {{"F", std::isfinite(t.f_statistic) ? nlohmann::json(t.f_statistic) : nlohmann::json(nullptr)},
            {"df", {t.df_num, t.df_den}},
            {"p_value", t.p_value}};
}

}  // namespace

ResponseShapeResult classify_response(std::span<const double> x, std::span<const double> y,
                                      std::span<const double> sigma, double x_ref,
                                      const ResponseShapeOptions& options) {
    const std::size_t n = x.size();
    if (y.size() != n || (!sigma.empty() && sigma.size() != n))
        throw std::invalid_argument("response shape: " + std::to_string(n) + " levels but " + std::to_string(y.size()) +
                                    " responses and " + std::to_string(sigma.size()) + " uncertainties");
    if (!(options.alpha > 0 && options.alpha < 1))
        throw std::invalid_argument("response shape: alpha = " + std::to_string(options.alpha) + " is not in (0, 1)");
    if (!std::isfinite(x_ref)) throw std::invalid_argument("response shape: x_ref is not finite");
    std::set<double> distinct;
    std::vector<double> w(n, 1.0);
    for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(x[i]) || !std::isfinite(y[i]))
            throw std::invalid_argument("response shape: level " + std::to_string(i) + " is not finite (x = " +
                                        std::to_string(x[i]) + ", y = " + std::to_string(y[i]) + ")");
        if (!sigma.empty()) {
            if (!(sigma[i] > 0) || !std::isfinite(sigma[i]))
                throw std::invalid_argument("response shape: uncertainty of level " + std::to_string(i) + " = " +
                                            std::to_string(sigma[i]) + " must be finite and > 0");
            w[i] = 1.0 / (sigma[i] * sigma[i]);
        }
        distinct.insert(x[i]);
    }
    if (n < 3 || distinct.size() < 3)
        throw std::invalid_argument("response shape: needs at least 3 distinct levels, got " +
                                    std::to_string(distinct.size()) + " distinct of " + std::to_string(n));

    double scale = 0;  // largest distance from x_ref: keeps u in [-1, 1] for a well-conditioned design
    for (double v : x) scale = std::max(scale, std::fabs(v - x_ref));
    std::vector<double> u(n);
    for (std::size_t i = 0; i < n; ++i) u[i] = (x[i] - x_ref) / scale;

    ResponseShapeResult r;
    r.criterion = options.criterion;
    r.alpha = options.alpha;
    r.x_ref = x_ref;
    r.n = static_cast<int>(n);
    if (options.max_degree < 1 || options.max_degree > 2)
        throw std::invalid_argument("response shape: max_degree = " + std::to_string(options.max_degree) +
                                    " is not 1 (linear) or 2 (parabolic)");
    // a parabola through 3 points leaves nothing to test it with
    const int max_degree = n >= 4 ? options.max_degree : 1;
    for (int d = 0; d <= max_degree; ++d) r.fits.push_back(fit_polynomial(u, y, w, d, scale));
    double weighted_total = 0;
    for (std::size_t i = 0; i < n; ++i) weighted_total += w[i] * y[i] * y[i];
    const double negligible = 1e-13 * weighted_total;
    r.linear_vs_constant = nested_f_test(r.fits[0], r.fits[1], negligible);
    if (max_degree == 2) r.parabolic_vs_linear = nested_f_test(r.fits[1], r.fits[2], negligible);

    if (options.criterion == ShapeCriterion::f_test) {
        if (r.parabolic_vs_linear && r.parabolic_vs_linear->p_value < options.alpha)
            r.shape = ResponseShape::parabolic;
        else if (r.linear_vs_constant.p_value < options.alpha)
            r.shape = ResponseShape::linear;
        else
            r.shape = ResponseShape::constant;
    } else {
        int best = 0;
        for (int d = 1; d <= max_degree; ++d)
            if (r.fits[d].aicc < r.fits[best].aicc) best = d;
        r.shape = static_cast<ResponseShape>(best);
    }
    return r;
}

nlohmann::json ResponseShapeResult::to_json() const {
    nlohmann::json j = {{"shape", to_string(shape)}, {"criterion", to_string(criterion)}, {"alpha", alpha},
                        {"x_ref", x_ref},          {"n", n},                             {"fits", nlohmann::json::array()}};
    for (const auto& f : fits) {
        nlohmann::json fj = {{"degree", f.degree},
                             {"chi_squared", f.chi_squared},
                             {"dof", f.dof},
                             {"aicc", std::isfinite(f.aicc) ? nlohmann::json(f.aicc) : nlohmann::json(nullptr)},
                             {"coefficients", nlohmann::json::array()}};
        for (const auto& c : f.coefficients) fj["coefficients"].push_back(coefficient_json(c));
        j["fits"].push_back(fj);
    }
    j["linear_vs_constant"] = f_test_json(linear_vs_constant);
    j["parabolic_vs_linear"] = parabolic_vs_linear ? f_test_json(*parabolic_vs_linear) : nlohmann::json(nullptr);
    const auto& s = selected();
    j["selected"] = {{"value_at_ref", coefficient_json(s.coefficients[0])},
                     {"slope_at_ref", s.degree >= 1 ? coefficient_json(s.coefficients[1]) : nlohmann::json(nullptr)},
                     {"curvature", s.degree >= 2 ? coefficient_json(s.coefficients[2]) : nlohmann::json(nullptr)}};
    return j;
}

}  // namespace demcal::analytics
