// Moving walls: contacts see the wall's velocity, the wall's work is the energy it gives, and a grain on a vibrating
// plate leaves it exactly when the plate's downward acceleration passes g.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {
const Material kGrain{1.0024e9, 0.4, 1430, "wheat"};
const Material kSteel{2.08e9, 0.3, 7500, "steel"};
}  // namespace

TEST_CASE("a wall moving at constant velocity: an elastic grain rebounds at 2V - u and gains the wall's work",
          "[kernel][walls]") {
  Simulation sim;
  const int g = sim.add_material(kGrain), s = sim.add_material(kSteel);
  sim.set_pair(g, g, {{1.0}, {0.0}});
  sim.set_pair(g, s, {{1.0}, {0.0}});  // e = 1, frictionless: the rebound is exact kinematics
  sim.set_gravity(Vec3::Zero());
  const double r = 1.5e-3, u = -0.5, V = 0.2;
  const int floor = sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, s));
  sim.set_wall_velocity(floor, {0, 0, V});
  sim.add_sphere({0, 0, r + 1e-4}, r, g, {0, 0, u});
  sim.set_timestep(0.02 * sim.rayleigh_timestep());
  const double m = sim.body(0).mass, ke0 = sim.kinetic_energy();
  double work = 0;  // by the wall on the grain: -F_on_wall . V dt
  for (int k = 0; k < 200000 && !(sim.body(0).velocity.z() > V && sim.wall_force(floor).norm() == 0.0); ++k) {
    sim.step(1);
    work -= sim.wall_force(floor).dot(sim.wall(floor).velocity) * sim.timestep();
  }
  const double vz = sim.body(0).velocity.z();
  CHECK(vz == Approx(2 * V - u).epsilon(1e-4));
  CHECK(sim.wall(floor).displacement.z() == Approx(V * sim.time()).epsilon(1e-12));
  CHECK(sim.kinetic_energy() - ke0 == Approx(work).epsilon(2e-3));
  CHECK(sim.kinetic_energy() - ke0 == Approx(0.5 * m * ((2 * V - u) * (2 * V - u) - u * u)).epsilon(2e-4));
}

namespace {
// A grain riding a plate that vibrates vertically, x = A sin(2 pi f t), from t0 on; the grain starts with the plate's
// velocity. Returns the phase (rad, in [0, 2 pi)) at which the contact first opens, or -1 if it never opens within
// `periods`.
double take_off_phase(double gamma_peak, double f, int periods, double stiffness = 1.0) {
  Material grain = kGrain, steel = kSteel;
  grain.young *= stiffness;
  steel.young *= stiffness;
  const double r = 1.5e-3, w = 2 * M_PI * f, amplitude = gamma_peak * 9.81 / (w * w);
  Vec3 rest;
  {  // the grain comes to rest on the still plate (damped)
    Simulation sim;
    const int g = sim.add_material(grain), s = sim.add_material(steel);
    sim.set_pair(g, s, {{0.5}, {0.3}});
    sim.set_pair(g, g, {{0.5}, {0.3}});
    sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, s));
    sim.add_sphere({0, 0, r}, r, g);
    sim.set_timestep(0.2 * sim.rayleigh_timestep());
    sim.step(long(0.01 / sim.timestep()));
    REQUIRE(sim.body(0).velocity.norm() < 1e-6);
    rest = sim.body(0).position;
  }
  Simulation sim;  // the same grain riding the plate from t = 0, with the plate's velocity (no jolt at the start)
  const int g = sim.add_material(grain), s = sim.add_material(steel);
  sim.set_pair(g, s, {{0.5}, {0.3}});
  sim.set_pair(g, g, {{0.5}, {0.3}});
  const int plate = sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, s)
                                     .moving(std::make_shared<SinusoidalMotion>(Vec3::UnitZ(), amplitude, f, 0.0)));
  sim.add_sphere(rest, r, g, {0, 0, amplitude * w});
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
  const long steps = long(periods / f / sim.timestep());
  for (long k = 0; k < steps; ++k) {
    sim.step(1);
    if (sim.wall_force(plate).z() == 0.0) return std::fmod(w * sim.time(), 2 * M_PI);
  }
  return -1;
}
}  // namespace

TEST_CASE("a grain on a vibrating plate: stays below 1 g of peak acceleration, leaves at asin(1/Gamma) above",
          "[kernel][walls]") {
  CHECK(take_off_phase(0.8, 20.0, 3) == -1.0);
  CHECK(take_off_phase(0.95, 20.0, 3) == -1.0);
  for (double gamma : {1.5, 2.0, 4.0}) {
    INFO("Gamma = " << gamma);
    // The contact opens once the plate decelerates faster than g, A w^2 sin(phase) = g, in the limit of rigid
    // contacts; a Hertz contact unloads last, so the grain leaves a little after that phase, the later the softer.
    const double analytic = std::asin(1.0 / gamma);
    const double soft = take_off_phase(gamma, 20.0, 2), stiff = take_off_phase(gamma, 20.0, 2, 100.0);
    CHECK(soft > analytic);
    CHECK(stiff > analytic);
    CHECK(stiff - analytic < 0.5 * (soft - analytic));
    CHECK(stiff == Approx(analytic).margin(0.005));
  }
}

TEST_CASE("a vibrating wall is checked and its law is part of the configuration", "[kernel][walls]") {
  CHECK_THROWS_WITH(SinusoidalMotion(Vec3::Zero(), 1e-4, 10, 0), Catch::Matchers::Contains("direction"));
  CHECK_THROWS_WITH(SinusoidalMotion(Vec3::UnitX(), -1e-4, 10, 0), Catch::Matchers::Contains("amplitude"));
  CHECK_THROWS_WITH(SinusoidalMotion(Vec3::UnitX(), 1e-4, NAN, 0), Catch::Matchers::Contains("frequency"));
  Simulation sim;
  const int s = sim.add_material(kSteel);
  const int w = sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, s)
                                 .moving(std::make_shared<SinusoidalMotion>(Vec3::UnitX(), 1e-4, 50, 0.0)));
  CHECK_THROWS_AS(sim.set_wall_velocity(w, {0, 0, 1}), std::logic_error);
  SinusoidalMotion m(Vec3(2, 0, 0), 1e-4, 50, 0.1);
  CHECK(m.displacement(0.05).norm() == 0.0);
  CHECK(m.displacement(0.1 + 0.005).x() == Approx(1e-4));  // a quarter period after the start
  CHECK(m.peak_acceleration() == Approx(1e-4 * std::pow(2 * M_PI * 50, 2)));
}
