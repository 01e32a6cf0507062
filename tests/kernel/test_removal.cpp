// Removing bodies (BasicSimulation::remove_bodies_if): the bodies go as if they had gone before the last force
// evaluation. A removed body that touched nothing changes nothing else, to the bit; one that touched others leaves
// them with exactly the loads of their other contacts; neither evaluates the forces of the rest again (the silo's
// removal below the outlet used to move the whole bed a little at every removal: examples/crosscheck/README.md).
#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

#include "kernel/clump.hpp"
#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {

const Material kGrain{1e7, 0.3, 2500, "grain"};

// A column of clumps settling on a floor, and one free sphere falling far from them.
Simulation pile(bool with_loner) {
  Simulation sim;
  const int g = sim.add_material(kGrain);
  sim.set_pair(g, g, {{0.5}, {0.4}, {0.01}});
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, g));
  const int t = sim.add_clump_template(make_clump_template({{-0.0008, 0, 0}, {0.0008, 0, 0}}, {0.001, 0.001}, 2500, 60));
  for (int k = 0; k < 12; ++k)
    sim.add_clump(t, g, Vec3(0.0005 * (k % 3) - 0.0005, 0.0004 * (k % 2), 0.0015 + 0.0022 * k));
  if (with_loner) sim.add_sphere(Vec3(0.05, 0.05, 0.03), 0.001, g);
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
  return sim;
}

std::vector<Vec3> positions(const Simulation& sim) {
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < sim.num_bodies(); ++i) x.push_back(sim.body(i).position);
  return x;
}

}  // namespace

TEST_CASE("removing a body that touches nothing leaves every other body's motion to the bit", "[kernel][removal]") {
  Simulation kept = pile(true), removed = pile(true);
  kept.step(400);
  removed.step(400);
  const RemovalResult r = removed.remove_bodies_if([](const BodyState& b) { return b.position.x() > 0.04; });
  REQUIRE(r.count == 1);
  kept.step(1500);
  removed.step(1500);
  std::vector<Vec3> x = positions(kept);
  x.pop_back();  // the loner
  CHECK(positions(removed) == x);
}

TEST_CASE("removing the top clump of a settled column: the floor carries one clump's weight less", "[kernel][removal]") {
  // the removed clump's contacts leave its neighbours' loads (kept valid, no evaluation of the rest again); the column
  // settles again under one clump less
  Simulation sim = pile(false);
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
