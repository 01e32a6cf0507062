// Normal sub-model: Hertz with viscous damping from the restitution coefficient (EDEM / LIGGGHTS "hertz"):
//   Fn = 4/3 E* sqrt(R*) dn^1.5 - 2 sqrt(5/6) beta sqrt(Sn m*) vn,  Sn = 2 E* sqrt(R* dn),
//   beta = ln e / sqrt(ln^2 e + pi^2).
// The damping term is not clipped (the force may turn slightly attractive at the end of a contact, as in LIGGGHTS
// without limitForce); with that, a head-on collision returns exactly e (verified in tests/kernel/test_contact.cpp).
#pragma once
#include <cmath>
#include "kernel/material.hpp"

namespace demcal::kernel {

struct HertzNormal {
  /// Normal force magnitude along n (positive = repulsive) for overlap dn > 0 and normal relative velocity
  /// vn = v_rel . n (negative while approaching). Returns sqrt(R* dn) in sqrt_rdn for the tangential model.
  static inline double force(const PairCoeffs& c, double dn, double r_star, double m_star, double vn, double& sqrt_rdn) {
    sqrt_rdn = std::sqrt(r_star * dn);
    const double kn = (4.0 / 3.0) * c.e_star * sqrt_rdn;  // Fn_el = kn * dn
    const double sn = 2.0 * c.e_star * sqrt_rdn;
    return kn * dn - c.damp * std::sqrt(sn * m_star) * vn;
  }
};

}  // namespace demcal::kernel
