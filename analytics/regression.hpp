// Nonlinear least squares with GSL (gsl_multifit_nlinear, Levenberg-Marquardt trust region, finite-difference
// Jacobian) and the covariance of the estimates scaled by the residual variance.
#pragma once
#include <cstddef>
#include <functional>
#include <vector>

namespace demcal::analytics {

// Fills residuals[0..n) for the parameters params[0..p).
using ResidualFunction = std::function<void(const double* params, double* residuals)>;

struct LeastSquaresFit {
    std::vector<double> params;
    std::vector<double> std_errors;  // sqrt of the covariance diagonal (NaN where the Jacobian is singular)
    std::vector<double> covariance;  // p x p, row-major, (J^T J)^-1 SSE / (n - p)
    double sse = 0;                  // sum of squared residuals at the optimum
    int n = 0, dof = 0;              // residuals, n - p
    bool converged = false;
};

// Minimises the sum of squared residuals from `initial`. n_residuals must be >= the number of parameters;
// throws std::invalid_argument otherwise. Never aborts on GSL errors: a failed fit returns converged = false with the
// best point reached.
LeastSquaresFit fit_least_squares(std::size_t n_residuals, const ResidualFunction& residuals,
                                  const std::vector<double>& initial, int max_iterations = 200);

}  // namespace demcal::analytics
