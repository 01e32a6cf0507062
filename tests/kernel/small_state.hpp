// The small kernel state of the checkpoint readers' tests: 20 spheres settling on a plane for 200 steps, saved as a
// checkpoint holds it. Its maker gives the same simulation (materials, walls, bodies) to load a state into.
#pragma once
#include <sstream>
#include <string>

#include "kernel/simulation.hpp"

namespace demcal::test {

inline kernel::Simulation small_state_simulation() {
  using namespace kernel;
  Simulation sim;
  const int a = sim.add_material({1e8, 0.3, 1500, "grain"});
  sim.set_pair(a, a, {{0.5}, {0.4}, {0.01}});
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, a));
  for (int k = 0; k < 20; ++k) sim.add_sphere({0.003 * (k % 5), 0.003 * (k / 5), 0.002 + 0.0001 * k}, 1e-3, a);
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
  return sim;
}

/// The saved state of small_state_simulation() after 200 steps.
inline std::string small_saved_state() {
  kernel::Simulation sim = small_state_simulation();
  sim.step(200);
  std::ostringstream os;
  sim.save_state(os);
  return os.str();
}

}  // namespace demcal::test
