// Normal sub-model: Hertz with viscous damping from the restitution coefficient (EDEM / LIGGGHTS "hertz"):
//   Fn = 4/3 E* sqrt(R*) dn^1.5 - 2 sqrt(5/6) beta sqrt(Sn m*) vn,  Sn = 2 E* sqrt(R* dn),
//   beta = ln e / sqrt(ln^2 e + pi^2).
// The damping term is not clipped (the force may turn slightly attractive at the end of a contact, as in LIGGGHTS
// without limitForce); with that, a head-on collision returns exactly e (verified in tests/kernel/test_contact.cpp).
// Acts only in contact (dn > 0); keeps no history.
#pragma once
#include <cmath>
#include <stdexcept>
#include "kernel/contact/contact_state.hpp"
#include "kernel/material.hpp"

namespace demcal::kernel {

/// Hertz's largest overlap in an undamped head-on impact at `speed` [m/s]: 1/2 m* v^2 = 8/15 E* sqrt(R*) delta^(5/2),
/// so delta = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5) [m]. A case whose bodies would overlap by more than a radius at the
/// speeds it produces lets them pass through each other (kernel/silo validate, kernel/cases/cohesive_hopper validate).
inline double hertz_impact_overlap(double m_star, double r_star, double e_star, double speed) {
  return std::pow(15 * m_star * speed * speed / (16 * e_star * std::sqrt(r_star)), 0.4);
}

struct HertzNormal {
  /// Per material pair, set by the user.
  struct Params {
    double restitution = 0.5;  ///< coefficient of restitution e [-], in (0, 1]; 1 = no damping
    void validate() const { restitution_beta(restitution); }
  };
  /// Per pair type, precomputed once.
  struct Coeffs {
    double e_star = 0;  ///< effective Young's modulus E* [Pa]
    double damp = 0;    ///< 2 sqrt(5/6) |beta| (>= 0; 0 for e = 1)
  };
  static Coeffs mix(const Material& a, const Material& b, const Params& p) {
    return {effective_young(a, b), 2.0 * std::sqrt(5.0 / 6.0) * std::abs(restitution_beta(p.restitution))};
  }
  static constexpr int history_size = 0;
  static constexpr bool beyond_contact = false;
  static void swap_history(double*) {}

  /// Normal force for overlap dn > 0 and normal relative velocity vn = v_rel . n (negative while approaching).
  [[gnu::always_inline]] static inline NormalState force(const Coeffs& c, const ContactGeometry& g, double vn, double*) {
    NormalState o;
    o.contact_radius = std::sqrt(g.r_star * g.dn);
    const double sn = 2.0 * c.e_star * o.contact_radius;  // Fn_el = 2/3 Sn dn
    o.damp_prefactor = c.damp * std::sqrt(sn * g.m_star);
    o.fn = (2.0 / 3.0) * sn * g.dn - o.damp_prefactor * vn;
    o.fn_crit = std::abs(o.fn);
    return o;
  }
};

}  // namespace demcal::kernel
