// BasicSimulation::scale_particles (YADE's utils.growParticles(f, updateMass=True)): radii, clump members' offsets,
// masses (f^3) and inertia (f^5) scale about each body's centre of mass, velocities stay; the numbers YADE 2023.02a
// printed for the same bodies are the reference. And a growth between steps acts on the whole next step, as in
// YADE's leapfrog (the half kick taken before it is taken again with the new forces).
#include <catch2/catch.hpp>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

TEST_CASE("particles grow in place as YADE's growParticles makes them", "[kernel][scale_particles]") {
  YadeLawSimulation sim;
  const int m = sim.add_material({.young = 1e7, .poisson = 0.3, .density = 2000, .name = {}});
  sim.set_pair(m, m, {{}, {.friction = 0.5}});
  const BodyId sphere = sim.add_sphere(Vec3(0, 0, 0), 0.01, m, Vec3(0.1, 0, 0));
  // YADE: two spheres r = 0.01 at x = 0.1 and 0.11, after growParticles(1.1): r = 0.011 at x = 0.0995 and 0.1105
  const ClumpTemplate t = make_clump_template({Vec3(0.1, 0, 0), Vec3(0.11, 0, 0)}, {0.01, 0.01}, 2000);
  const int tmpl = sim.add_clump_template(t);
  sim.add_clump(tmpl, m, Vec3(0.105, 0, 0), Quat::Identity(), Vec3::Zero(), Vec3(0, 0, 2));
  const double clump_mass = sim.body(1).mass, sphere_mass = sim.body(0).mass;
  const double e_rot = sim.rotational_kinetic_energy();
  sim.scale_particles(1.1);
  CHECK(sim.body(0).id == sphere);
  CHECK(sim.body(0).radius == Approx(0.011).epsilon(1e-14));
  CHECK(sim.body(0).mass == Approx(sphere_mass * 1.331).epsilon(1e-14));
  CHECK(sim.body(0).velocity.x() == 0.1);  // velocities stay
  CHECK(sim.body(1).mass == Approx(clump_mass * 1.331).epsilon(1e-14));
  CHECK(sim.body(1).angular_velocity.z() == Approx(2.0).epsilon(1e-12));
  // rotational energy 1/2 I w^2 with I x f^5
  CHECK(sim.rotational_kinetic_energy() == Approx(e_rot * 1.61051).epsilon(1e-12));
  std::vector<double> xs;
  for (std::size_t k = 1; k < sim.num_spheres(); ++k) {
    xs.push_back(sim.sphere(k).position.x());
    CHECK(sim.sphere(k).radius == Approx(0.011).epsilon(1e-14));
  }
  std::sort(xs.begin(), xs.end());
  CHECK(xs[0] == Approx(0.0995).margin(1e-9));  // (the grid's centre of mass)
  CHECK(xs[1] == Approx(0.1105).margin(1e-9));
  CHECK_THROWS_AS(sim.scale_particles(0.0), std::invalid_argument);
}

TEST_CASE("grown particles find the contacts their new size makes at once", "[kernel][scale_particles]") {
  YadeLawSimulation sim;
  const int m = sim.add_material({.young = 1e7, .poisson = 0.3, .density = 2000, .name = {}});
  sim.set_pair(m, m, {{}, {.friction = 0.5}});
  sim.set_gravity(Vec3::Zero());
  sim.add_sphere(Vec3(0, 0, 0), 0.01, m);
  sim.add_sphere(Vec3(0.021, 0, 0), 0.01, m);  // 1 mm apart
  sim.set_timestep(1e-6);
  sim.step(5);
  CHECK(sim.body(0).velocity.norm() == 0.0);
  sim.scale_particles(1.1);  // now 1 mm overlap: they must push apart at the next step
  sim.step(1);
  CHECK(sim.body(0).velocity.x() < 0);
  CHECK(sim.body(1).velocity.x() > 0);
  CHECK(sim.unbalanced_force() > 0);
}

TEST_CASE("the unbalanced force is YADE's: mean body force over mean contact force", "[kernel][scale_particles]") {
  YadeLawSimulation sim;
  const int m = sim.add_material({.young = 1e6, .poisson = 0.3, .density = 2000, .name = {}});
  const int floor_mat = sim.add_material({.young = 1e6, .poisson = 0.3, .density = 2000, .name = {}});
  sim.set_pair(m, m, {{}, {.friction = 0.5}});
  sim.set_pair(m, floor_mat, {{}, {.friction = 0.5}});
  sim.add_wall(Wall::plane(Vec3::Zero(), Vec3::UnitZ(), floor_mat));
  sim.add_sphere(Vec3(0, 0, 0.5), 0.01, m);  // falling, no contact
  sim.set_timestep(1e-5);
  sim.step(1);
  CHECK(sim.unbalanced_force() == 0.0);
  // one sphere resting on the floor: body force |F_contact + m g| -> 0 against contact force m g
  YadeLawSimulation rest;
  const int a = rest.add_material({.young = 1e6, .poisson = 0.3, .density = 2000, .name = {}});
  rest.set_pair(a, a, {{}, {.friction = 0.5}});
  rest.add_wall(Wall::plane(Vec3::Zero(), Vec3::UnitZ(), a));
  rest.add_sphere(Vec3(0, 0, 0.0099), 0.01, a);
  rest.set_local_damping(0.5);
  rest.set_timestep(1e-5);
  rest.step(1);
  const double early = rest.unbalanced_force();
  rest.step(200000);
  CHECK(rest.unbalanced_force() < 1e-3);
  CHECK(rest.unbalanced_force() < early);
}

TEST_CASE("growth is charged to the neighbour skin - the list keeps every contact and is rebuilt only when spent",
          "[kernel][scale_particles]") {
  // a loose random cloud, no gravity, random velocities; 200 growth calls of 0.2 % each (49 % in radius) with a step
  // after each: through the list, the contacts are always the brute-force ones
  YadeLawSimulation sim;
  const int m = sim.add_material({.young = 1e7, .poisson = 0.3, .density = 2000, .name = {}});
  sim.set_pair(m, m, {{}, {.friction = 0.5}});
  sim.set_gravity(Vec3::Zero());
  std::uint64_t state = 12345;
  auto uniform = [&state] {  // (a fixed LCG: the same cloud everywhere)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) / double(1ULL << 53);
  };
  for (int i = 0; i < 400; ++i)
    sim.add_sphere(Vec3(0.2 * uniform(), 0.2 * uniform(), 0.2 * uniform()), 0.004 + 0.002 * uniform(), m,
                   Vec3(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5) * 0.2);
  sim.set_timestep(1e-5);
  sim.step(1);
  const std::size_t builds_before = sim.neighbor_builds();
  int checked_with_contacts = 0;
  for (int call = 0; call < 200; ++call) {
    sim.scale_particles(1.002);
    auto through_list = sim.contact_pairs();
    auto brute = sim.contact_pairs_brute_force();
    std::sort(through_list.begin(), through_list.end());
    std::sort(brute.begin(), brute.end());
    INFO("growth call " << call);
    REQUIRE(through_list == brute);
    if (!brute.empty()) ++checked_with_contacts;
    sim.step(1);
  }
  CHECK(checked_with_contacts > 100);  // (the cloud densifies: most checks see contacts)
  // growth alone spends the skin (0.2 of the mean radius) in about 30 calls; the grains pushed apart by their new
  // overlaps move it too. Before the budget every growth call rebuilt the list (200 builds); measured here: 98.
  const std::size_t builds = sim.neighbor_builds() - builds_before;
  CHECK(builds < 150);
  CHECK(builds > 5);
}
