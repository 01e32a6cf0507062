// YADE's shear-box laws in the kernel (YadeCohesiveFrictional, local damping) against YADE's own single-contact
// traces (tests/data/yade_contact/, made by yade_scripts/single_contact.py with real YADE; the formulas in
// yade_scripts/YADE_LAWS.md): two spheres and a sphere on a box wall driven through approach, sliding and separation,
// bonded and not, bonds failing in tension and in shear; and a free sphere thrown on a box with YADE's damping.
// Forces equal YADE's to 1e-6 relative at every sampled step (the relative error of a vector: |kernel - YADE| over
// max(|YADE|, 1e-9 of its peak in the trace), as yade_scripts/check_single_contact.py measures it).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "kernel/simulation.hpp"
#include "yade_trace.hpp"

using namespace demcal::kernel;
using namespace demcal::test::yade_trace;
using Law = YadeCohesiveFrictional;
using json = nlohmann::json;

namespace {

bool is_cohesive(const json& m) { return m["type"] == "CohFrictMat" && m.value("is_cohesive", false); }

// The pair's inputs as YADE mixes them: tan(min(phi)), min of the cohesions when both materials are cohesive.
Law::Params pair_params(const json& a, const json& b) {
  Law::Params p;
  p.friction = std::tan(std::min(a["friction_angle"].get<double>(), b["friction_angle"].get<double>()));
  if (is_cohesive(a) && is_cohesive(b)) {
    p.normal_cohesion = std::min(a["normal_cohesion"].get<double>(), b["normal_cohesion"].get<double>());
    p.shear_cohesion = std::min(a["shear_cohesion"].get<double>(), b["shear_cohesion"].get<double>());
  }
  return p;
}

double replay(const std::string& name) { return demcal::test::yade_trace::replay<Law>(name, pair_params); }

}  // namespace

TEST_CASE("YADE laws: prescribed single contacts give YADE's forces and torques to 1e-6", "[kernel][yade-laws]") {
  for (const char* name : {"ss_frict", "ss_frict_cundall", "ss_bond_tension", "ss_bond_shear", "ss_bond_shear_tension",
                           "sb_frict"}) {
    const double e = replay(name);
    INFO(name << ": max relative error " << e);
    CHECK(e < 1e-6);
  }
}

TEST_CASE("YADE laws: a free sphere thrown on a box wall with local damping follows YADE's trajectory",
          "[kernel][yade-laws]") {
  const json p = read_params("sb_dynamic_damped");
  const Trace t = read_trace(kData + std::string("sb_dynamic_damped.csv"));
  const json& ms = p["materials"][p["moving"]["material"].get<std::string>()];
  const json& mw = p["materials"][p["fixed"]["material"].get<std::string>()];
  YadeLawSimulation sim;
  const int s = sim.add_material(material(ms)), w = sim.add_material(material(mw));
  sim.set_pair(s, s, pair_params(ms, ms));
  sim.set_pair(s, w, pair_params(ms, mw));
  sim.set_gravity(Vec3::Zero());
  const Vec3 c = vec(p["fixed"]["center"]), e = vec(p["fixed"]["extents"]);
  const int box = sim.add_wall(Wall::box(c - e, c + e, w));
  sim.add_sphere(vec(p["moving"]["pos"]), p["moving"]["radius"], s, vec(p["moving"]["vel0"]), vec(p["moving"]["angvel0"]));
  sim.set_timestep(p["dt"]);
  sim.set_local_damping(p["damping"]);
  const double peak_f = t.peak("b0_f_");
  double worst_x = 0, worst_f = 0;
  int contacts = 0;
  for (const auto& r : t.rows) {
    const long k = long(r.at("step"));
    if (k > 0 && sim.steps_done() < k) sim.step(k - sim.steps_done());
    // after k steps: positions x^k and the forces F^k computed from them (the trace's row k)
    worst_x = std::max(worst_x, (sim.body(0).position - vec(r, "b1_pos_")).norm() / vec(r, "b1_pos_").norm());
    if (k > 0) worst_f = std::max(worst_f, rel_error(sim.wall_force(box), vec(r, "b0_f_"), peak_f));
    contacts += r.at("real") == 1.0;
  }
  INFO("max relative error: position " << worst_x << ", force on the box " << worst_f);
  CHECK(contacts > 10);
  CHECK(worst_x < 1e-9);
  CHECK(worst_f < 1e-6);
}

TEST_CASE("YADE laws in the kernel's loops: bonds set on the contacts present hold tension up to cohesion R^2, then "
          "end for good", "[kernel][yade-laws]") {
  const double r = 2e-3, sigma = 3e4, V = 1e-3;
  YadeLawSimulation sim;
  Material heavy{2e7, 0.3, 1e12, "sand"};  // heavy: the bond cannot change the path, only the momentum a little
  const int a = sim.add_material(heavy);
  Law::Params p;
  p.friction = 0.5;
  p.normal_cohesion = sigma;
  p.shear_cohesion = sigma;
  sim.set_pair(a, a, p);
  sim.set_gravity(Vec3::Zero());
  sim.add_sphere({-r + 1e-7, 0, 0}, r, a);
  sim.add_sphere({r - 1e-7, 0, 0}, r, a);
  sim.add_sphere({0, 0.1, 0}, r, a);  // far away: no contact, no bond
  sim.set_timestep(1e-5);
  sim.step(1);
  sim.bond_contacts_now();
  sim.step(1);
  sim.set_body_velocity(0, {-0.5 * V, 0, 0}, Vec3::Zero());
  sim.set_body_velocity(1, {0.5 * V, 0, 0}, Vec3::Zero());
  const double m = sim.body(1).mass, kn = 2e7 * r;  // kn = E R for equal spheres
  double max_pull = 0, gap_at_end = 0, v_prev = sim.body(1).velocity.x();
  for (int k = 0; k < 2000; ++k) {
    sim.step(1);
    const double v = sim.body(1).velocity.x(), f = m * (v - v_prev) / sim.timestep();
    v_prev = v;
    const double gap = sim.body(1).position.x() - sim.body(0).position.x() - 2 * r;
    if (f < 0) max_pull = std::max(max_pull, -f);
    if (max_pull > 0 && f == 0.0 && gap_at_end == 0.0) gap_at_end = gap;
  }
  // tension up to the strength sigma R^2, reached at the gap sigma R^2 / kn, and nothing after
  CHECK(max_pull <= sigma * r * r * (1 + 1e-9));
  CHECK(max_pull > 0.99 * sigma * r * r);
  CHECK(gap_at_end == Approx(sigma * r * r / kn).epsilon(0.02));
  // pushed back together, the pair touches again unbonded: no tension any more
  sim.set_body_velocity(0, {0.5 * V, 0, 0}, Vec3::Zero());
  sim.set_body_velocity(1, {-0.5 * V, 0, 0}, Vec3::Zero());
  sim.step(long(2 * gap_at_end / V / sim.timestep()) + 20);
  sim.set_body_velocity(0, {-0.5 * V, 0, 0}, Vec3::Zero());
  sim.set_body_velocity(1, {0.5 * V, 0, 0}, Vec3::Zero());
  double pull_after = 0;
  v_prev = sim.body(1).velocity.x();
  for (int k = 0; k < 200; ++k) {
    sim.step(1);
    const double v = sim.body(1).velocity.x(), f = m * (v - v_prev) / sim.timestep();
    v_prev = v;
    pull_after = std::max(pull_after, -f);
  }
  CHECK(pull_after <= 1e-12 * sigma * r * r);
}
