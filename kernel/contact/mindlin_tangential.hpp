// Tangential sub-model: Mindlin no-slip spring with history, damping from restitution, Coulomb limit
// (EDEM "Hertz-Mindlin (no slip)", LIGGGHTS "tangential history"):
//   St = 8 G* sqrt(R* dn);  Ft = -St s - 2 sqrt(5/6) beta sqrt(St m*) vt;
//   s (the accumulated tangential displacement) is first rotated into the current tangent plane (magnitude kept),
//   then incremented by vt dt. If |St s| > mu |Fn| the contact slides: Ft = -mu |Fn| s/|s| (no damping while
//   sliding, as LIGGGHTS) and the spring is reset to s = -Ft/St.
#pragma once
#include <cmath>
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct MindlinTangential {
  /// n: unit normal, vt: tangential relative velocity, fn: normal force (signed), s: history (in/out).
  static inline Vec3 force(const PairCoeffs& c, const Vec3& n, const Vec3& vt, double fn, double sqrt_rdn,
                           double m_star, Vec3& s, double dt) {
    // rotate the history into the current tangent plane, keeping its magnitude
    const double s2_old = s.squaredNorm();
    if (s2_old > 0.0) {
      s -= s.dot(n) * n;
      const double s2_new = s.squaredNorm();
      if (s2_new > 0.0) s *= std::sqrt(s2_old / s2_new);
    }
    s += vt * dt;
    const double st = 8.0 * c.g_star * sqrt_rdn;
    const double ft_spring = st * s.norm();
    const double ft_max = c.mu * std::abs(fn);
    if (ft_spring > ft_max) {
      if (ft_spring > 0.0) {
        const double ratio = ft_max / ft_spring;
        s *= ratio;
        return -st * s;
      }
      return Vec3::Zero();
    }
    return -st * s - c.damp * std::sqrt(st * m_star) * vt;
  }
};

}  // namespace demcal::kernel
