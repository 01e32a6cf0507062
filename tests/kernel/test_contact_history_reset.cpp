// forget_contact_history(): every contact restarts as if just formed. Two blocks (rigid clumps of four spheres in a
// square) stacked on an incline below the friction angle rest on the tangential springs of their contacts: the lower
// block's wall contacts and the upper block's sphere-pair contacts carry m g sin(alpha). With the springs forgotten,
// nothing holds either block along the slope at that instant: both start at g sin(alpha). The springs then load
// again and the stack comes back to rest. Kept, the next step leaves them at rest. (The incline is the plane z = 0
// with gravity tilted by alpha, as in test_incline.cpp.)
#include <catch2/catch.hpp>

#include <cmath>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {

struct Stack {
  Simulation sim;
  double dt = 0;
};

// Settled stack on an incline 4 deg below the friction angle; body 0 below, body 1 on top of it.
void settle(Stack& st, double alpha) {
  Simulation& sim = st.sim;
  const double mu = 0.5;
  const int a = sim.add_material({1e8, 0.3, 1000, ""});
  const int w = sim.add_material({2e11, 0.3, 7800, ""});
  sim.set_pair(a, a, {{0.5}, {mu}, {0.0}});
  sim.set_pair(a, w, {{0.5}, {mu}, {0.0}});
  sim.set_gravity(9.81 * Vec3(std::sin(alpha), 0, -std::cos(alpha)));
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, w));
  const double r = 1e-3, h = 2e-3;
  const int tmpl = sim.add_clump_template(
      make_clump_template({{-h, -h, 0}, {h, -h, 0}, {-h, h, 0}, {h, h, 0}}, {r, r, r, r}, 1000, 80));
  sim.add_clump(tmpl, a, {0, 0, r}, Quat::Identity());
  sim.add_clump(tmpl, a, {0, 0, 3 * r}, Quat::Identity());  // each upper sphere on a lower one
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
  const double alpha = (std::atan(0.5) * 180 / M_PI - 4.0) * M_PI / 180, free_fall = 9.81 * std::sin(alpha);
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
