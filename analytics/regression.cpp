#include "analytics/regression.hpp"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit_nlinear.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace demcal::analytics {

namespace {

int gsl_residuals(const gsl_vector* x, void* context, gsl_vector* f) {
    const auto& fn = *static_cast<const ResidualFunction*>(context);
    // GSL hands strided views (a column of the Jacobian when differencing), so go through contiguous copies.
    std::vector<double> xs(x->size), fs(f->size);
    for (std::size_t i = 0; i < x->size; ++i) xs[i] = gsl_vector_get(x, i);
    fn(xs.data(), fs.data());
    for (std::size_t i = 0; i < f->size; ++i) {
        if (!std::isfinite(fs[i])) return GSL_EDOM;
        gsl_vector_set(f, i, fs[i]);
    }
    return GSL_SUCCESS;
}

// GSL's default handler aborts the process; a fit that fails must only report it.
struct GslErrorsReturned {
    gsl_error_handler_t* previous = gsl_set_error_handler_off();
    ~GslErrorsReturned() { gsl_set_error_handler(previous); }
};

}  // namespace

LeastSquaresFit fit_least_squares(std::size_t n, const ResidualFunction& residuals, const std::vector<double>& initial,
                                  int max_iterations) {
    const std::size_t p = initial.size();
    if (p == 0 || n < p)
        throw std::invalid_argument("least squares: " + std::to_string(n) + " residuals for " + std::to_string(p) +
                                    " parameters");
    GslErrorsReturned guard;
    auto params = gsl_multifit_nlinear_default_parameters();
    params.trs = gsl_multifit_nlinear_trs_lm;
    std::unique_ptr<gsl_multifit_nlinear_workspace, decltype(&gsl_multifit_nlinear_free)> work(
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &params, n, p), gsl_multifit_nlinear_free);
    gsl_multifit_nlinear_fdf fdf{};
    fdf.f = gsl_residuals;
    fdf.df = nullptr;  // finite differences
    fdf.fvv = nullptr;
    fdf.n = n;
    fdf.p = p;
    fdf.params = const_cast<ResidualFunction*>(&residuals);

    std::vector<double> x0 = initial;
    gsl_vector_view x = gsl_vector_view_array(x0.data(), p);
    LeastSquaresFit fit;
    fit.n = static_cast<int>(n);
    fit.dof = static_cast<int>(n - p);
    fit.params = initial;
    fit.std_errors.assign(p, std::numeric_limits<double>::quiet_NaN());
    fit.covariance.assign(p * p, std::numeric_limits<double>::quiet_NaN());
    if (gsl_multifit_nlinear_init(&x.vector, &fdf, work.get()) != GSL_SUCCESS) {
        fit.sse = std::numeric_limits<double>::infinity();
        return fit;
    }
    int info = 0;
    const int status = gsl_multifit_nlinear_driver(max_iterations, 1e-10, 1e-10, 1e-14, nullptr, nullptr, &info,
                                                   work.get());
    // No progress means no step lowers the sum of squares any more: a minimum. Started at the optimum (data that
    // follow the law exactly, where the log-log line's start is already the fit), GSL's driver finds no step on its
    // first iteration and reports that as GSL_EMAXITER with info = GSL_ENOPROG: the same minimum, not a failure.
    fit.converged = status == GSL_SUCCESS || status == GSL_ENOPROG || (status == GSL_EMAXITER && info == GSL_ENOPROG);
    const gsl_vector* xs = gsl_multifit_nlinear_position(work.get());
    const gsl_vector* f = gsl_multifit_nlinear_residual(work.get());
    for (std::size_t i = 0; i < p; ++i) fit.params[i] = gsl_vector_get(xs, i);
    double sse = 0;
    gsl_blas_ddot(f, f, &sse);
    fit.sse = sse;
    if (fit.dof > 0) {
        std::unique_ptr<gsl_matrix, decltype(&gsl_matrix_free)> covar(gsl_matrix_alloc(p, p), gsl_matrix_free);
        if (gsl_multifit_nlinear_covar(gsl_multifit_nlinear_jac(work.get()), 0.0, covar.get()) == GSL_SUCCESS) {
            const double s2 = sse / fit.dof;
            for (std::size_t i = 0; i < p; ++i)
                for (std::size_t j = 0; j < p; ++j) fit.covariance[i * p + j] = gsl_matrix_get(covar.get(), i, j) * s2;
            for (std::size_t i = 0; i < p; ++i) fit.std_errors[i] = std::sqrt(fit.covariance[i * p + i]);
        }
    }
    return fit;
}

}  // namespace demcal::analytics
