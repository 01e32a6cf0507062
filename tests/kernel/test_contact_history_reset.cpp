// forget_contact_history(): every contact restarts as if just formed. Two blocks (rigid clumps of four spheres in a
// square) stacked on an incline below the friction angle rest on the tangential springs of their contacts: the lower
// block's wall contacts and the upper block's sphere-pair contacts carry m g sin(alpha). With the springs forgotten,
// nothing holds either block along the slope at that instant: both start at g sin(alpha). The springs then load
// again and the stack comes back to rest. Kept, the next step leaves them at rest. (The incline is the plane z = 0
// with gravity tilted by alpha, as in test_incline.cpp.)
#include <catch2/catch.hpp>

#include <cmath>

#include "incline_scene.hpp"

using namespace demcal::kernel;

namespace {

constexpr double kFriction = 0.5;

struct Stack {
  Simulation sim;
  double dt = 0;
};

// Settled stack on the incline; body 0 below, body 1 on top of it.
void settle(Stack& st, double alpha) {
  Simulation& sim = st.sim;
  const auto scene = demcal::test::make_incline(sim, alpha, kFriction);
  sim.add_clump(scene.block, scene.grain, {0, 0, scene.r}, Quat::Identity());
  sim.add_clump(scene.block, scene.grain, {0, 0, 3 * scene.r}, Quat::Identity());  // each upper sphere on a lower one
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
  st.dt = sim.timestep();
  sim.step(long(0.05 / st.dt));
}

// Acceleration along the slope over the next step [m/s^2], of each body.
std::pair<double, double> next_step_acceleration(Stack& st) {
  const double v0 = st.sim.body(0).velocity.x(), v1 = st.sim.body(1).velocity.x();
  st.sim.step(1);
  return {(st.sim.body(0).velocity.x() - v0) / st.dt, (st.sim.body(1).velocity.x() - v1) / st.dt};
}

}  // namespace

TEST_CASE("forgotten contact histories: a stack held by friction on an incline starts at g sin(alpha), then rests again",
          "[kernel][contact]") {
  const double alpha = std::atan(kFriction) - 4.0 * M_PI / 180, free_fall = 9.81 * std::sin(alpha);
  Stack kept, forgotten;
  settle(kept, alpha);
  settle(forgotten, alpha);
  REQUIRE(std::abs(kept.sim.body(0).velocity.x()) < 1e-4);
  REQUIRE(std::abs(kept.sim.body(1).velocity.x()) < 1e-4);
  REQUIRE(std::abs(kept.sim.body(1).position.z() - 3e-3) < 1e-4);  // still stacked

  const auto [kept_low, kept_up] = next_step_acceleration(kept);
  forgotten.sim.forget_contact_history();
  const auto [forgot_low, forgot_up] = next_step_acceleration(forgotten);
  INFO("g sin(alpha) " << free_fall << "; kept: " << kept_low << ", " << kept_up << "; forgotten: " << forgot_low
                       << ", " << forgot_up);
  CHECK(std::abs(kept_low) < 0.1 * free_fall);
  CHECK(std::abs(kept_up) < 0.1 * free_fall);
  // the wall contacts' springs (the lower block) and the sphere pairs' (the upper block, held by the lower only)
  CHECK(forgot_low == Approx(free_fall).epsilon(0.05));
  CHECK(forgot_up == Approx(free_fall).epsilon(0.05));

  // the springs load again: the stack stops within an elastic slip, far below a sliding block's travel
  const double x0 = forgotten.sim.body(1).position.x();
  forgotten.sim.step(long(0.05 / forgotten.dt));
  CHECK(std::abs(forgotten.sim.body(0).velocity.x()) < 1e-4);
  CHECK(std::abs(forgotten.sim.body(1).velocity.x()) < 1e-4);
  CHECK(std::abs(forgotten.sim.body(1).position.x() - x0) < 1e-5);
  CHECK(std::abs(forgotten.sim.body(1).position.z() - 3e-3) < 1e-4);
}
