// Cohesive arching in a vibrating hopper, and the cut-off frequency that breaks the arch (issue 24; the seed's
// sections 2.1.3 and 3.6). A short driver over the kernel: JKR spheres (CohesiveSimulation) settle in a small conical
// hopper with its outlet closed, the outlet opens, and the whole bin vibrates horizontally, x = A sin(2 pi f t), from the
// opening. "Flows" means: at least half of the mass leaves within `--window` seconds of the opening (a stated,
// fixed criterion, not tuned). The cohesion is set by the bond number Bo = F_pulloff / (m g) of two equal grains
// (F_pulloff = 3 pi gamma R*, R* = r/2).
//   cohesive_arch --bond-number 10 --frequency 150 --amplitude 1e-4         one run, one JSON line
//   cohesive_arch --bond-number 10 --amplitude 1e-4 --cutoff 0,400 --tol 10  the lowest frequency that flows, by
//                                                                            bisection of the bracket [0, 400] Hz
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {

struct Case {
  double bond_number = 10;   // F_pulloff / (m g)
  double frequency = 0;      // Hz
  double amplitude = 1e-4;   // m
  double theta_deg = 30;     // hopper half angle from the vertical
  double grain_radius = 1e-3, outlet_radius = 6e-3, bin_radius = 20e-3;
  double young = 5e6;        // Pa: soft grains (the time step), stated with the results
  int grains = 800;
  unsigned seed = 1;
  double settle = 0.4;       // s with the outlet closed
  double window = 1.0;       // s after the opening
};

struct Outcome {
  double discharged_fraction = 0, wall_s = 0, peak_acceleration_g = 0;
};

Outcome run(const Case& c) {
  const auto t0 = std::chrono::steady_clock::now();
  CohesiveSimulation sim;
  const int meal = sim.add_material({c.young, 0.3, 1000, "meal"});
  const int steel = sim.add_material({2e8, 0.3, 7800, "steel"});
  const double r = c.grain_radius, m = 1000 * 4.0 / 3.0 * M_PI * r * r * r;
  const double gamma = c.bond_number * m * 9.81 / (3 * M_PI * 0.5 * r);
  const CohesiveSimulation::PairParams pair{{.restitution = 0.3, .surface_energy = gamma}, {.friction = 0.5},
                                            {.rolling_friction = 0.05}};
  sim.set_pair(meal, meal, pair);
  sim.set_pair(meal, steel, pair);
  const double th = c.theta_deg * M_PI / 180, hopper_height = (c.bin_radius - c.outlet_radius) / std::tan(th);
  std::shared_ptr<const WallMotion> shaker;
  if (c.frequency > 0 && c.amplitude > 0)
    shaker = std::make_shared<SinusoidalMotion>(Vec3::UnitX(), c.amplitude, c.frequency, c.settle);
  auto add = [&](const Wall& w) { return sim.add_wall(shaker ? w.moving(shaker) : w); };
  add(Wall::cone(0, 0, c.outlet_radius, 0, th, c.bin_radius, steel));
  add(Wall::cylinder(0, 0, c.bin_radius, hopper_height, 0.3, steel));
  const int plate = add(Wall::disk(0, 0, c.outlet_radius * 1.01, 0, steel));
  // grains on a jittered lattice inside the hopper, layer by layer from 0.3 of its height up
  std::mt19937_64 rng(c.seed);
  std::uniform_real_distribution<double> u(-1, 1);
  int placed = 0;
  for (double z = 0.3 * hopper_height; placed < c.grains; z += 2.2 * r)
    for (double x = -c.bin_radius; x <= c.bin_radius && placed < c.grains; x += 2.2 * r)
      for (double y = -c.bin_radius; y <= c.bin_radius && placed < c.grains; y += 2.2 * r) {
        const double room = c.outlet_radius + (c.bin_radius - c.outlet_radius) * std::min(1.0, z / hopper_height) - 1.5 * r;
        if (x * x + y * y >= room * room) continue;
        sim.add_sphere({x + 0.05 * r * u(rng), y + 0.05 * r * u(rng), z}, r * (1 + 0.1 * u(rng)), meal);
        ++placed;
      }
  sim.set_timestep(0.25 * sim.rayleigh_timestep());
  while (sim.time() < c.settle) sim.step(100);
  sim.set_wall_enabled(plate, false);
  const double mass = sim.total_mass();
  double out = 0;
  while (sim.time() < c.settle + c.window && out < 0.5 * mass) {
    sim.step(500);
    out += sim.remove_bodies_if([](const BodyState& b) { return b.position.z() < -0.02; }).mass;
  }
  Outcome o;
  o.discharged_fraction = out / mass;
  o.peak_acceleration_g = c.amplitude * std::pow(2 * M_PI * c.frequency, 2) / 9.81;
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

bool flows(const Outcome& o) { return o.discharged_fraction >= 0.5; }

void print(const Case& c, const Outcome& o) {
  std::printf("{\"bond_number\":%g,\"frequency_hz\":%g,\"amplitude_m\":%g,\"peak_acceleration_g\":%.3f,"
              "\"discharged_fraction\":%.4f,\"flows\":%s,\"seed\":%u,\"grains\":%d,\"wall_s\":%.1f}\n",
              c.bond_number, c.frequency, c.amplitude, o.peak_acceleration_g, o.discharged_fraction,
              flows(o) ? "true" : "false", c.seed, c.grains, o.wall_s);
  std::fflush(stdout);
}

double number(const char* name, const char* text, double lo, double hi) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(v >= lo && v <= hi) || (v != 0 && std::abs(v) < 1e-300))
    throw std::invalid_argument(std::string(name) + " = '" + text + "': must be a number in [" + std::to_string(lo) +
                                ", " + std::to_string(hi) + "]");
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Case c;
    double lo = -1, hi = -1, tol = 10;
    for (int k = 1; k < argc; ++k) {
      const std::string a = argv[k];
      if (k + 1 >= argc) throw std::invalid_argument(a + ": needs a value");
      const char* v = argv[++k];
      if (a == "--bond-number") c.bond_number = number("bond-number", v, 0, 1e4);
      else if (a == "--frequency") c.frequency = number("frequency", v, 0, 1000);
      else if (a == "--amplitude") c.amplitude = number("amplitude", v, 0, 0.01);
      else if (a == "--theta") c.theta_deg = number("theta", v, 5, 80);
      else if (a == "--grains") c.grains = int(number("grains", v, 10, 20000));
      else if (a == "--seed") c.seed = unsigned(number("seed", v, 0, 4e9));
      else if (a == "--window") c.window = number("window", v, 0.05, 10);
      else if (a == "--tol") tol = number("tol", v, 0.1, 1000);
      else if (a == "--cutoff") {
        const std::string s = v;
        const auto comma = s.find(',');
        if (comma == std::string::npos) throw std::invalid_argument("cutoff = '" + s + "': give LO,HI in Hz");
        lo = number("cutoff low", s.substr(0, comma).c_str(), 0, 1000);
        hi = number("cutoff high", s.substr(comma + 1).c_str(), 0, 1000);
        if (!(lo < hi)) throw std::invalid_argument("cutoff = '" + s + "': LO must be below HI");
      } else throw std::invalid_argument("unknown option " + a);
    }
    if (lo < 0) {
      print(c, run(c));
      return 0;
    }
    // bracket: the low end must hold the arch, the high end must flow; then bisect to within tol
    c.frequency = lo;
    Outcome o = run(c);
    print(c, o);
    if (flows(o)) { std::printf("{\"cutoff\":null,\"reason\":\"flows at the low end\"}\n"); return 1; }
    c.frequency = hi;
    o = run(c);
    print(c, o);
    if (!flows(o)) { std::printf("{\"cutoff\":null,\"reason\":\"arched at the high end\"}\n"); return 1; }
    while (hi - lo > tol) {
      c.frequency = 0.5 * (lo + hi);
      o = run(c);
      print(c, o);
      (flows(o) ? hi : lo) = c.frequency;
    }
    std::printf("{\"cutoff_hz\":[%g,%g],\"criterion\":\"half the mass out within %g s of the opening\"}\n", lo, hi, c.window);
    return 0;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "cohesive_arch: %s\n", e.what());
    return 2;
  }
}
