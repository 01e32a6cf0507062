// Tangential sub-model: YADE's incremental shear force (Law2_ScGeom_FrictPhys_CundallStrack, and
// Law2_ScGeom6D_CohFrictPhys_CohesionMoment's shear part), as yade_scripts/YADE_LAWS.md documents it:
//   the stored shear force F turns with the contact frame (F -= F x (n_old x n), then F -= F x ((dt/2)
//   (n_old . (w_i + w_j)) n_old)), then F -= ks dt v_t, v_t the tangential part of YADE's relative velocity
//   (yade_scgeom.hpp's yade_incident_velocity);
//   ks = 2 (E_a R_a nu_a)(E_b R_b nu_b) / (E_a R_a nu_a + E_b R_b nu_b): YADE's "poisson" is ks/kn, not a Poisson
//   ratio;
//   cap max(0, S + Fn tan(phi)) with S the bond's shear strength; passing it breaks an intact bond (the cap is then
//   max(0, Fn tan(phi)) in the same step) and, with Fn < 0, cancels the normal force for that step.
// The force acts at the middle of the overlap (wall contacts too: ComposedLaw asks lever_at_overlap_middle).
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include "kernel/contact/contact_state.hpp"
#include "kernel/contact/yade_scgeom.hpp"
#include "kernel/material.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

struct YadeIncrementalTangential {
  struct Params {
    double friction = 0.5;  ///< tan(phi) of the pair [-] >= 0 (YADE: tan(min(phi_a, phi_b)))
    void validate() const {
      if (!(friction >= 0 && std::isfinite(friction)))
        throw std::invalid_argument("friction must be finite and >= 0, got " + std::to_string(friction));
    }
  };
  struct Coeffs {
    double ks_i = 0, ks_j = 0;  ///< E nu of the two materials (ordered: sphere i's first) [Pa]
    double tan_phi = 0;
  };
  static Coeffs mix(const Material& a, const Material& b, const Params& p) {
    return {a.young * a.poisson, b.young * b.poisson, p.friction};
  }
  static constexpr int history_size = 6;  ///< [0..2]: the shear force on i [N]; [3..5]: the last normal (0: new)
  static void swap_history(double* h) {
    for (int k = 0; k < 6; ++k) h[k] = -h[k];
  }
  static constexpr bool lever_at_overlap_middle = true;
  static constexpr bool uses_centre_velocities = true;
  static constexpr bool velocity_free_at_rest = true;  ///< velocities enter only as dt * v (nothing at dt = 0)

  [[gnu::always_inline]] static inline Vec3 force(const Coeffs& c, const ContactGeometry& g, const ContactKinematics& k,
                                                  const Vec3&, NormalState& nrm, double* h, double dt, bool wall) {
    const Vec3& n = g.n;
    Vec3 f = yade_rotated_shear(h, n, k, dt);
    const Vec3 v = yade_incident_velocity(g, k, wall);  // i relative to j, as YADE computes it
    const double rj = wall ? g.radius_i : g.radius_j;
    const Vec3 inc = dt * (v - n.dot(v) * n);
    const double ka = c.ks_i * g.radius_i, kb = c.ks_j * rj;
    const double ks = (ka != 0.0 && kb != 0.0) ? 2 * ka * kb / (ka + kb) : 0.0;
    f -= ks * inc;
    const double fs = f.norm();
    double cap = std::max(0.0, nrm.shear_adhesion + nrm.fn * c.tan_phi);
    if (fs > cap) {
      if (nrm.bonded) {
        nrm.bond_failed = true;
        cap = std::max(0.0, nrm.fn * c.tan_phi);
      }
      f *= cap / fs;
      if (nrm.fn < 0) nrm.fn = 0;
    }
    yade_store_shear(h, f, n);
    return f;
  }
};

}  // namespace demcal::kernel
