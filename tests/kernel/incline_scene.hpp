// An incline for the kernel's friction tests: the plane z = 0 with gravity tilted by alpha (equivalent to a tilted
// plane, and exact), a grain material and a stiff wall material with friction mu between grains and against the
// wall, and the template of a flat-bottomed block (a rigid clump of four spheres of radius r in a square of side 2h).
#pragma once
#include "kernel/simulation.hpp"

#include <cmath>

namespace demcal::test {

struct InclineScene {
  static constexpr double r = 1e-3, h = 2e-3;  // block sphere radius, half the square's side [m]
  int grain = 0;                               // the blocks' material
  int block = 0;                               // the block's clump template
};

inline InclineScene make_incline(kernel::Simulation& sim, double alpha, double mu) {
  using namespace kernel;
  InclineScene scene;
  scene.grain = sim.add_material({1e8, 0.3, 1000, ""});
  const int wall = sim.add_material({2e11, 0.3, 7800, ""});
  sim.set_pair(scene.grain, scene.grain, {{0.5}, {mu}, {0.0}});
  sim.set_pair(scene.grain, wall, {{0.5}, {mu}, {0.0}});
  sim.set_gravity(9.81 * Vec3(std::sin(alpha), 0, -std::cos(alpha)));
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, wall));
  const double r = InclineScene::r, h = InclineScene::h;
  scene.block = sim.add_clump_template(
      make_clump_template({{-h, -h, 0}, {h, -h, 0}, {-h, h, 0}, {h, h, 0}}, {r, r, r, r}, 1000, 80));
  return scene;
}

}  // namespace demcal::test
