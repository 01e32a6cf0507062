#include "analytics/diagnose_model.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_linalg.h>

#include <algorithm>
#include <cmath>

namespace demcal::analytics::diagnosis {

// Externally studentized residuals of s.rows under the fit p to s.rows (the deletion formulas of least squares, with
// the leverages of the Jacobian at p); NaN where a row's leverage is 1 (it alone fixes a parameter).
std::vector<double> studentized_residuals(const Setting& s, const Model& m, const std::vector<double>& p) {
    const std::size_t n = s.rows.size(), k = p.size();
    std::vector<double> t(n, nan);
    if (n < k + 2) return t;
    std::vector<double> e(n);
    double sse = 0;
    for (std::size_t i = 0; i < n; ++i) {
        e[i] = residual(s, m, s.rows[i], p.data());
        sse += e[i] * e[i];
    }
    // Jacobian by central differences, then its SVD: the leverage of row i is the squared norm of row i of U over the
    // singular values that are not zero.
    gsl_matrix* u = gsl_matrix_alloc(n, k);
    gsl_matrix* v = gsl_matrix_alloc(k, k);
    gsl_vector* sv = gsl_vector_alloc(k);
    gsl_vector* work = gsl_vector_alloc(k);
    std::vector<double> q = p;
    for (std::size_t j = 0; j < k; ++j) {
        const double h = 1e-6 * std::max(1.0, std::abs(p[j]));
        q[j] = p[j] + h;
        std::vector<double> up(n);
        for (std::size_t i = 0; i < n; ++i) up[i] = residual(s, m, s.rows[i], q.data());
        q[j] = p[j] - h;
        for (std::size_t i = 0; i < n; ++i)
            gsl_matrix_set(u, i, j, (up[i] - residual(s, m, s.rows[i], q.data())) / (2 * h));
        q[j] = p[j];
    }
    gsl_linalg_SV_decomp(u, v, sv, work);
    const double tolerance = gsl_vector_get(sv, 0) * 1e-10 * static_cast<double>(n);
    const double dof = static_cast<double>(n - k);
    for (std::size_t i = 0; i < n; ++i) {
        double h = 0;
        for (std::size_t j = 0; j < k; ++j)
            if (gsl_vector_get(sv, j) > tolerance) h += gsl_matrix_get(u, i, j) * gsl_matrix_get(u, i, j);
        if (h > 1 - 1e-9) continue;
        const double s2 = (sse - e[i] * e[i] / (1 - h)) / (dof - 1);  // residual variance without row i
        if (s2 > 0) t[i] = e[i] / std::sqrt(s2 * (1 - h));
    }
    gsl_vector_free(work);
    gsl_vector_free(sv);
    gsl_matrix_free(v);
    gsl_matrix_free(u);
    return t;
}

// The Bonferroni threshold for |t| over the n rows of a fit with k parameters.
double outlier_threshold(std::size_t n, std::size_t k, double alpha) {
    return n >= k + 2 ? gsl_cdf_tdist_Qinv(alpha / (2.0 * n), static_cast<double>(n - k - 1)) : nan;
}

// Rows (indices into the data) of s.rows whose studentized residual under the fit p is beyond the threshold.
std::vector<std::size_t> flagged_rows(const Setting& s, const Model& m, const std::vector<double>& p, double alpha) {
    const auto t = studentized_residuals(s, m, p);
    const double limit = outlier_threshold(s.rows.size(), p.size(), alpha);
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < t.size(); ++i)
        if (std::abs(t[i]) > limit) out.push_back(s.rows[i]);
    return out;
}

}  // namespace demcal::analytics::diagnosis
