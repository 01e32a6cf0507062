// Clump templates (mass properties of a union of spheres) and free rigid-body rotation.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "kernel/clump_rotation.hpp"
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
  sim.set_pair(a, a, {{0.5}, {0.3}, {0.01}});
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
  sim.set_pair(a, a, {{0.5}, {0.3}, {0.01}});
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

// The batched orientation update (kernel/clump_rotation.hpp) against the scalar Eigen formulation it replaced
// (Richardson iteration as LAMMPS MathExtra::richardson), bit for bit: the kernel's results must not depend on
// whether a clump is updated alone or in a batch.
namespace {
Quat wq_reference(const Vec3& w, const Quat& q) { return Quat(0.0, w.x(), w.y(), w.z()) * q; }
Quat add_scaled_reference(const Quat& a, double s, const Quat& b) {
  return Quat(a.w() + s * b.w(), a.x() + s * b.x(), a.y() + s * b.y(), a.z() + s * b.z());
}
Quat renormalized_reference(const Quat& q) {
  const double f = 1.5 - 0.5 * q.squaredNorm();
  return Quat(f * q.w(), f * q.x(), f * q.y(), f * q.z());
}
Vec3 omega_reference(const Quat& q, const Vec3& L, const Vec3& inv_I) {
  return q * (q.conjugate() * L).cwiseProduct(inv_I);
}
Quat richardson_reference(Quat q, const Vec3& L, const Vec3& inv_I, double dt) {
  const double dtq = 0.5 * dt;
  const Quat wq0 = wq_reference(omega_reference(q, L, inv_I), q);
  const Quat qfull = renormalized_reference(add_scaled_reference(q, dtq, wq0));
  Quat qhalf = renormalized_reference(add_scaled_reference(q, 0.5 * dtq, wq0));
  const Vec3 w = omega_reference(qhalf, L, inv_I);
  qhalf = renormalized_reference(add_scaled_reference(qhalf, 0.5 * dtq, wq_reference(w, qhalf)));
  q = Quat(2 * qhalf.w() - qfull.w(), 2 * qhalf.x() - qfull.x(), 2 * qhalf.y() - qfull.y(), 2 * qhalf.z() - qfull.z());
  q.normalize();
  return q;
}
}  // namespace

TEST_CASE("batched rotation: four clumps side by side give the scalar Eigen update bit for bit", "[kernel][clump]") {
  namespace cr = clump_rotation;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double dt = 2.08e-6;
  long mismatches = 0, compared = 0;
  for (int batch = 0; batch < 20000; ++batch) {
    Quat q0[cr::kLanes];
    Vec3 L0[cr::kLanes], iI0[cr::kLanes];
    cr::QuatPack q;
    cr::VecPack L, iI;
    for (int k = 0; k < cr::kLanes; ++k) {
      q0[k] = Quat(u(rng), u(rng), u(rng), u(rng)).normalized();
      // wheat-like moments (7e-11 kg m^2) and angular velocities up to ~1000 rad/s; a degenerate axis now and then
      iI0[k] = Vec3(1.0 / (3e-11 * (1.5 + u(rng))), 1.0 / (7e-11 * (1.5 + u(rng))), batch % 97 == 0 ? 0.0 : 1.3e10);
      L0[k] = Vec3(u(rng), u(rng), u(rng)) * 5e-8;
      q.x[k] = q0[k].x(); q.y[k] = q0[k].y(); q.z[k] = q0[k].z(); q.w[k] = q0[k].w();
      L.x[k] = L0[k].x(); L.y[k] = L0[k].y(); L.z[k] = L0[k].z();
      iI.x[k] = iI0[k].x(); iI.y[k] = iI0[k].y(); iI.z[k] = iI0[k].z();
    }
    cr::richardson(q, L, iI, dt);
    const cr::MatPack R = cr::rotation_matrix(q);
    const cr::VecPack w = cr::angular_velocity(R, L, iI);
    for (int k = 0; k < cr::kLanes; ++k) {
      const Quat ref = richardson_reference(q0[k], L0[k], iI0[k], dt);
      const Mat3 Rref = ref.toRotationMatrix();
      const Vec3 wref = Rref * (Rref.transpose() * L0[k]).cwiseProduct(iI0[k]);
      bool same = q.x[k] == ref.x() && q.y[k] == ref.y() && q.z[k] == ref.z() && q.w[k] == ref.w();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) same = same && R.m[i][j][k] == Rref(i, j);
      same = same && w.x[k] == wref.x() && w.y[k] == wref.y() && w.z[k] == wref.z();
      mismatches += !same;
      ++compared;
    }
  }
  INFO(mismatches << " of " << compared << " clumps differ from the scalar update");
  CHECK(mismatches == 0);
}
