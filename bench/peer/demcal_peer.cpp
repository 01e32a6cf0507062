// The peer case (../shared/reference/peer-case/in.peer) run by demcal's kernel: 49,280 spheres d = 3 mm on the sc
// lattice (centres at (i + 1/2) 3 mm) inside a cylinder r = 50.5 mm, 0 <= z <= 0.165 m; cylindrical wall r = 52.5 mm
// and floor z = 0; gravity 9.81; Hertz-Mindlin with tangential history, no rolling friction; particles E = 1.0024e9,
// nu = 0.4, rho = 1430; walls E = 2.08e9, nu = 0.3; e = 0.5 (pp) / 0.6 (pw), mu = 0.3 / 0.25; dt = 5e-7; skin
// 0.3 mm (LIGGGHTS `neighbor 0.0003 bin`). 200 warm-up steps, then STEPS timed steps.
// Usage: demcal_peer [STEPS=2000] [THREADS=1] [REORDER_EVERY=10 (neighbour builds; 0 = never)]. Prints one JSON line.
#include <omp.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {
long status_kb(const char* key) {  // VmHWM / VmRSS from /proc/self/status [kB]
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::string(key).size() + 1);
  return -1;
}
}  // namespace

int main(int argc, char** argv) {
  const long steps = argc > 1 ? std::atol(argv[1]) : 2000;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 1;
  const int reorder = argc > 3 ? std::atoi(argv[3]) : 10;
  if (steps <= 0 || threads <= 0) {
    std::fprintf(stderr, "usage: demcal_peer [STEPS > 0] [THREADS > 0]\n");
    return 2;
  }
  const long rss0 = status_kb("VmRSS:");
  BasicSimulation<HertzMindlin> sim;  // no rolling friction in the peer case
  const int p = sim.add_material({1.0024e9, 0.4, 1430, "particle"});
  const int w = sim.add_material({2.08e9, 0.3, 7500, "wall"});
  sim.set_pair(p, p, {{0.5}, {0.3}});
  sim.set_pair(p, w, {{0.6}, {0.25}});
  sim.set_gravity({0, 0, -9.81});
  sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, w));
  sim.add_wall(Wall::cylinder(0, 0, 0.0525, -0.002, 0.20, w));
  // LIGGGHTS: lattice sc 0.003 origin 0.5 0.5 0.5 in the box [-0.056, 0.056]^2 x [-0.002, 0.2], region cylinder r
  // 0.0505, 0 <= z <= H: a site is taken when its centre is in the region (boundaries included)
  const double a = 0.003, R = 0.0505, H = 0.165;
  for (int k = 0; (k + 0.5) * a <= H; ++k)
    for (int j = -19; j < 19; ++j)
      for (int i = -19; i < 19; ++i) {
        const double x = (i + 0.5) * a, y = (j + 0.5) * a, z = (k + 0.5) * a;
        if (x * x + y * y <= R * R) sim.add_sphere({x, y, z}, 0.0015, p);
      }
  sim.set_timestep(5e-7);
  sim.set_skin(0.0003);
  sim.set_threads(threads);
  sim.set_reorder_every(reorder);
  sim.step(200);
  const auto t0 = std::chrono::steady_clock::now();
  struct rusage ru0, ru1;
  getrusage(RUSAGE_SELF, &ru0);
  sim.step(steps);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  getrusage(RUSAGE_SELF, &ru1);
  const double cpu = (ru1.ru_utime.tv_sec - ru0.ru_utime.tv_sec) + 1e-6 * (ru1.ru_utime.tv_usec - ru0.ru_utime.tv_usec) +
                     (ru1.ru_stime.tv_sec - ru0.ru_stime.tv_sec) + 1e-6 * (ru1.ru_stime.tv_usec - ru0.ru_stime.tv_usec);
  const std::size_t n = sim.num_bodies();
  double mean_z = 0, max_v = 0;
  for (std::size_t b = 0; b < n; ++b) {
    const BodyState s = sim.body(b);
    mean_z += s.position.z();
    max_v = std::max(max_v, s.velocity.norm());
  }
  mean_z /= double(n);
  const long hwm = status_kb("VmHWM:");
  std::printf(
      "{\"code\":\"demcal\",\"spheres\":%zu,\"steps\":%ld,\"threads\":%d,\"reorder_every\":%d,\"wall_s\":%.4f,\"cpu_s\":%.4f,"
      "\"particle_steps_per_s\":%.6g,\"peak_rss_kb\":%ld,\"rss_before_kb\":%ld,\"bytes_per_particle\":%.1f,"
      "\"kernel_bytes_per_particle\":%.1f,\"neighbor_builds\":%zu,\"pairs\":%zu,\"kinetic_energy_J\":%.9g,\"rotational_kinetic_energy_J\":%.6g,"
      "\"mean_z_m\":%.8f,\"max_speed_m_s\":%.6g}\n",
      n, steps, threads, reorder, wall, cpu, double(n) * double(steps) / wall, hwm, rss0, 1024.0 * double(hwm) / double(n),
      double(sim.memory_bytes()) / double(n), sim.neighbor_builds(), sim.neighbor_pairs(), sim.kinetic_energy(), sim.rotational_kinetic_energy(), mean_z,
      max_v);
  return 0;
}
