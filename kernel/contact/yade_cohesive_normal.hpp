// Normal sub-model: YADE's linear normal spring with fragile cohesive bonds, as yade_scripts/shear_box.py uses it
// (Ip2_CohFrictMat_CohFrictMat_CohFrictPhys + Law2_ScGeom6D_CohFrictPhys_CohesionMoment, and FrictPhys +
// CundallStrack for walls, which is the same law without a bond). Formulas and source lines:
// yade_scripts/YADE_LAWS.md; checked against YADE's own traces (tests/kernel/test_yade_laws.cpp).
//   kn = 2 (E_a R_a)(E_b R_b) / (E_a R_a + E_b R_b)  (a wall "has" the sphere's radius), Fn = kn dn, no damping
//   (YADE damps through the integrator: BasicSimulation::set_local_damping).
// A bond is set on the contacts present when the driver asks (BasicSimulation::bond_contacts_now, YADE's
// setCohesionNow) and only between materials whose pair has a cohesion: normal and shear strengths
// normal_cohesion min(R_a, R_b)^2 and shear_cohesion min(R_a, R_b)^2 [N]. A bonded contact carries tension down to
// -normal strength and acts beyond touching; past it the contact ends (YADE erases the interaction); a shear failure
// (decided by the tangential model) breaks the bond for good. An unbonded contact ends as soon as the spheres part.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include "kernel/contact/contact_state.hpp"
#include "kernel/material.hpp"

namespace demcal::kernel {

struct YadeCohesiveNormal {
  struct Params {
    double normal_cohesion = 0.0;  ///< bond tensile strength [Pa] >= 0 (YADE: min of the materials' normalCohesion)
    double shear_cohesion = 0.0;   ///< bond shear strength [Pa] >= 0 (min of the materials' shearCohesion)
    void validate() const {
      if (!(normal_cohesion >= 0 && normal_cohesion < 1e15))
        throw std::invalid_argument("normal_cohesion must be in [0, 1e15) Pa, got " + std::to_string(normal_cohesion));
      if (!(shear_cohesion >= 0 && shear_cohesion < 1e15))
        throw std::invalid_argument("shear_cohesion must be in [0, 1e15) Pa, got " + std::to_string(shear_cohesion));
    }
  };
  struct Coeffs {
    double young_i = 0, young_j = 0;  ///< the two materials' E (ordered: sphere i's first) [Pa]
    double normal_cohesion = 0, shear_cohesion = 0;
  };
  static Coeffs mix(const Material& a, const Material& b, const Params& p) {
    return {a.young, b.young, p.normal_cohesion, p.shear_cohesion};
  }
  static constexpr int history_size = 3;  ///< [0]: 1 while bonded; [1], [2]: the bond's normal and shear strength [N]
  static constexpr bool beyond_contact = true;
  static constexpr bool velocity_free_at_rest = true;  ///< a linear spring, no damping
  static void swap_history(double*) {}

  /// The radius YADE gives body j: its own, or the sphere's for a wall (radius_j = 0).
  static double radius_j(const ContactGeometry& g) { return g.radius_j > 0 ? g.radius_j : g.radius_i; }
  static double kn(const Coeffs& c, const ContactGeometry& g) {
    const double ka = c.young_i * g.radius_i, kb = c.young_j * radius_j(g);
    return 2 * ka * kb / (ka + kb);
  }
  /// An upper bound of the gap a bond holds for radii up to r_max: N / kn <= sigma R_min / E_min.
  static double reach(const Coeffs& c, double r_max) {
    return c.normal_cohesion * r_max / std::min(c.young_i, c.young_j);
  }
  static bool acts(const Coeffs& c, const ContactGeometry& g, const double* h) {
    if (h[0] != 0.0) return -(kn(c, g) * g.dn) <= h[1];  // a bond holds until its tensile strength is passed
    return g.dn >= 0.0;
  }
  /// Bonds the contact (YADE's setCohesionNow) if the pair is cohesive; keeps its current forces.
  static void bond(const Coeffs& c, const ContactGeometry& g, double* h) {
    if (!(c.normal_cohesion > 0 || c.shear_cohesion > 0)) return;
    const double r = std::min(g.radius_i, radius_j(g));
    h[0] = 1.0;
    h[1] = c.normal_cohesion * r * r;
    h[2] = c.shear_cohesion * r * r;
  }
  static void break_bond(double* h) { h[0] = h[1] = h[2] = 0.0; }

  [[gnu::always_inline]] static inline NormalState force(const Coeffs& c, const ContactGeometry& g, double, double* h) {
    NormalState o;
    o.fn = kn(c, g) * g.dn;
    o.fn_crit = std::abs(o.fn);
    o.bonded = h[0] != 0.0;
    o.shear_adhesion = h[2];
    return o;
  }
};

}  // namespace demcal::kernel
