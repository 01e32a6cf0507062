// Tangential sub-model: YADE's incremental Mindlin shear force (Law2_ScGeom_MindlinPhys_Mindlin with betas), as
// yade_scripts/silo.py configures it; for cross-checks against YADE. Differs from MindlinTangential (EDEM, LIGGGHTS:
// the spring is the total tangential displacement times the current stiffness St = 8 G* a) in that YADE integrates
// the force itself with the current (tangent) stiffness:
//   F_el turns with the contact frame (yade_scgeom.hpp: yade_rotated_shear), then
//   F_el -= ks dt v_s,  ks = 8 G* sqrt(R* dn) (Mindlin's tangent stiffness, G* = 1/((2-nu_a)/G_a + (2-nu_b)/G_b) as
//   in MindlinTangential), v_s the tangential part of YADE's relative velocity (yade_incident_velocity: the centres'
//   relative velocity scaled by alpha = (r_i + r_j) / (r_i + r_j - dn), the spins with the full radii; the normal
//   damping, however, sees the plain relative velocity: both measured on YADE 2023.02a's trace);
//   Coulomb: if |F_el| > tan(phi) Fn (Fn after damping, never attractive) the spring is scaled back to the limit and
//   the force is F_el (no damping while sliding); else F = F_el - cs v_s with cs = 2 betas sqrt(m* ks), betas = betan.
// History: F_el (the elastic shear force on i) and the last normal (zero: a new contact).
// Measured, not read: older YADE sources mix kso = 2 sqrt(4 R*) G / (2 - nu) with ARITHMETIC means of G and nu, but the
// trace of the installed YADE 2023.02a (tests/data/yade_contact/hm_pair, unlike spheres) has ks / sqrt(dn) =
// 876514.62 N/m^1.5 = 8 G* sqrt(R*) to 16 digits (the arithmetic form gives 917646.6, 4.7 % more).
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>
#include "kernel/contact/contact_state.hpp"
#include "kernel/contact/yade_scgeom.hpp"
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct YadeMindlinTangential {
  struct Params {
    double friction = 0.5;  ///< tan(phi) of the pair [-] >= 0 (YADE: tan(min(phi_a, phi_b)), or a MatchMaker's)
    void validate() const {
      if (!(friction >= 0 && std::isfinite(friction)))
        throw std::invalid_argument("friction must be finite and >= 0, got " + std::to_string(friction));
    }
  };
  struct Coeffs {
    double ks_factor = 0;    ///< 8 G*: ks = ks_factor sqrt(R* dn) [Pa]
    double tan_phi = 0;
    double cs_over_cn = 0;   ///< sqrt(ks / kn) = sqrt(ks_factor / (2 E*)): cs = cn sqrt(ks / kn) (betas = betan)
  };
  static Coeffs mix(const Material& a, const Material& b, const Params& p) {
    const double ks_factor = 8.0 * effective_shear(a, b);
    return {ks_factor, p.friction, std::sqrt(ks_factor / (2.0 * effective_young(a, b)))};
  }
  static constexpr int history_size = 6;  ///< [0..2]: the elastic shear force on i [N]; [3..5]: the last normal
  static void swap_history(double* h) {
    for (int k = 0; k < 6; ++k) h[k] = -h[k];
  }
  static constexpr bool lever_at_overlap_middle = true;  ///< YADE's contact point, wall contacts too
  static constexpr bool uses_centre_velocities = true;

  [[gnu::always_inline]] static inline Vec3 force(const Coeffs& c, const ContactGeometry& g, const ContactKinematics& k,
                                                  const Vec3&, NormalState& nrm, double* h, double dt, bool wall) {
    const Vec3& n = g.n;
    const Vec3 v = yade_incident_velocity(g, k, wall);
    const Vec3 vs = v - n.dot(v) * n;
    Vec3 f = yade_rotated_shear(h, n, k, dt);
    // nrm.contact_radius = sqrt(R* dn)
    const double ks = c.ks_factor * nrm.contact_radius;
    f -= (ks * dt) * vs;
    const double cap = nrm.fn * c.tan_phi;
    Vec3 ft;
    const double f2 = f.squaredNorm();
    if (f2 > cap * cap) {
      f *= cap / std::sqrt(f2);
      ft = f;
    } else {
      ft = f - (nrm.damp_prefactor * c.cs_over_cn) * vs;  // cs = 2 betas sqrt(m* ks), cn = 2 betan sqrt(m* kn)
    }
    yade_store_shear(h, f, n);
    return ft;
  }
};

}  // namespace demcal::kernel
