#include "kernel/clump.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace demcal::kernel {

ClumpTemplate make_clump_template(const std::vector<Vec3>& positions, const std::vector<double>& radii, double density,
                                  int cells) {
  if (positions.empty() || positions.size() != radii.size())
    throw std::invalid_argument("make_clump_template: need as many radii as positions (>= 1)");
  if (!(density > 0)) throw std::invalid_argument("make_clump_template: density must be > 0");
  if (cells < 8) throw std::invalid_argument("make_clump_template: cells must be >= 8");
  for (double r : radii)
    if (!(r > 0)) throw std::invalid_argument("make_clump_template: radii must be > 0");
  ClumpTemplate t;
  t.positions = positions;
  t.radii = radii;
  t.density = density;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (std::size_t k = 0; k < positions.size(); ++k) {
    lo = lo.cwiseMin(positions[k] - Vec3::Constant(radii[k]));
    hi = hi.cwiseMax(positions[k] + Vec3::Constant(radii[k]));
  }
  const double h = (hi - lo).maxCoeff() / cells;
  const int nx = int(std::ceil((hi.x() - lo.x()) / h)), ny = int(std::ceil((hi.y() - lo.y()) / h)),
            nz = int(std::ceil((hi.z() - lo.z()) / h));
  lo = 0.5 * (lo + hi) - 0.5 * h * Vec3(nx, ny, nz);  // grid centred on the bounding box (symmetry kept)
  // accumulate volume, first and second moments (about lo, for conditioning)
  double vol = 0;
  Vec3 m1 = Vec3::Zero();
  Mat3 m2 = Mat3::Zero();
  const double dv = h * h * h;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const Vec3 p = lo + h * Vec3(i + 0.5, j + 0.5, k + 0.5);
        bool in = false;
        for (std::size_t s = 0; s < positions.size() && !in; ++s) in = (p - positions[s]).squaredNorm() <= radii[s] * radii[s];
        if (!in) continue;
        const Vec3 q = p - lo;
        vol += dv;
        m1 += dv * q;
        m2 += dv * q * q.transpose();
      }
  const Vec3 c = m1 / vol;                       // centre (relative to lo)
  const Mat3 second = m2 - vol * c * c.transpose();  // int (q-c)(q-c)^T dV
  Mat3 inertia = density * (second.trace() * Mat3::Identity() - second);
  t.volume = vol;
  t.mass = density * vol;
  t.com = lo + c;
  Eigen::SelfAdjointEigenSolver<Mat3> es(inertia);
  Mat3 axes = es.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1.0;
  t.inertia = es.eigenvalues();
  t.principal = Quat(axes).normalized();
  t.offsets.resize(positions.size());
  t.bounding_radius = 0;
  for (std::size_t k = 0; k < positions.size(); ++k) {
    t.offsets[k] = axes.transpose() * (positions[k] - t.com);
    t.bounding_radius = std::max(t.bounding_radius, t.offsets[k].norm() + radii[k]);
  }
  return t;
}

ClumpTemplate wheat_clump_template(double density, int cells) {
  return make_clump_template({Vec3(-1.5e-3, 0, 0), Vec3(0, 0, 0), Vec3(1.5e-3, 0, 0)}, {1.25e-3, 1.5e-3, 1.25e-3},
                             density, cells);
}

void scale_clump_template(ClumpTemplate& t, double factor) {
  const double f3 = factor * factor * factor, f5 = f3 * factor * factor;
  for (Vec3& p : t.positions) p *= factor;
  for (Vec3& o : t.offsets) o *= factor;
  for (double& r : t.radii) r *= factor;
  t.com *= factor;
  t.volume *= f3;
  t.mass *= f3;
  t.inertia *= f5;
  t.bounding_radius *= factor;
}

}  // namespace demcal::kernel
