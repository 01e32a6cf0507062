// A flat-bottomed block (a rigid clump of four spheres in a square) on an incline slides only above the friction
// angle atan(mu). The incline is the plane z = 0 with gravity tilted by alpha (equivalent, and exact).
#include <catch2/catch.hpp>

#include <cmath>

#include "incline_scene.hpp"

using namespace demcal::kernel;

namespace {
struct Slide {
  double v_end;  // velocity along the slope at the end [m/s]
  double dx;     // displacement along the slope over the measuring window [m]
};

Slide run(double alpha_deg, double mu) {
  Simulation sim;
  const auto scene = demcal::test::make_incline(sim, alpha_deg * M_PI / 180.0, mu);
  sim.add_clump(scene.block, scene.grain, {0, 0, scene.r}, Quat::Identity());
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
  const long settle = long(0.05 / sim.timestep()), window = long(0.1 / sim.timestep());
  sim.step(settle);  // bounce and settle
  const double x0 = sim.body(0).position.x();
  sim.step(window);
  return {sim.body(0).velocity.x(), sim.body(0).position.x() - x0};
}
}  // namespace

TEST_CASE("a block on an incline slides only above the friction angle", "[kernel][friction]") {
  const double mu = 0.3, phi = std::atan(mu) * 180 / M_PI;  // 16.70 deg
  SECTION("below: 2 deg under the friction angle it stays") {
    const Slide s = run(phi - 2.0, mu);
    CHECK(std::abs(s.dx) < 1e-6);       // elastic creep only (the block is 6 mm wide)
    CHECK(std::abs(s.v_end) < 1e-4);
  }
  SECTION("above: 2 deg over the friction angle it accelerates at g (sin a - mu cos a)") {
    const double alpha = (phi + 2.0) * M_PI / 180;
    const double acc = 9.81 * (std::sin(alpha) - mu * std::cos(alpha));
    const Slide s = run(phi + 2.0, mu);
    // during the 0.1 s window it slides all the time: dx = v0 t + a t^2/2 and v_end = v0 + a t
    const double t = 0.1, v0 = s.v_end - acc * t;
    CHECK(s.dx == Approx(v0 * t + 0.5 * acc * t * t).epsilon(0.05));
    CHECK(s.v_end > 0.5 * acc * t);
    CHECK(s.dx > 1e-3);
  }
  SECTION("frictionless: slides at g sin a") {
    const Slide s = run(5.0, 0.0);
    CHECK(s.dx > 1e-3);
  }
}
