// A contact law = a normal, a tangential and a rolling sub-model composed at compile time. A new law is a new
// alias (or a new sub-model file plus an alias), plus one explicit instantiation of BasicSimulation in a .cpp.
#pragma once
#include "kernel/contact/geometry.hpp"
#include "kernel/contact/hertz_normal.hpp"
#include "kernel/contact/mindlin_tangential.hpp"
#include "kernel/contact/rolling_edem_cdt.hpp"

namespace demcal::kernel {

template <class Normal, class Tangential, class Rolling>
struct ComposedLaw {
  /// Whether compute() reads ContactKinematics::omega_i_norm / omega_j_norm (the kernel skips that pass if not).
  static constexpr bool uses_omega_norm = Rolling::uses_omega_norm;
  /// One contact: g (geometry, dn > 0), k (kinematics), c (pair constants), s (tangential history, in/out).
  [[gnu::always_inline]] static inline ContactResult compute(const PairCoeffs& c, const ContactGeometry& g, const ContactKinematics& k,
                                      Vec3& s, double dt, bool wall) {
    ContactResult r;
    const double vn = k.v_rel.dot(g.n);
    const NormalOut nrm = Normal::force(c, g.dn, g.r_star, g.m_star, vn);
    const double fn = nrm.fn;
    const Vec3 vt = k.v_rel - vn * g.n;
    const Vec3 ft = Tangential::force(c, g.n, vt, nrm, s, dt);
    r.force_i = fn * g.n + ft;
    // tangential force acts at the contact point: lever -lever_i n from i, +lever_j n from j (force -ft)
    const Vec3 nxft = g.n.cross(ft);
    r.torque_i = -g.lever_i * nxft;
    r.torque_j = -g.lever_j * nxft;
    Rolling::torque(c, fn, g.radius_i, g.radius_j, k, r.torque_i, r.torque_j, wall);
    return r;
  }
};

/// Hertz-Mindlin (no slip) with EDEM's constant directional torque rolling friction: the seed's EDEM model.
using HertzMindlinEdem = ComposedLaw<HertzNormal, MindlinTangential, EdemCdtRolling>;
/// Hertz-Mindlin without rolling friction (the peer case; LIGGGHTS "hertz + tangential history").
using HertzMindlin = ComposedLaw<HertzNormal, MindlinTangential, NoRolling>;

}  // namespace demcal::kernel
