// Clump templates (mass properties of a union of spheres) and free rigid-body rotation.
#include <catch2/catch.hpp>

#include <cmath>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

TEST_CASE("the wheat clump's mass and principal moments match the seed", "[kernel][clump]") {
  const ClumpTemplate t = wheat_clump_template();
  CHECK(t.mass == Approx(0.0356e-3).epsilon(0.01));
  CHECK(t.inertia[0] == Approx(2.918e-11).epsilon(0.01));   // about the long axis
  CHECK(t.inertia[1] == Approx(7.654e-11).epsilon(0.01));
  CHECK(t.inertia[2] == Approx(7.654e-11).epsilon(0.01));
  CHECK(t.com.norm() < 1e-9);
  // the long axis (smallest moment) is the template's x axis
  const Mat3 axes = t.principal.toRotationMatrix();
  CHECK(std::abs(axes.col(0).x()) == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("clump mass properties: a single sphere and two disjoint spheres are exact", "[kernel][clump]") {
  const double r = 1e-3, rho = 2000;
  const ClumpTemplate one = make_clump_template({{0.1, 0.2, 0.3}}, {r}, rho, 200);
  const double m = rho * 4.0 / 3.0 * M_PI * r * r * r;
  CHECK(one.mass == Approx(m).epsilon(1e-3));
  CHECK(one.inertia[0] == Approx(0.4 * m * r * r).epsilon(3e-3));
  CHECK((one.com - Vec3(0.1, 0.2, 0.3)).norm() < 1e-9);
  // two spheres 4r apart: parallel axis theorem, transverse I = 2 (2/5 m r^2 + m (2r)^2)
  const ClumpTemplate two = make_clump_template({{-2 * r, 0, 0}, {2 * r, 0, 0}}, {r, r}, rho, 300);
  CHECK(two.mass == Approx(2 * m).epsilon(2e-3));
  CHECK(two.inertia[0] == Approx(2 * 0.4 * m * r * r).epsilon(5e-3));
  CHECK(two.inertia[2] == Approx(2 * (0.4 * m * r * r + m * 4 * r * r)).epsilon(5e-3));
}

namespace {
// L = R_world I_template R_world^T omega, from what body() reports and the template's tensor (independent of the
// kernel's stored angular momentum).
Vec3 angular_momentum(const BodyState& b, const ClumpTemplate& t) {
  const Mat3 P = t.principal.toRotationMatrix();
  const Mat3 I_tmpl = P * t.inertia.asDiagonal() * P.transpose();
  const Mat3 R = b.orientation.toRotationMatrix();
  return R * I_tmpl * R.transpose() * b.angular_velocity;
}
}  // namespace

TEST_CASE("a clump spinning freely about a non-principal axis conserves angular momentum and energy",
          "[kernel][clump]") {
  Simulation sim;
  const int a = sim.add_material({1e9, 0.4, 1430, ""});
  sim.set_pair(a, a, {0.5, 0.3, 0.01});
  sim.set_gravity(Vec3::Zero());
  // an asymmetric clump (three moments all different): L-shaped, overlapping spheres
  const ClumpTemplate t = make_clump_template({{0, 0, 0}, {1.5e-3, 0, 0}, {0, 1e-3, 0.5e-3}}, {1e-3, 0.8e-3, 0.7e-3},
                                              1430, 120);
  REQUIRE(t.inertia[0] < 0.95 * t.inertia[1]);
  REQUIRE(t.inertia[1] < 0.95 * t.inertia[2]);
  const int tmpl = sim.add_clump_template(t);
  const Vec3 w0(40, 25, -60);  // rad/s, not along a principal axis
  sim.add_clump(tmpl, a, {0, 0, 0}, Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized())), Vec3(0.01, 0, 0), w0);
  sim.set_timestep(1e-6);
  const Vec3 L0 = angular_momentum(sim.body(0), t);
  const double E0 = sim.kinetic_energy();
  double max_dw = 0, max_dL = 0, max_dE = 0;
  for (int k = 0; k < 100; ++k) {
    sim.step(1000);  // 1e5 steps in all (0.1 s, ~1 turn per 0.1 s at |w| = 76 rad/s... about 1.2 turns)
    const BodyState b = sim.body(0);
    max_dw = std::max(max_dw, (b.angular_velocity - w0).norm());
    max_dL = std::max(max_dL, (angular_momentum(b, t) - L0).norm() / L0.norm());
    max_dE = std::max(max_dE, std::abs(sim.kinetic_energy() - E0) / E0);
  }
  CHECK(max_dw > 0.1 * w0.norm());  // omega really changes direction (it is not a trivial steady spin)
  CHECK(max_dL < 1e-6);             // |dL|/|L|
  CHECK(max_dE < 1e-5);             // bounded O(dt^2) error of the Richardson update
  CHECK(sim.body(0).position.x() == Approx(0.01 * sim.time()).epsilon(1e-9));
}

TEST_CASE("a clump spinning about a principal axis keeps omega", "[kernel][clump]") {
  Simulation sim;
  const int a = sim.add_material({1e9, 0.4, 1430, ""});
  sim.set_pair(a, a, {0.5, 0.3, 0.01});
  sim.set_gravity(Vec3::Zero());
  const int tmpl = sim.add_clump_template(wheat_clump_template());
  const Vec3 w0(0, 0, 50);  // about the template z axis: a transverse principal axis of the wheat grain
  sim.add_clump(tmpl, a, {0, 0, 0}, Quat::Identity(), Vec3::Zero(), w0);
  sim.set_timestep(1e-6);
  sim.step(20000);
  CHECK((sim.body(0).angular_velocity - w0).norm() < 1e-6 * w0.norm());
  // the grain turned by |w| t about z: its long axis (template x) is now at angle 50 * 0.02 = 1 rad
  const Vec3 ax = sim.body(0).orientation * Vec3::UnitX();
  CHECK(std::atan2(ax.y(), ax.x()) == Approx(1.0).epsilon(1e-6));
}
