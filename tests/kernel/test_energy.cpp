// Without damping (e = 1) and friction (mu = 0) the total energy (kinetic + potential in gravity + elastic Hertz
// energy 8/15 E* sqrt(R*) dn^2.5 of every contact, computed here independently of the kernel) is conserved.
// Velocity Verlet is symplectic and second order: for a conservative force the energy error stays bounded (no
// drift) with an amplitude O(dt^2) (the Hertz force is not smooth at first touch, which adds a local error per
// contact event, also small at the step used). So: (1) over 10^5 steps of 8 spheres bouncing in a cylinder the
// total energy never deviates from its initial value by more than 1e-3 relative at dt = 0.1 dt_Rayleigh, and (2)
// halving dt shrinks the worst error by at least 2.5x (4x in theory for second order; measured 2.8e-4 -> 6.4e-5).
// Why 0.1 dt_R: the Rayleigh step is a wave-speed criterion; a Hertz contact at the ~0.8 m/s impacts here lasts only
// ~2 dt_R, so 0.1 dt_R resolves it with ~20 steps (at 0.4 dt_R, ~5 steps per contact, the error measured is 1 %).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {
double e_star(const Material& a, const Material& b) {
  return 1.0 / ((1 - a.poisson * a.poisson) / a.young + (1 - b.poisson * b.poisson) / b.young);
}

double elastic_energy(const Simulation& sim) {
  double e = 0;
  const auto& x = sim.sphere_positions();
  const auto& r = sim.sphere_radii();
  const Material& pm = sim.material(0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (std::size_t j = i + 1; j < x.size(); ++j) {
      const double dn = r[i] + r[j] - (x[i] - x[j]).norm();
      if (dn > 0) e += 8.0 / 15.0 * e_star(pm, pm) * std::sqrt(r[i] * r[j] / (r[i] + r[j])) * std::pow(dn, 2.5);
    }
    for (std::size_t w = 0; w < sim.num_walls(); ++w) {
      Vec3 n;
      double dn, dist;
      if (sim.wall(int(w)).contact(x[i], r[i], n, dn, dist))
        e += 8.0 / 15.0 * e_star(pm, sim.material(sim.wall(int(w)).material)) * std::sqrt(r[i]) * std::pow(dn, 2.5);
    }
  }
  return e;
}

// max over time of |E(t) - E0| / E0 (E = kinetic + potential + elastic), sampled every 10 steps
double energy_error(double dt_fraction, long steps) {
  Simulation sim;
  const int a = sim.add_material({1e8, 0.3, 1000, ""});
  const int w = sim.add_material({2e11, 0.3, 7800, ""});
  sim.set_pair(a, a, {{1.0}, {0.0}, {0.0}});
  sim.set_pair(a, w, {{1.0}, {0.0}, {0.0}});
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, w));
  sim.add_wall(Wall::cylinder(0, 0, 0.006, -0.01, 0.05, w));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  // 8 spheres (4 single, 2 pairs of different radii) in a column with random horizontal velocities
  for (int k = 0; k < 8; ++k)
    sim.add_sphere({0.003 * u(rng), 0.003 * u(rng), 0.002 + 0.004 * k}, k % 2 ? 1e-3 : 1.3e-3, a,
                   {0.2 * u(rng), 0.2 * u(rng), 0.2 * u(rng)});
  sim.set_timestep(dt_fraction * sim.rayleigh_timestep());
  const double e0 = sim.kinetic_energy() + sim.potential_energy() + elastic_energy(sim);
  double worst = 0;
  for (long s = 0; s < steps; s += 10) {
    sim.step(10);
    worst = std::max(worst, std::abs(sim.kinetic_energy() + sim.potential_energy() + elastic_energy(sim) - e0) / e0);
  }
  return worst;
}
}  // namespace

TEST_CASE("energy is conserved without damping and friction over 1e5 steps", "[kernel][energy]") {
  const double err = energy_error(0.1, 100000);
  const double err_half = energy_error(0.05, 200000);  // the same simulated time
  INFO("relative energy error: dt " << err << ", dt/2 " << err_half);
  CHECK(err < 1e-3);
  CHECK(err_half < err / 2.5);
}
