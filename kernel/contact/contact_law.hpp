// A contact law = a normal, a tangential and a rolling sub-model composed at compile time; the law is the only thing
// the kernel's pair and wall loops see. Each sub-model (one header each, after LAMMPS GRANULAR's gran_sub_mod_* and
// MercuryDPM's species slots) declares:
//   Params                     its per-material-pair inputs (fields documented there; validate() names a bad one),
//   Coeffs, mix(a, b, params)  its precomputed per-pair-type constants and how two materials mix into them,
//   history_size, swap_history its per-contact state (doubles) and how it transforms when i and j trade places,
//   beyond_contact, reach      (normal models) whether and how far beyond touching it acts (adhesion),
// and its force. A new model is a new header and an alias below, plus one explicit instantiation in simulation.cpp.
#pragma once
#include <algorithm>
#include "kernel/contact/contact_state.hpp"
#include "kernel/contact/hertz_normal.hpp"
#include "kernel/contact/jkr_normal.hpp"
#include "kernel/contact/mindlin_tangential.hpp"
#include "kernel/contact/rolling_edem_cdt.hpp"
#include "kernel/contact/yade_cohesive_normal.hpp"
#include "kernel/contact/yade_incremental_tangential.hpp"
#include "kernel/contact/yade_mindlin_normal.hpp"
#include "kernel/contact/yade_mindlin_tangential.hpp"

namespace demcal::kernel {

template <class Normal, class Tangential, class Rolling>
struct ComposedLaw {
  /// The pair's inputs: every sub-model's fields side by side (p.restitution, p.friction, p.rolling_friction, ...),
  /// built from the sub-models' own: {{.restitution = 0.5}, {.friction = 0.3}, {.rolling_friction = 0.01}}.
  struct Params : Normal::Params, Tangential::Params, Rolling::Params {
    Params() = default;
    Params(const typename Normal::Params& n, const typename Tangential::Params& t,
           const typename Rolling::Params& r = {})
        : Normal::Params(n), Tangential::Params(t), Rolling::Params(r) {}
    void validate() const {
      Normal::Params::validate();
      Tangential::Params::validate();
      Rolling::Params::validate();
    }
  };
  struct Coeffs {
    typename Normal::Coeffs normal;
    typename Tangential::Coeffs tangential;
    typename Rolling::Coeffs rolling;
  };
  /// Constants of the ordered material pair (a = sphere i's material, b = j's or the wall's).
  static Coeffs mix(const Material& a, const Material& b, const Params& p) {
    return {Normal::mix(a, b, p), Tangential::mix(a, b, p), Rolling::mix(a, b, p)};
  }

  static constexpr int normal_history = Normal::history_size;
  static constexpr int tangential_history = Tangential::history_size;
  static constexpr int history_size = Normal::history_size + Tangential::history_size + Rolling::history_size;
  static void swap_history(double* h) {
    Normal::swap_history(h);
    Tangential::swap_history(h + normal_history);
    Rolling::swap_history(h + normal_history + tangential_history);
  }

  /// Whether the law acts at negative overlap (then the kernel calls acts() and reach()).
  static constexpr bool beyond_contact = Normal::beyond_contact;
  /// The largest gap [m] at which a contact of effective radius r_star can still act (0 without adhesion).
  static double reach(const Coeffs& c, double r_star) {
    if constexpr (beyond_contact) return Normal::reach(c.normal, r_star); else return 0.0;
  }
  /// Whether a contact with this geometry and history acts now (always true in contact, dn > 0).
  [[gnu::always_inline]] static inline bool acts(const Coeffs& c, const ContactGeometry& g, const double* h) {
    if constexpr (beyond_contact) return Normal::acts(c.normal, g, h); else return g.dn > 0.0;
  }

  /// Whether compute() reads ContactKinematics::omega_i_norm / omega_j_norm (the kernel skips that pass if not).
  static constexpr bool uses_omega_norm = Rolling::uses_omega_norm;
  /// Where a wall contact's tangential force acts: at the middle of the overlap (YADE) or at the wall (default).
  static constexpr bool lever_at_overlap_middle = [] {
    if constexpr (requires { Tangential::lever_at_overlap_middle; }) return Tangential::lever_at_overlap_middle;
    else return false;
  }();
  /// Whether the tangential model reads the centres' velocities (ContactKinematics::v_i, v_j; skipped otherwise).
  static constexpr bool uses_centre_velocities = [] {
    if constexpr (requires { Tangential::uses_centre_velocities; }) return Tangential::uses_centre_velocities;
    else return false;
  }();
  /// Whether a force evaluation that does not advance time (dt = 0) depends on the velocities (viscous damping,
  /// rolling torques along omega): if not, a wall's new velocity changes no force until the next step, and the kernel
  /// skips the re-evaluation (a sub-model says `velocity_free_at_rest = true`; by default it is assumed to depend).
  static constexpr bool forces_depend_on_velocity = [] {
    auto free = []<class M>() {
      if constexpr (requires { M::velocity_free_at_rest; }) return M::velocity_free_at_rest; else return false;
    };
    return !(free.template operator()<Normal>() && free.template operator()<Tangential>() &&
             free.template operator()<Rolling>());
  }();
  /// Whether the law has bonds that a driver sets (bond_now below).
  static constexpr bool has_bonds =
      requires(const typename Normal::Coeffs& nc, const ContactGeometry& g, double* h) { Normal::bond(nc, g, h); };

  /// One contact: c (pair constants), g (geometry), k (kinematics), h (history, history_size doubles, in/out);
  /// bond_now: bond this contact now (laws with bonds; YADE's setCohesionNow).
  [[gnu::always_inline]] static inline ContactResult compute(const Coeffs& c, const ContactGeometry& g,
                                                             const ContactKinematics& k, double* h, double dt,
                                                             bool wall, bool bond_now = false) {
    ContactResult r;
    if constexpr (has_bonds) {
      if (bond_now) Normal::bond(c.normal, g, h);
    }
    const double vn = k.v_rel.dot(g.n);
    NormalState nrm = Normal::force(c.normal, g, vn, h);
    const Vec3 vt = k.v_rel - vn * g.n;
    const Vec3 ft = Tangential::force(c.tangential, g, k, vt, nrm, h + normal_history, dt, wall);
    if constexpr (has_bonds) {
      if (nrm.bond_failed) Normal::break_bond(h);
    }
    r.force_i = nrm.fn * g.n + ft;
    // tangential force acts at the contact point: lever -lever_i n from i, +lever_j n from j (force -ft)
    const Vec3 nxft = g.n.cross(ft);
    r.torque_i = -g.lever_i * nxft;
    r.torque_j = -g.lever_j * nxft;
    Rolling::torque(c.rolling, nrm, g, k, r.torque_i, r.torque_j, wall);
    return r;
  }
};

/// Hertz-Mindlin (no slip) with EDEM's constant directional torque rolling friction: the seed's EDEM model.
using HertzMindlinEdem = ComposedLaw<HertzNormal, MindlinTangential, EdemCdtRolling>;
/// Hertz-Mindlin without rolling friction (the peer case; LIGGGHTS "hertz + tangential history").
using HertzMindlin = ComposedLaw<HertzNormal, MindlinTangential, NoRolling>;
/// JKR adhesion (EDEM "Hertz-Mindlin with JKR cohesion") with Mindlin friction and EDEM rolling friction.
using JkrMindlinEdem = ComposedLaw<JkrNormal, MindlinTangential, EdemCdtRolling>;
/// YADE's linear law with fragile cohesive bonds, as its shear box uses it (CohesionMoment for particle pairs;
/// CundallStrack for walls, the same without a bond). No rolling resistance (momentRotationLaw = False).
using YadeCohesiveFrictional = ComposedLaw<YadeCohesiveNormal, YadeIncrementalTangential, NoRolling>;
/// YADE's Hertz-Mindlin as its silo script uses it (Ip2_FrictMat_FrictMat_MindlinPhys with betan = betas,
/// Law2_ScGeom_MindlinPhys_Mindlin without rolling moment), for cross-checks that run one law in both codes.
using YadeHertzMindlin = ComposedLaw<YadeMindlinNormal, YadeMindlinTangential, NoRolling>;

}  // namespace demcal::kernel
