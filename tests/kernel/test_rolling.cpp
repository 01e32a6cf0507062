// Rolling friction (EDEM constant directional torque, contact/rolling_edem_cdt.hpp) against its analytic solution:
// a sphere rolling without slip on a floor under a constant resisting torque M = mu_r m g R. Energy balance with
// v = omega R: (m + I/R^2) v dv/dt = -M v / R, so it decelerates uniformly at a = mu_r g / (1 + I/(m R^2))
// = (5/7) mu_r g and stops after v0 / a, having rolled v0^2 / (2 a). Friction (mu = 0.5) holds the no-slip
// condition: the force it needs, m a, is 7 % of mu m g.
#include <catch2/catch.hpp>

#include <cmath>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {
struct Roll {
  double v_early, v_late, t_between;  // velocity along x at two times during the roll, and the time between them
  double slip;                        // largest |v - omega R| seen while rolling [m/s]
  double stop_time, stop_distance;    // when v first fell below 1 % of v0 (or the run's end), and the distance then
};

Roll roll(double mu_roll, double v0, double duration) {
  Simulation sim;
  const int grain = sim.add_material({1e8, 0.3, 2500, "grain"});
  const int steel = sim.add_material({2e11, 0.3, 7800, "steel"});
  sim.set_pair(grain, grain, {{0.5}, {0.5}, {mu_roll}});
  sim.set_pair(grain, steel, {{0.5}, {0.5}, {mu_roll}});
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, steel));
  const double R = 2e-3;
  sim.add_sphere({0, 0, R}, R, grain);
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
  sim.step(long(0.02 / sim.timestep()));  // settle on the floor (e = 0.5: the bounce dies out)
  // launch rolling in +x: the contact point at -R z is at rest when omega_y = v0 / R
  sim.set_body_velocity(0, {v0, 0, 0}, {0, v0 / R, 0});
  const double x0 = sim.body(0).position.x(), dt = sim.timestep();
  const long chunk = std::max(1L, long(1e-3 / dt));  // sample every ~1 ms
  Roll r{0, 0, 0, 0, duration, 0};
  const double t_early = 0.2 * duration, t_late = 0.6 * duration;
  double t = 0, te = -1, tl = -1;
  bool stopped = false;
  while (t < duration) {
    sim.step(chunk);
    t += chunk * dt;
    const BodyState b = sim.body(0);
    if (te < 0 && t >= t_early) { r.v_early = b.velocity.x(); te = t; }
    if (tl < 0 && t >= t_late) { r.v_late = b.velocity.x(); tl = t; }
    if (!stopped) {
      r.slip = std::max(r.slip, std::abs(b.velocity.x() - b.angular_velocity.y() * R));
      if (b.velocity.x() < 0.01 * v0) {
        stopped = true;
        r.stop_time = t;
        r.stop_distance = b.position.x() - x0;
      }
    }
  }
  if (!stopped) r.stop_distance = sim.body(0).position.x() - x0;
  r.t_between = tl - te;
  return r;
}
}  // namespace

TEST_CASE("rolling friction: a rolling sphere decelerates at 5/7 mu_r g and stops where the analytic solution says",
          "[kernel][rolling]") {
  const double g = 9.81, v0 = 0.2;
  SECTION("mu_r = 0.05") {
    const double mu_r = 0.05, a = 5.0 / 7.0 * mu_r * g;  // 0.350 m/s^2
    const double t_stop = v0 / a, x_stop = v0 * v0 / (2 * a);  // 0.571 s, 57.1 mm
    const Roll r = roll(mu_r, v0, 1.2 * t_stop);
    CHECK((r.v_early - r.v_late) / r.t_between == Approx(a).epsilon(0.02));
    CHECK(r.stop_time == Approx(t_stop).epsilon(0.03));  // sampled every ~1 ms, stopped at v < 1 % of v0
    CHECK(r.stop_distance == Approx(x_stop).epsilon(0.02));
    CHECK(r.slip < 0.01 * v0);  // it rolls, it does not slide
  }
  SECTION("mu_r = 0: it keeps rolling (the deceleration above comes from the rolling torque)") {
    const Roll r = roll(0.0, v0, 0.5);
    CHECK(std::abs(r.v_early - r.v_late) / r.t_between < 0.01 * 5.0 / 7.0 * 0.05 * g);
    CHECK(r.stop_distance == Approx(v0 * 0.5).epsilon(0.02));
  }
}
