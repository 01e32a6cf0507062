// Normal sub-model: Hertz with viscous damping from the restitution coefficient (EDEM / LIGGGHTS "hertz"):
//   Fn = 4/3 E* sqrt(R*) dn^1.5 - 2 sqrt(5/6) beta sqrt(Sn m*) vn,  Sn = 2 E* sqrt(R* dn),
//   beta = ln e / sqrt(ln^2 e + pi^2).
// The damping term is not clipped (the force may turn slightly attractive at the end of a contact, as in LIGGGHTS
// without limitForce); with that, a head-on collision returns exactly e (verified in tests/kernel/test_contact.cpp).
#pragma once
#include <cmath>
#include "kernel/material.hpp"

namespace demcal::kernel {

/// What a normal model hands to the tangential one.
struct NormalOut {
  double fn;         ///< normal force along n (positive = repulsive) [N]
  double sqrt_rdn;   ///< sqrt(R* dn) [m]
  double sqrt_sn_m;  ///< sqrt(Sn m*) [kg/s]
};

struct HertzNormal {
  /// Normal force for overlap dn > 0 and normal relative velocity vn = v_rel . n (negative while approaching).
  [[gnu::always_inline]] static inline NormalOut force(const PairCoeffs& c, double dn, double r_star, double m_star,
                                                       double vn) {
    NormalOut o;
    o.sqrt_rdn = std::sqrt(r_star * dn);
    const double sn = 2.0 * c.e_star * o.sqrt_rdn;  // Fn_el = 2/3 Sn dn
    o.sqrt_sn_m = std::sqrt(sn * m_star);
    o.fn = (2.0 / 3.0) * sn * dn - c.damp * o.sqrt_sn_m * vn;
    return o;
  }
};

}  // namespace demcal::kernel
