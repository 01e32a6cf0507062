// Removing bodies (BasicSimulation::remove_bodies_if) with exact removals on (set_exact_removal, as the silo case
// runs): the bodies go as if they had gone before the last force evaluation. A removed body that touched nothing changes nothing else, to the bit; one that touched others leaves
// them with exactly the loads of their other contacts; neither evaluates the forces of the rest again (the silo's
// removal below the outlet used to move the whole bed a little at every removal: examples/crosscheck/README.md).
#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

#include "kernel/clump.hpp"
#include "kernel/simulation.hpp"

using namespace demcal::kernel;
using YadeSim = BasicSimulation<YadeHertzMindlin>;  // the law the silo cross-check runs

namespace {

const Material kGrain{1e7, 0.3, 2500, "grain"};

// A column of clumps settling on a floor, and one free sphere falling far from them.
YadeSim pile(bool with_loner) {
  YadeSim sim;
  const int g = sim.add_material(kGrain);
  sim.set_pair(g, g, {{0.5}, {0.4}});
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, g));
  const int t = sim.add_clump_template(make_clump_template({{-0.0008, 0, 0}, {0.0008, 0, 0}}, {0.001, 0.001}, 2500, 60));
  for (int k = 0; k < 12; ++k)
    sim.add_clump(t, g, Vec3(0.0005 * (k % 3) - 0.0005, 0.0004 * (k % 2), 0.0015 + 0.0022 * k));
  if (with_loner) sim.add_sphere(Vec3(0.05, 0.05, 0.03), 0.001, g);
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
  sim.set_exact_removal(true);
  return sim;
}

std::vector<Vec3> positions(const YadeSim& sim) {
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < sim.num_bodies(); ++i) x.push_back(sim.body(i).position);
  return x;
}

double largest_gap(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double gap = 0;
  for (std::size_t i = 0; i < a.size(); ++i) gap = std::max(gap, (a[i] - b[i]).norm());
  return gap;
}

// The column's largest position difference 1500 steps after a contact-free removal, from a run without it.
double gap_after_removal(bool exact) {
  YadeSim kept = pile(true), removed = pile(true);
  kept.set_exact_removal(exact);
  removed.set_exact_removal(exact);
  kept.step(3000);  // the column's clumps land and collide (contacts, damping); the loner still falls
  removed.step(3000);
  REQUIRE(removed.remove_bodies_if([](const BodyState& b) { return b.position.x() > 0.04; }).count == 1);
  kept.step(1500);
  removed.step(1500);
  std::vector<Vec3> x = positions(kept);
  x.pop_back();  // the loner
  return largest_gap(positions(removed), x);
}

}  // namespace

TEST_CASE("removing a body that touches nothing leaves every other body's motion, to round-off", "[kernel][removal]") {
  // the neighbour list built anew after the removal sums in another order: round-off, not a change of the motion;
  // evaluating every force again instead (exact removals off) moves the column measurably
  const double exact = gap_after_removal(true), refreshed = gap_after_removal(false);
  INFO("largest gap: exact removal " << exact << " m, forces evaluated again " << refreshed << " m");
  CHECK(exact < 1e-12);
  CHECK(refreshed > 100 * exact);
}

namespace {
}  // namespace

TEST_CASE("removing the top clump of a settled column: the floor carries one clump's weight less", "[kernel][removal]") {
  // the removed clump's contacts leave its neighbours' loads (kept valid, no evaluation of the rest again); the column
  // settles again under one clump less
  YadeSim sim = pile(false);
  sim.step(20000);  // settled
  const std::size_t n = sim.num_bodies();
  double top = 0;
  for (std::size_t i = 0; i < n; ++i) top = std::max(top, sim.body(i).position.z());
  const double g = 9.81;
  const double load_before = -sim.wall_force(0).z();  // the floor carries the column's weight (the particles push down)
  const RemovalResult r = sim.remove_bodies_if([top](const BodyState& b) { return b.position.z() == top; });
  REQUIRE(r.count == 1);
  sim.step(20000);  // settled again under one clump less
  CHECK(load_before == Approx(double(n) * r.mass * g).epsilon(2e-3));
  CHECK(-sim.wall_force(0).z() == Approx(load_before - r.mass * g).epsilon(2e-3));
}

