// Normal sub-model: YADE's Hertz normal force with viscous damping (Ip2_FrictMat_FrictMat_MindlinPhys with betan +
// Law2_ScGeom_MindlinPhys_Mindlin, no adhesion), as yade_scripts/silo.py configures it; for cross-checks against YADE.
//   Fn = kno dn^1.5 - cn vn,  kno = 4/3 E* sqrt(R*),  cn = 2 betan sqrt(m* kn),  kn = 3/2 kno sqrt(dn)
// which is HertzNormal's force with betan = sqrt(5/6) |beta(e)| (silo.py's damping_ratio), except that the total force
// is never attractive: where the damping would pull, Fn = 0 (HertzNormal lets it pull, as LIGGGHTS without
// limitForce). vn is the plain relative velocity along n, the kernel's (measured: YADE 2023.02a's normal damping does
// not take the alpha = (r_i + r_j) / (r_i + r_j - dn) its shear increment takes, see YadeMindlinTangential).
// Checked against YADE's own single-contact trace (tests/kernel/test_yade_mindlin.cpp, tests/data/yade_contact/hm_pair).
#pragma once
#include "kernel/contact/contact_state.hpp"
#include "kernel/contact/hertz_normal.hpp"
#include "kernel/material.hpp"

namespace demcal::kernel {

struct YadeMindlinNormal {
  using Params = HertzNormal::Params;
  using Coeffs = HertzNormal::Coeffs;
  static Coeffs mix(const Material& a, const Material& b, const Params& p) { return HertzNormal::mix(a, b, p); }
  static constexpr int history_size = 0;
  static constexpr bool beyond_contact = false;
  static void swap_history(double*) {}

  [[gnu::always_inline]] static inline NormalState force(const Coeffs& c, const ContactGeometry& g, double vn, double* h) {
    NormalState o = HertzNormal::force(c, g, vn, h);
    if (o.fn < 0.0) o.fn = 0.0;  // YADE: "no attraction force should be permitted if particles are non-adhesive"
    o.fn_crit = o.fn;
    return o;
  }
};

}  // namespace demcal::kernel
