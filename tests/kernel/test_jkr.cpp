// JKR adhesion against its analytic solution: the pull-off force 3 pi gamma R* and the gap at which a contact snaps
// off, 3/4 k (k R*/4)^(1/3) with k = sqrt(4 pi gamma / E*) (kernel/contact/jkr_normal.hpp); a grain hangs under a
// ceiling exactly when its weight is below the pull-off force.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {
const Material kGrain{1.0024e9, 0.4, 1430, "meal"};
const Material kSteel{2.08e9, 0.3, 7500, "steel"};

CohesiveSimulation::PairParams jkr(double gamma, double e = 1.0, double mu = 0.3) {
  return {{.restitution = e, .surface_energy = gamma}, {.friction = mu}, {.rolling_friction = 0.0}};
}

double analytic_snap_gap(double gamma, double e_star, double r_star) {
  const double k = std::sqrt(4 * M_PI * gamma / e_star);
  return 0.75 * k * std::cbrt(0.25 * k * r_star);
}

struct PullOff {
  double max_pull = 0;  // largest tensile force [N]
  double snap_gap = 0;  // the gap at the last step with a force [m]
  double first_gap_without = 0;
};
}  // namespace

TEST_CASE("JKR sphere-wall: pull-off force and snap-off gap equal the analytic ones", "[kernel][jkr]") {
  const double gamma = 0.05, r = 1.5e-3, V = 1e-4;
  CohesiveSimulation sim;
  const int g = sim.add_material(kGrain), s = sim.add_material(kSteel);
  sim.set_pair(g, g, jkr(gamma));
  sim.set_pair(g, s, jkr(gamma));
  sim.set_gravity(Vec3::Zero());
  // a grain so heavy that the adhesion cannot move it: the wall's path alone sets the gap
  Material heavy = kGrain;
  heavy.density = 1e15;
  const int h = sim.add_material(heavy);
  sim.set_pair(h, s, jkr(gamma));
  sim.set_pair(h, h, jkr(gamma));
  sim.set_pair(h, g, jkr(gamma));
  sim.add_sphere({0, 0, r - 1e-7}, r, h);  // pressed 0.1 um into the floor
  const int floor = sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, s));
  sim.set_wall_velocity(floor, {0, 0, -V});  // pulled away slowly: quasi-static (e = 1, no damping)
  sim.set_timestep(1e-7);
  const double e_star = 1.0 / ((1 - 0.16) / kGrain.young + (1 - 0.09) / kSteel.young);
  PullOff p;
  for (int k = 0; k < 40000; ++k) {
    sim.step(1);
    const double fz = -sim.wall_force(floor).z();  // on the grain (negative: pulled towards the floor)
    const double gap = (sim.body(0).position.z() - r) - sim.wall(floor).displacement.z();
    if (fz != 0.0) {
      p.max_pull = std::max(p.max_pull, -fz);
      p.snap_gap = gap;
    } else if (p.snap_gap != 0.0) {
      p.first_gap_without = gap;
      break;
    }
  }
  CHECK(p.max_pull == Approx(3 * M_PI * gamma * r).epsilon(1e-4));
  const double snap = analytic_snap_gap(gamma, e_star, r);
  INFO("snap-off between gaps " << p.snap_gap << " and " << p.first_gap_without << " m; analytic " << snap);
  CHECK(p.snap_gap <= snap);
  CHECK(p.first_gap_without >= snap);
  CHECK(p.first_gap_without - p.snap_gap < 2e-3 * snap);  // one step of the wall's path apart
}

TEST_CASE("JKR sphere-sphere: pull-off force 3 pi gamma R* with R* = R/2, measured from the momentum", "[kernel][jkr]") {
  const double gamma = 0.05, r = 1.5e-3, V = 1e-4;
  CohesiveSimulation sim;
  Material heavy = kGrain;
  heavy.density = 7e7;  // about 1 kg: the pull changes the velocity measurably but not the path
  const int h = sim.add_material(heavy);
  sim.set_pair(h, h, jkr(gamma));
  sim.set_gravity(Vec3::Zero());
  sim.add_sphere({-r + 0.5e-7, 0, 0}, r, h, {-0.5 * V, 0, 0});
  sim.add_sphere({r - 0.5e-7, 0, 0}, r, h, {0.5 * V, 0, 0});
  sim.set_timestep(1e-7);
  const double m = sim.body(1).mass;
  double max_pull = 0, v_prev = sim.body(1).velocity.x(), last_gap_with_force = 0;
  for (int k = 0; k < 40000; ++k) {
    sim.step(1);
    const double v = sim.body(1).velocity.x();
    const double f = m * (v - v_prev) / sim.timestep();  // on sphere 1, +x is away from sphere 0
    v_prev = v;
    const double gap = (sim.body(1).position.x() - sim.body(0).position.x()) - 2 * r;
    if (f != 0.0) {
      max_pull = std::max(max_pull, -f);
      last_gap_with_force = gap;
    } else if (last_gap_with_force != 0.0) {
      break;
    }
  }
  CHECK(max_pull == Approx(3 * M_PI * gamma * 0.5 * r).epsilon(1e-3));
  const double e_star = 1.0 / (2 * (1 - 0.16) / kGrain.young);
  CHECK(last_gap_with_force == Approx(analytic_snap_gap(gamma, e_star, 0.5 * r)).epsilon(5e-3));
}

TEST_CASE("JKR: a grain hangs under a steel ceiling exactly when its weight is below the pull-off force",
          "[kernel][jkr]") {
  const double r = 1.5e-3;
  const double weight = 1430 * 4.0 / 3.0 * M_PI * r * r * r * 9.81;
  auto hangs = [&](double pull_off_over_weight) {
    const double gamma = pull_off_over_weight * weight / (3 * M_PI * r);
    CohesiveSimulation sim;
    const int g = sim.add_material(kGrain), s = sim.add_material(kSteel);
    sim.set_pair(g, g, jkr(gamma, 0.5));
    sim.set_pair(g, s, jkr(gamma, 0.5));
    sim.add_wall(Wall::plane({0, 0, 0.01}, {0, 0, -1}, s));  // ceiling, particles below
    sim.add_sphere({0, 0, 0.01 - r + 1e-8}, r, g);            // just touching it
    sim.set_timestep(0.2 * sim.rayleigh_timestep());
    sim.step(long(0.02 / sim.timestep()));
    return sim.body(0).position.z() > 0.01 - 1.01 * r;
  };
  CHECK(hangs(2.0));
  CHECK(hangs(1.2));
  CHECK_FALSE(hangs(0.8));
  CHECK_FALSE(hangs(0.0));
}

TEST_CASE("JKR with zero surface energy is Hertz", "[kernel][jkr]") {
  JkrNormal::Coeffs j = JkrNormal::mix(kGrain, kSteel, {.restitution = 0.5, .surface_energy = 0.0});
  HertzNormal::Coeffs hz = HertzNormal::mix(kGrain, kSteel, {.restitution = 0.5});
  ContactGeometry geo{Vec3::UnitZ(), 2e-6, 1.5e-3, 2e-5, 1.5e-3, 0, 1.5e-3, 0};
  double hist[2] = {0, 0};
  const NormalState a = JkrNormal::force(j, geo, -0.01, hist);
  const NormalState b = HertzNormal::force(hz, geo, -0.01, nullptr);
  CHECK(a.fn == Approx(b.fn).epsilon(1e-12));
  CHECK(a.contact_radius == Approx(b.contact_radius).epsilon(1e-12));
  CHECK_THROWS_WITH(JkrNormal::Params({.restitution = 0.5, .surface_energy = -1}).validate(),
                    Catch::Matchers::Contains("surface_energy"));
}
