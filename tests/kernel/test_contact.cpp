// Head-on collisions: restitution and Hertz contact duration (sphere-sphere and sphere-wall).
#include <catch2/catch.hpp>

#include <cmath>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {

struct Collision {
  double e;    // measured restitution: |v_rel after| / |v_rel before|
  double tc;   // measured contact duration [s] (resolution dt)
};

// Analytic undamped Hertz contact duration: t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5).
double hertz_duration(double m_star, double r_star, double e_star, double v) {
  return 2.868 * std::pow(m_star * m_star / (r_star * e_star * e_star * v), 0.2);
}

// Independent reference for the damped case: RK4 on m* x'' = -4/3 E* sqrt(R*) x^1.5 - 2 sqrt(5/6) |beta|
// sqrt(2 E* sqrt(R* x) m*) x' (x = overlap), with a step 1e-5 of the duration; returns {e, t_c}.
Collision reference(double m, double rs, double es, double e, double v) {
  const double l = std::log(e), beta = l / std::sqrt(l * l + M_PI * M_PI);
  auto acc = [&](double x, double xd) {
    if (x <= 0) return 0.0;
    const double sn = 2 * es * std::sqrt(rs * x);
    return (-4.0 / 3.0 * es * std::sqrt(rs) * std::pow(x, 1.5) - 2 * std::sqrt(5.0 / 6.0) * std::abs(beta) * std::sqrt(sn * m) * xd) / m;
  };
  const double h = hertz_duration(m, rs, es, v) * 1e-5;
  double x = 0, xd = v, t = 0;
  while (true) {
    const double a1 = acc(x, xd), k1 = xd;
    const double a2 = acc(x + 0.5 * h * k1, xd + 0.5 * h * a1), k2 = xd + 0.5 * h * a1;
    const double a3 = acc(x + 0.5 * h * k2, xd + 0.5 * h * a2), k3 = xd + 0.5 * h * a2;
    const double a4 = acc(x + h * k3, xd + h * a3), k4 = xd + h * a3;
    const double xn = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    const double xdn = xd + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    if (xn <= 0) {  // linear interpolation of the exit time
      t += h * x / (x - xn);
      return {std::abs(xdn) / v, t};
    }
    x = xn; xd = xdn; t += h;
  }
}

const Material kA{1.0024e9, 0.4, 1430, "wheat"};
const Material kB{2.08e9, 0.3, 7500, "steel"};

// Two spheres (radii r1, r2, material A) approaching head-on at relative speed v along x.
Collision sphere_sphere(double e, double r1, double r2, double v, double dt_fraction, double* tc_analytic,
                        Collision* ref) {
  Simulation sim;
  const int a = sim.add_material(kA);
  sim.set_pair(a, a, {{e}, {0.3}, {0.0}});
  sim.set_gravity(Vec3::Zero());
  sim.add_sphere({-r1 - 1e-6, 0, 0}, r1, a, {0.5 * v, 0, 0});
  sim.add_sphere({r2 + 1e-6, 0, 0}, r2, a, {-0.5 * v, 0, 0});
  const double m1 = sim.body(0).mass, m2 = sim.body(1).mass;
  const double ms = m1 * m2 / (m1 + m2), rs = r1 * r2 / (r1 + r2);
  const double es = 1.0 / (2 * (1 - kA.poisson * kA.poisson) / kA.young);
  *tc_analytic = hertz_duration(ms, rs, es, v);
  *ref = reference(ms, rs, es, e, v);
  sim.set_timestep(*tc_analytic * dt_fraction);
  long first = -1, last = -1;
  for (long s = 0; s < long(20 / dt_fraction); ++s) {
    sim.step(1);
    const double gap = (sim.body(1).position - sim.body(0).position).norm() - r1 - r2;
    if (gap < 0) {
      if (first < 0) first = s;
      last = s;
    } else if (first >= 0) {
      break;
    }
  }
  REQUIRE(first >= 0);
  const double vrel = sim.body(1).velocity.x() - sim.body(0).velocity.x();
  return {vrel / v, double(last - first + 1) * sim.timestep()};
}

// A sphere (material A) hitting a plane wall (material B) at normal speed v.
Collision sphere_wall(double e, double r, double v, double dt_fraction, double* tc_analytic, Collision* ref,
                      bool rectangle) {
  Simulation sim;
  const int a = sim.add_material(kA), b = sim.add_material(kB);
  sim.set_pair(a, a, {{0.5}, {0.3}, {0.0}});
  sim.set_pair(a, b, {{e}, {0.25}, {0.0}});
  sim.set_gravity(Vec3::Zero());
  if (rectangle)
    sim.add_wall(Wall::rectangle({0, 0, 0}, {0, 0, 1}, {1, 1, 0}, 0.01, 0.02, b));
  else
    sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, b));
  sim.add_sphere({0, 0, r + 1e-6}, r, a, {0, 0, -v});
  const double m = sim.body(0).mass;
  const double es = 1.0 / ((1 - kA.poisson * kA.poisson) / kA.young + (1 - kB.poisson * kB.poisson) / kB.young);
  *tc_analytic = hertz_duration(m, r, es, v);
  *ref = reference(m, r, es, e, v);
  sim.set_timestep(*tc_analytic * dt_fraction);
  long first = -1, last = -1;
  for (long s = 0; s < long(20 / dt_fraction); ++s) {
    sim.step(1);
    if (sim.body(0).position.z() < r) {
      if (first < 0) first = s;
      last = s;
    } else if (first >= 0) {
      break;
    }
  }
  REQUIRE(first >= 0);
  return {sim.body(0).velocity.z() / v, double(last - first + 1) * sim.timestep()};
}

}  // namespace

TEST_CASE("head-on sphere-sphere collision: restitution and Hertz duration", "[kernel][contact]") {
  double tc;
  Collision ref;
  SECTION("undamped (e = 1): analytic Hertz duration within 2 %") {
    const Collision c = sphere_sphere(1.0, 1.5e-3, 1.25e-3, 0.5, 1.0 / 1000, &tc, &ref);
    CHECK(c.e == Approx(1.0).epsilon(0.01));
    CHECK(c.tc == Approx(tc).epsilon(0.02));
  }
  for (double e : {0.3, 0.5, 0.9}) {
    DYNAMIC_SECTION("damped, e = " << e) {
      const Collision c = sphere_sphere(e, 1.5e-3, 1.25e-3, 1.0, 1.0 / 1000, &tc, &ref);
      CHECK(c.e == Approx(e).epsilon(0.01));
      // Damping lengthens the contact (for e = 0.5 by ~3.6 %, more than the 2 % tolerance), so the damped duration
      // is compared to the fine-step RK4 solution of the same force law (reference()), not to the undamped formula.
      CHECK(c.tc == Approx(ref.tc).epsilon(0.02));
      CHECK(ref.e == Approx(e).epsilon(0.005));  // the damping law itself returns the set e
      CHECK(ref.tc > tc);
    }
  }
}

TEST_CASE("head-on sphere-wall collision: restitution and Hertz duration", "[kernel][contact]") {
  double tc;
  Collision ref;
  for (bool rect : {false, true}) {
    DYNAMIC_SECTION((rect ? "bounded rectangle" : "infinite plane")) {
      const Collision u = sphere_wall(1.0, 1.5e-3, 0.7, 1.0 / 1000, &tc, &ref, rect);
      CHECK(u.e == Approx(1.0).epsilon(0.01));
      CHECK(u.tc == Approx(tc).epsilon(0.02));
      const Collision c = sphere_wall(0.6, 1.5e-3, 0.7, 1.0 / 1000, &tc, &ref, rect);
      CHECK(c.e == Approx(0.6).epsilon(0.01));
      CHECK(c.tc == Approx(ref.tc).epsilon(0.02));
    }
  }
}
