// Rolling sub-models.
// EdemCdtRolling: EDEM's "constant directional torque" (the one the seed's EDEM runs used):
//   tau_i = -mu_r |Fn| R_i omega_i / |omega_i|   (and likewise for j with its own R_j, omega_j),
// with R_i the sphere's radius and omega_i its body's absolute angular velocity. (LIGGGHTS "cdt" uses the relative
// angular velocity and R* instead, about half of this torque for equal spheres; not implemented here.)
// The torque is applied only while |omega| > omega_eps, so a body at rest gets no torque (no jitter at rest).
// NoRolling: no rolling resistance (compiles to nothing).
#pragma once
#include <cmath>
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct EdemCdtRolling {
  static constexpr double omega_eps = 1e-12;  ///< [rad/s] below this |omega| no rolling torque
  /// Adds the rolling torques to ti (on i) and tj (on j; ignored for walls, wall = true).
  [[gnu::always_inline]] static inline void torque(const PairCoeffs& c, double fn, double radius_i, double radius_j, const Vec3& wi,
                            const Vec3& wj, Vec3& ti, Vec3& tj, bool wall) {
    if (c.mu_roll == 0.0) return;
    const double a = c.mu_roll * std::abs(fn);
    const double wi_n = wi.norm();
    if (wi_n > omega_eps) ti -= (a * radius_i / wi_n) * wi;
    if (!wall) {
      const double wj_n = wj.norm();
      if (wj_n > omega_eps) tj -= (a * radius_j / wj_n) * wj;
    }
  }
};

struct NoRolling {
  [[gnu::always_inline]] static inline void torque(const PairCoeffs&, double, double, double, const Vec3&, const Vec3&, Vec3&, Vec3&, bool) {}
};

}  // namespace demcal::kernel
