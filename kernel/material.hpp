// Materials (per body / per wall) and material-pair properties, with the precomputed per-pair-type constants
// the contact laws use (computed once per pair type, never per contact).
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace demcal::kernel {

/// Elastic and inertial properties of one material. Walls use young/poisson only.
struct Material {
  double young = 1e9;       ///< Young's modulus E [Pa] (> 0). From a shear modulus: E = 2 G (1 + nu).
  double poisson = 0.3;     ///< Poisson's ratio nu [-], in (-1, 0.5).
  double density = 1000.0;  ///< density rho [kg/m^3] (> 0 for particles; ignored for walls).
  std::string name;         ///< free label, for messages only.
  /// Shear modulus G = E / (2 (1 + nu)) [Pa].
  double shear_modulus() const { return young / (2.0 * (1.0 + poisson)); }
};

/// Properties of one (unordered) pair of materials: particle-particle or particle-wall.
struct PairProperties {
  double restitution = 0.5;       ///< coefficient of restitution e [-], in (0, 1]; 1 = no damping.
  double friction = 0.5;          ///< coefficient of static (Coulomb) friction mu_s [-], >= 0.
  double rolling_friction = 0.0;  ///< coefficient of rolling friction mu_r [-], >= 0 (EDEM constant directional
                                  ///< torque: tau = mu_r |Fn| R_i; see contact/rolling_edem_cdt.hpp).
};

/// Constants of one pair type, derived from two Materials and their PairProperties (see contact-model.md).
struct PairCoeffs {
  double e_star = 0;     ///< effective Young's modulus E*: 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j
  double g_star = 0;     ///< effective shear modulus G*: 1/G* = 2(2-nu_i)(1+nu_i)/E_i + 2(2-nu_j)(1+nu_j)/E_j
  double damp = 0;       ///< 2 sqrt(5/6) |beta|, beta = ln e / sqrt(ln^2 e + pi^2) (>= 0; 0 for e = 1)
  double mu = 0;         ///< static friction coefficient
  double mu_roll = 0;    ///< rolling friction coefficient
  double st_over_sn = 0; ///< sqrt(St / Sn) = sqrt(4 G* / E*): sqrt(St m*) = sqrt(Sn m*) * st_over_sn
};

/// beta(e) = ln e / sqrt(ln^2 e + pi^2) (< 0 for e < 1; 0 for e = 1).
inline double restitution_beta(double e) {
  if (!(e > 0.0 && e <= 1.0)) throw std::invalid_argument("restitution must be in (0, 1], got " + std::to_string(e));
  const double l = std::log(e);
  return l / std::sqrt(l * l + M_PI * M_PI);
}

inline PairCoeffs make_pair_coeffs(const Material& a, const Material& b, const PairProperties& p) {
  PairCoeffs c;
  c.e_star = 1.0 / ((1 - a.poisson * a.poisson) / a.young + (1 - b.poisson * b.poisson) / b.young);
  c.g_star = 1.0 / (2 * (2 - a.poisson) * (1 + a.poisson) / a.young + 2 * (2 - b.poisson) * (1 + b.poisson) / b.young);
  c.damp = 2.0 * std::sqrt(5.0 / 6.0) * std::abs(restitution_beta(p.restitution));
  c.mu = p.friction;
  c.mu_roll = p.rolling_friction;
  c.st_over_sn = std::sqrt(4.0 * c.g_star / c.e_star);
  return c;
}

/// Rayleigh time step dt_R = pi R sqrt(rho/G) / (0.1631 nu + 0.8766) of a sphere of radius R [m] (G in Pa).
inline double rayleigh_timestep(double radius, double density, double shear_modulus, double poisson) {
  return M_PI * radius * std::sqrt(density / shear_modulus) / (0.1631 * poisson + 0.8766);
}

}  // namespace demcal::kernel
