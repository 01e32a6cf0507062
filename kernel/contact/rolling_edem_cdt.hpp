// Rolling sub-models.
// EdemCdtRolling: EDEM's "constant directional torque" (the one the seed's EDEM runs used):
//   tau_i = -mu_r |Fn| R_i omega_i / |omega_i|   (and likewise for j with its own R_j, omega_j),
// with R_i the sphere's radius and omega_i its body's absolute angular velocity. (LIGGGHTS "cdt" uses the relative
// angular velocity and R* instead, about half of this torque for equal spheres; not implemented here.)
// The torque is applied only while |omega| > omega_eps, so a body at rest gets no torque (no jitter at rest).
// NoRolling: no rolling resistance (compiles to nothing).
#pragma once
#include <cmath>
#include "kernel/contact/geometry.hpp"
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct EdemCdtRolling {
  static constexpr double omega_eps = 1e-12;  ///< [rad/s] below this |omega| no rolling torque
  static constexpr bool uses_omega_norm = true;  ///< the kernel fills ContactKinematics::omega_*_norm
  /// Adds the rolling torques to ti (on i) and tj (on j; ignored for walls, wall = true).
  /// The norms |omega| come with the kinematics: a sphere's is computed once per force evaluation, not once per
  /// contact (two square roots per contact saved; the same value, so the same result bit for bit).
  [[gnu::always_inline]] static inline void torque(const PairCoeffs& c, double fn, double radius_i, double radius_j,
                                                   const ContactKinematics& k, Vec3& ti, Vec3& tj, bool wall) {
    if (c.mu_roll == 0.0) return;
    const double a = c.mu_roll * std::abs(fn);
    if (k.omega_i_norm > omega_eps) ti -= (a * radius_i / k.omega_i_norm) * k.omega_i;
    if (!wall && k.omega_j_norm > omega_eps) tj -= (a * radius_j / k.omega_j_norm) * k.omega_j;
  }
};

struct NoRolling {
  static constexpr bool uses_omega_norm = false;
  [[gnu::always_inline]] static inline void torque(const PairCoeffs&, double, double, double, const ContactKinematics&, Vec3&,
                                                   Vec3&, bool) {}
};

}  // namespace demcal::kernel
