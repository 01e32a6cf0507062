// Materials (per body / per wall) and the effective quantities of a pair that several contact sub-models share.
// What a pair of materials adds (restitution, friction, ...) is declared by each sub-model (kernel/contact/).
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

/// beta(e) = ln e / sqrt(ln^2 e + pi^2) (< 0 for e < 1; 0 for e = 1).
inline double restitution_beta(double e) {
  if (!(e > 0.0 && e <= 1.0)) throw std::invalid_argument("restitution must be in (0, 1], got " + std::to_string(e));
  const double l = std::log(e);
  return l / std::sqrt(l * l + M_PI * M_PI);
}

/// Effective Young's modulus of a pair (Hertz): 1/E* = (1-nu_a^2)/E_a + (1-nu_b^2)/E_b [Pa].
inline double effective_young(const Material& a, const Material& b) {
  return 1.0 / ((1 - a.poisson * a.poisson) / a.young + (1 - b.poisson * b.poisson) / b.young);
}

/// Effective shear modulus of a pair (Mindlin): 1/G* = 2(2-nu_a)(1+nu_a)/E_a + 2(2-nu_b)(1+nu_b)/E_b [Pa].
inline double effective_shear(const Material& a, const Material& b) {
  return 1.0 / (2 * (2 - a.poisson) * (1 + a.poisson) / a.young + 2 * (2 - b.poisson) * (1 + b.poisson) / b.young);
}

/// Rayleigh time step dt_R = pi R sqrt(rho/G) / (0.1631 nu + 0.8766) of a sphere of radius R [m] (G in Pa).
inline double rayleigh_timestep(double radius, double density, double shear_modulus, double poisson) {
  return M_PI * radius * std::sqrt(density / shear_modulus) / (0.1631 * poisson + 0.8766);
}

}  // namespace demcal::kernel
