// Tangential sub-model: Mindlin no-slip spring with history, damping from restitution, Coulomb limit
// (EDEM "Hertz-Mindlin (no slip)", LIGGGHTS "tangential history"):
//   St = 8 G* a (a: the normal model's contact radius, sqrt(R* dn) for Hertz);
//   Ft = -St s - sqrt(St / Sn) c_n vt  (c_n: the normal model's damping coefficient 2 sqrt(5/6) beta sqrt(Sn m*),
//   so that the tangential one is 2 sqrt(5/6) beta sqrt(St m*));
//   s (the accumulated tangential displacement, the history) is first rotated into the current tangent plane
//   (magnitude kept), then incremented by vt dt. If |St s| > mu Fn_crit the contact slides: Ft = -mu Fn_crit s/|s|
//   (no damping while sliding, as LIGGGHTS) and the spring is reset to s = -Ft/St.
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>
#include "kernel/contact/contact_state.hpp"
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct MindlinTangential {
  struct Params {
    double friction = 0.5;  ///< coefficient of static (Coulomb) friction mu_s [-], >= 0
    void validate() const {
      if (!(friction >= 0 && std::isfinite(friction)))
        throw std::invalid_argument("friction must be finite and >= 0, got " + std::to_string(friction));
    }
  };
  struct Coeffs {
    double g_star = 0;      ///< effective shear modulus G* [Pa]
    double mu = 0;          ///< static friction coefficient
    double st_over_sn = 0;  ///< sqrt(St / Sn) = sqrt(4 G* / E*)
  };
  static Coeffs mix(const Material& a, const Material& b, const Params& p) {
    const double g = effective_shear(a, b);
    return {g, p.friction, std::sqrt(4.0 * g / effective_young(a, b))};
  }
  static constexpr int history_size = 3;  ///< the spring's displacement s (world frame)
  /// When i and j trade places the displacement of i relative to j changes sign.
  static void swap_history(double* h) { h[0] = -h[0]; h[1] = -h[1]; h[2] = -h[2]; }

  /// g, k: the contact; vt: tangential relative velocity; nrm: the normal model's output; h: history (in/out).
  [[gnu::always_inline]] static inline Vec3 force(const Coeffs& c, const ContactGeometry& g, const ContactKinematics&,
                                                  const Vec3& vt, NormalState& nrm, double* h, double dt, bool) {
    const Vec3& n = g.n;
    Vec3 s(h[0], h[1], h[2]);
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
    const double st = 8.0 * c.g_star * nrm.contact_radius;
    const double ft_max = c.mu * nrm.fn_crit;
    const double s2 = s.squaredNorm();
    Vec3 ft;
    if (st * st * s2 > ft_max * ft_max) {  // sliding
      if (s2 > 0.0) {
        s *= ft_max / (st * std::sqrt(s2));
        ft = -st * s;
      } else {
        ft = Vec3::Zero();
      }
    } else {
      ft = -st * s - (nrm.damp_prefactor * c.st_over_sn) * vt;
    }
    h[0] = s.x(); h[1] = s.y(); h[2] = s.z();
    return ft;
  }
};

}  // namespace demcal::kernel
