// Tangential sub-model: Mindlin no-slip spring with history, damping from restitution, Coulomb limit
// (EDEM "Hertz-Mindlin (no slip)", LIGGGHTS "tangential history"):
//   St = 8 G* sqrt(R* dn);  Ft = -St s - 2 sqrt(5/6) beta sqrt(St m*) vt;
//   s (the accumulated tangential displacement) is first rotated into the current tangent plane (magnitude kept),
//   then incremented by vt dt. If |St s| > mu |Fn| the contact slides: Ft = -mu |Fn| s/|s| (no damping while
//   sliding, as LIGGGHTS) and the spring is reset to s = -Ft/St.
#pragma once
#include <cmath>
#include "kernel/contact/hertz_normal.hpp"
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct MindlinTangential {
  /// n: unit normal, vt: tangential relative velocity, nrm: the normal model's output, s: history (in/out).
  [[gnu::always_inline]] static inline Vec3 force(const PairCoeffs& c, const Vec3& n, const Vec3& vt,
                                                  const NormalOut& nrm, Vec3& s, double dt) {
    // rotate the history into the current tangent plane, keeping its magnitude
    const double s2_old = s.squaredNorm();
    if (s2_old > 0.0) {
      const double sn = s.dot(n);
      s -= sn * n;
      const double s2_new = s2_old - sn * sn;
      if (s2_new > 0.0) {
        const double eps = sn * sn / s2_new;  // s2_old / s2_new = 1 + eps
        // sqrt(1 + eps) by its series when eps is tiny (the usual case: contacts rotate little per step); the
        // truncation error eps^3/16 < 1e-16 relative below 1e-5
        s *= eps < 1e-5 ? 1.0 + eps * (0.5 - 0.125 * eps) : std::sqrt(1.0 + eps);
      }
    }
    s += vt * dt;
    const double st = 8.0 * c.g_star * nrm.sqrt_rdn;
    const double ft_max = c.mu * std::abs(nrm.fn);
    const double s2 = s.squaredNorm();
    if (st * st * s2 > ft_max * ft_max) {  // sliding
      if (s2 > 0.0) {
        s *= ft_max / (st * std::sqrt(s2));
        return -st * s;
      }
      return Vec3::Zero();
    }
    return -st * s - (c.damp * nrm.sqrt_sn_m * c.st_over_sn) * vt;
  }
};

}  // namespace demcal::kernel
