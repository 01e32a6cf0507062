// Normal sub-model: JKR adhesion (Johnson-Kendall-Roberts; EDEM's "Hertz-Mindlin with JKR cohesion"), for moist or
// fine cohesive powders. With the contact radius a and the surface energy gamma (EDEM's "cohesion energy density"):
//   F_el(a) = 4 E* a^3 / (3 R*) - 4 sqrt(pi gamma E*) a^1.5,      dn(a) = a^2 / R* - sqrt(4 pi gamma a / E*).
// (Johnson's form with the work of adhesion w = 2 gamma.) For an overlap dn the contact radius is the root of dn(a) on
// its stable branch (Newton on x = sqrt(a): dn = x^4/R* - k x, k = sqrt(4 pi gamma / E*), convex in x).
// Hysteresis: a contact forms when the spheres touch (dn > 0) and then holds in tension until the gap reaches
// -dn_c = 3/4 k x_c, x_c = (k R*/4)^(1/3) (the end of the stable branch); the largest pull, at a = (9 pi gamma R*^2 /
// (4 E*))^(1/3), is the pull-off force 3 pi gamma R* (= 3/2 pi w R*). Both are checked in tests/kernel/test_jkr.cpp.
// Damping as HertzNormal with Sn = 2 E* a. Friction and rolling resistance are bounded by |F_el + 2 F_pulloff| (the
// Hertzian load of the same contact area, as LAMMPS GRANULAR's jkr), so an adhesive contact has friction at zero load.
// gamma = 0 is Hertz. History: whether the pair has touched, and the last x (a warm start for Newton).
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>
#include "kernel/contact/contact_state.hpp"
#include "kernel/material.hpp"

namespace demcal::kernel {

struct JkrNormal {
  struct Params {
    double restitution = 0.5;     ///< coefficient of restitution e [-], in (0, 1]
    double surface_energy = 0.0;  ///< gamma [J/m^2] >= 0 (EDEM's JKR "surface energy"; work of adhesion w = 2 gamma)
    void validate() const {
      restitution_beta(restitution);
      if (!(surface_energy >= 0 && surface_energy < 1e6))
        throw std::invalid_argument("surface_energy must be in [0, 1e6) J/m^2, got " + std::to_string(surface_energy));
    }
  };
  struct Coeffs {
    double e_star = 0;   ///< effective Young's modulus E* [Pa]
    double damp = 0;     ///< 2 sqrt(5/6) |beta|
    double gamma = 0;    ///< surface energy [J/m^2]
    double k = 0;        ///< sqrt(4 pi gamma / E*) [m^0.5]
    double adhesion = 0; ///< 4 sqrt(pi gamma E*) [N/m^1.5]
  };
  static Coeffs mix(const Material& a, const Material& b, const Params& p) {
    Coeffs c;
    c.e_star = effective_young(a, b);
    c.damp = 2.0 * std::sqrt(5.0 / 6.0) * std::abs(restitution_beta(p.restitution));
    c.gamma = p.surface_energy;
    c.k = std::sqrt(4.0 * M_PI * c.gamma / c.e_star);
    c.adhesion = 4.0 * std::sqrt(M_PI * c.gamma * c.e_star);
    return c;
  }
  static constexpr int history_size = 2;  ///< [0]: 1 once the pair touched; [1]: last x = sqrt(a) [m^0.5]
  static constexpr bool beyond_contact = true;
  static void swap_history(double*) {}

  /// x = sqrt(a) at the end of the stable branch (where the contact snaps off).
  static double x_snap(const Coeffs& c, double r_star) { return std::cbrt(0.25 * c.k * r_star); }
  /// The gap at which a formed contact snaps off, -dn_c > 0 [m].
  static double reach(const Coeffs& c, double r_star) { return 0.75 * c.k * x_snap(c, r_star); }
  /// The largest tensile force of a contact, 3 pi gamma R* [N].
  static double pull_off_force(const Coeffs& c, double r_star) { return 3.0 * M_PI * c.gamma * r_star; }
  static bool acts(const Coeffs& c, const ContactGeometry& g, const double* h) {
    return g.dn > 0.0 || (h[0] != 0.0 && g.dn > -reach(c, g.r_star));
  }
  /// x = sqrt(a) on the stable branch for overlap dn (>= -reach): the largest root of x^4/R* - k x - dn.
  static double root_x(const Coeffs& c, double r_star, double dn, double x_guess) {
    if (c.k == 0.0) return std::sqrt(std::sqrt(r_star * std::max(dn, 0.0)));
    const double xc = x_snap(c, r_star);
    // From any x > x_c Newton reaches the root from above and then decreases monotonically (convex, increasing).
    // Without a warm start: from an upper bound (at x >= (2 k R*)^(1/3), k x <= x^4 / (2 R*)).
    double x = x_guess > 0.0 ? std::max(x_guess, 1.001 * xc)
                             : std::max(std::cbrt(2.0 * c.k * r_star), std::sqrt(std::sqrt(2.0 * r_star * std::max(dn, 0.0))));
    for (int it = 0; it < 100; ++it) {
      const double x3 = x * x * x;
      const double f = x3 * x / r_star - c.k * x - dn, fp = 4.0 * x3 / r_star - c.k;
      const double step = f / fp;
      const double next = std::max(x - step, xc);
      if (std::abs(next - x) <= 1e-15 * x) return next;
      x = next;
    }
    return x;
  }

  [[gnu::always_inline]] static inline NormalState force(const Coeffs& c, const ContactGeometry& g, double vn, double* h) {
    NormalState o;
    h[0] = 1.0;
    const double x = root_x(c, g.r_star, g.dn, h[1]);
    h[1] = x;
    const double a = x * x, a15 = a * x;
    o.contact_radius = a;
    const double f_el = 4.0 * c.e_star * a15 * a15 / (3.0 * g.r_star) - c.adhesion * a15;
    o.damp_prefactor = c.damp * std::sqrt(2.0 * c.e_star * a * g.m_star);
    o.fn = f_el - o.damp_prefactor * vn;
    o.fn_crit = std::abs(f_el + 2.0 * pull_off_force(c, g.r_star));
    return o;
  }
};

}  // namespace demcal::kernel
