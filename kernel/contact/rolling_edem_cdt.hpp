// Rolling sub-models.
// EdemCdtRolling: EDEM's "constant directional torque" (the one the seed's EDEM runs used):
//   tau_i = -mu_r Fn_crit R_i omega_i / |omega_i|   (and likewise for j with its own R_j, omega_j),
// with R_i the sphere's radius and omega_i its body's absolute angular velocity (Fn_crit = |Fn| without adhesion).
// (LIGGGHTS "cdt" uses the relative angular velocity and R* instead, about half of this torque for equal spheres; not
// implemented here.) The torque is applied only while |omega| > omega_eps, so a body at rest gets no torque.
// NoRolling: no rolling resistance (compiles to nothing).
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>
#include "kernel/contact/contact_state.hpp"
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct EdemCdtRolling {
  struct Params {
    double rolling_friction = 0.0;  ///< coefficient of rolling friction mu_r [-], >= 0
    void validate() const {
      if (!(rolling_friction >= 0 && std::isfinite(rolling_friction)))
        throw std::invalid_argument("rolling_friction must be finite and >= 0, got " + std::to_string(rolling_friction));
    }
  };
  struct Coeffs {
    double mu_roll = 0;
  };
  static Coeffs mix(const Material&, const Material&, const Params& p) { return {p.rolling_friction}; }
  static constexpr int history_size = 0;
  static void swap_history(double*) {}
  static constexpr double omega_eps = 1e-12;     ///< [rad/s] below this |omega| no rolling torque
  static constexpr bool uses_omega_norm = true;  ///< the kernel fills ContactKinematics::omega_*_norm
  /// Adds the rolling torques to ti (on i) and tj (on j; ignored for walls, wall = true).
  /// The norms |omega| come with the kinematics: a sphere's is computed once per force evaluation, not once per
  /// contact (two square roots per contact saved; the same value, so the same result bit for bit).
  [[gnu::always_inline]] static inline void torque(const Coeffs& c, const NormalState& nrm, const ContactGeometry& g,
                                                   const ContactKinematics& k, Vec3& ti, Vec3& tj, bool wall) {
    if (c.mu_roll == 0.0) return;
    const double a = c.mu_roll * nrm.fn_crit;
    if (k.omega_i_norm > omega_eps) ti -= (a * g.radius_i / k.omega_i_norm) * k.omega_i;
    if (!wall && k.omega_j_norm > omega_eps) tj -= (a * g.radius_j / k.omega_j_norm) * k.omega_j;
  }
};

struct NoRolling {
  struct Params {
    void validate() const {}
  };
  struct Coeffs {};
  static Coeffs mix(const Material&, const Material&, const Params&) { return {}; }
  static constexpr int history_size = 0;
  static void swap_history(double*) {}
  static constexpr bool uses_omega_norm = false;
  static constexpr bool velocity_free_at_rest = true;
  [[gnu::always_inline]] static inline void torque(const Coeffs&, const NormalState&, const ContactGeometry&,
                                                   const ContactKinematics&, Vec3&, Vec3&, bool) {}
};

}  // namespace demcal::kernel
