// What YADE's ScGeom gives its incremental shear laws, shared by YadeIncrementalTangential (the shear box's laws) and
// YadeMindlinTangential (the silo's Hertz-Mindlin), both checked against YADE's own single-contact traces
// (tests/kernel/test_yade_laws.cpp, test_yade_mindlin.cpp):
// - yade_rotated_shear (ScGeom::rotate): a stored shear vector (yade_store_shear) turned with the contact frame,
//   F -= F x (n_old x n), then F -= F x ((dt/2) (n_old . (w_i + w_j)) n_old); zero for a new contact;
// - yade_incident_velocity (ScGeom::getIncidentVel with the "granular ratcheting" correction): the velocity of sphere
//   i relative to j,
//   sphere pairs: alpha (v_i - v_j) - w_i x (r_i n) - w_j x (r_j n),  alpha = (r_i + r_j) / (r_i + r_j - dn)
//   (the centres' relative velocity scaled to the contact, the spins with the full radii);
//   walls: the velocity of the sphere's point at r_i - dn/2 relative to the wall.
#pragma once
#include "kernel/contact/contact_state.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

/// h: the stored vector (3 doubles) then the contact normal it was stored with (3 doubles; zero: a new contact).
[[gnu::always_inline]] inline Vec3 yade_rotated_shear(const double* h, const Vec3& n, const ContactKinematics& k,
                                                      double dt) {
  const Vec3 n_old(h[3], h[4], h[5]);
  if (!(n_old.squaredNorm() > 0.0)) return Vec3::Zero();
  Vec3 f(h[0], h[1], h[2]);
  f -= f.cross(n_old.cross(n));
  f -= f.cross((0.5 * dt * n_old.dot(k.omega_i + k.omega_j)) * n_old);
  return f;
}

/// Stores a shear vector and the normal it belongs to, in the layout yade_rotated_shear reads.
[[gnu::always_inline]] inline void yade_store_shear(double* h, const Vec3& f, const Vec3& n) {
  h[0] = f.x(); h[1] = f.y(); h[2] = f.z();
  h[3] = n.x(); h[4] = n.y(); h[5] = n.z();
}

[[gnu::always_inline]] inline Vec3 yade_incident_velocity(const ContactGeometry& g, const ContactKinematics& k,
                                                          bool wall) {
  const Vec3& n = g.n;
  if (wall) return k.v_i - k.omega_i.cross((g.radius_i - 0.5 * g.dn) * n) - k.v_j;
  const double alpha = (g.radius_i + g.radius_j) / (g.radius_i + g.radius_j - g.dn);
  return alpha * (k.v_i - k.v_j) - k.omega_i.cross(g.radius_i * n) - k.omega_j.cross(g.radius_j * n);
}

}  // namespace demcal::kernel
