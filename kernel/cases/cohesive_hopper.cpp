#include "kernel/cases/cohesive_hopper.hpp"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "kernel/contact/hertz_normal.hpp"
#include "kernel/silo/input_error.hpp"
#include "kernel/simulation.hpp"

namespace demcal::kernel::cases {

namespace {
// The grains' material besides E (the case's fixed choices, stated in examples/cohesive_arch/README.md).
constexpr double kGrainDensity = 1000, kGrainPoisson = 0.3, kTimestepFraction = 0.25;

Material grain_material(const CohesiveHopperCase& c) { return {c.young, kGrainPoisson, kGrainDensity, "meal"}; }
Material wall_material() { return {2e8, 0.3, 7800, "steel"}; }
constexpr double kBinHeight = 0.3;  // the cylinder above the hopper [m]
double hopper_height(const CohesiveHopperCase& c) {
  return (c.bin_radius - c.outlet_radius) / std::tan(c.theta_deg * M_PI / 180);
}

void check(bool ok, const char* field, double value, const std::string& rule) {
  if (!ok || (value != 0 && std::abs(value) < 1e-300))
    throw std::invalid_argument(std::string(field) + " = " + silo::setting_text(value) + ": " + rule);
}
}  // namespace

namespace {
// A grain meeting a wall, or another grain, at the speed of a fall through the bin plus the walls' peak speed must not
// overlap it by more than its radius, or it passes through: an amplitude of 1 cm at 1000 Hz (walls at 63 m/s, 1.7
// radii of overlap on the 5 MPa grains) ran and reported a cut-off frequency. The silo case's rule, on this case.
void check_contact_softness(const CohesiveHopperCase& c) {
  const Material grain = grain_material(c);
  const double r = 0.9 * c.grain_radius;  // the smallest grain
  const double mass = kGrainDensity * 4.0 / 3.0 * M_PI * r * r * r;
  const double fall = std::sqrt(2 * 9.81 * (hopper_height(c) + kBinHeight));
  const double wall_speed = 2 * M_PI * c.frequency * c.amplitude;
  auto overlap_at = [&](double speed) {
    return std::max(hertz_impact_overlap(0.5 * mass, 0.5 * r, effective_young(grain, grain), speed),
                    hertz_impact_overlap(mass, r, effective_young(grain, wall_material()), speed));
  };
  const double still = overlap_at(fall), shaken = overlap_at(fall + wall_speed);
  if (!(still <= r))
    check(false, "young", c.young,
          "the grains are so soft that one falling through the bin (" + silo::setting_text(fall) +
              " m/s) would overlap by " + silo::setting_text(still / r) + " radii: it would pass through");
  if (!(shaken <= r))
    check(false, "amplitude", c.amplitude,
          "at " + silo::setting_text(c.frequency) + " Hz the walls move at up to " + silo::setting_text(wall_speed) +
              " m/s: a grain meeting one would overlap it by " + silo::setting_text(shaken / r) +
              " radii and pass through (grains of E = " + silo::setting_text(c.young) +
              " Pa); a smaller amplitude or frequency");
}
}  // namespace

void validate(const CohesiveHopperCase& c) {
  check(c.bond_number >= 0 && c.bond_number <= 1e4, "bond_number", c.bond_number, "must be in [0, 1e4]");
  check(c.frequency >= 0 && c.frequency <= 1000, "frequency", c.frequency, "must be in [0, 1000] Hz");
  check(c.amplitude >= 0 && c.amplitude <= 0.01, "amplitude", c.amplitude, "must be in [0, 0.01] m");
  check(c.theta_deg >= 5 && c.theta_deg <= 80, "theta", c.theta_deg, "must be in [5, 80] deg");
  check(c.grains >= 10 && c.grains <= 20000, "grains", c.grains, "must be in [10, 20000]");
  check(c.window >= kWindowMin && c.window <= kWindowMax, "window", c.window,
        "must be in [" + silo::setting_text(kWindowMin) + ", " + silo::setting_text(kWindowMax) + "] s");
  check_contact_softness(c);
  if (c.frequency > 0) {
    // at least 20 steps per period (the time step of the smallest grain, 0.9 r; about 1.7e-5 s by default)
    const Material m = grain_material(c);
    const double dt = kTimestepFraction * rayleigh_timestep(0.9 * c.grain_radius, m.density, m.shear_modulus(), m.poisson);
    check(1.0 / c.frequency >= 20 * dt, "frequency", c.frequency, "leaves fewer than 20 time steps per period");
  }
  // last: the rules above name the grains' softness and the time step, the more telling reasons
  if (c.frequency > 0 && c.amplitude > 0) {
    const std::string defect = vibration_strength_defect(c.amplitude, c.frequency);
    check(defect.empty(), "amplitude", c.amplitude, defect);
  }
}

CohesiveHopperOutcome run_cohesive_hopper(const CohesiveHopperCase& c) {
  validate(c);
  const auto t0 = std::chrono::steady_clock::now();
  CohesiveSimulation sim;
  const int meal = sim.add_material(grain_material(c));
  const int steel = sim.add_material(wall_material());
  const double r = c.grain_radius, m = kGrainDensity * 4.0 / 3.0 * M_PI * r * r * r;
  const double gamma = c.bond_number * m * 9.81 / (3 * M_PI * 0.5 * r);
  const CohesiveSimulation::PairParams pair{{.restitution = 0.3, .surface_energy = gamma}, {.friction = 0.5},
                                            {.rolling_friction = 0.05}};
  sim.set_pair(meal, meal, pair);
  sim.set_pair(meal, steel, pair);
  const double th = c.theta_deg * M_PI / 180, hopper_height = cases::hopper_height(c);
  std::shared_ptr<const WallMotion> shaker;
  if (c.frequency > 0 && c.amplitude > 0)
    shaker = std::make_shared<SinusoidalMotion>(Vec3::UnitX(), c.amplitude, c.frequency, c.settle);
  auto add = [&](const Wall& w) { return sim.add_wall(shaker ? w.moving(shaker) : w); };
  add(Wall::cone(0, 0, c.outlet_radius, 0, th, c.bin_radius, steel));
  add(Wall::cylinder(0, 0, c.bin_radius, hopper_height, kBinHeight, steel));
  const int plate = add(Wall::disk(0, 0, c.outlet_radius * 1.01, 0, steel));
  // grains on a jittered lattice inside the hopper, layer by layer from 0.3 of its height up
  std::mt19937_64 rng(c.seed);
  std::uniform_real_distribution<double> u(-1, 1);
  int placed = 0;
  for (double z = 0.3 * hopper_height; placed < c.grains; z += 2.2 * r)
    for (double x = -c.bin_radius; x <= c.bin_radius && placed < c.grains; x += 2.2 * r)
      for (double y = -c.bin_radius; y <= c.bin_radius && placed < c.grains; y += 2.2 * r) {
        const double room =
            c.outlet_radius + (c.bin_radius - c.outlet_radius) * std::min(1.0, z / hopper_height) - 1.5 * r;
        if (x * x + y * y >= room * room) continue;
        sim.add_sphere({x + 0.05 * r * u(rng), y + 0.05 * r * u(rng), z}, r * (1 + 0.1 * u(rng)), meal);
        ++placed;
      }
  sim.set_timestep(kTimestepFraction * sim.rayleigh_timestep());
  sim.set_exact_removal(true);  // the discharged spheres leave every 500 steps
  // the outlet opens at the step that reaches `settle`, when the shaker starts (100-step strides opened it up to 100
  // steps, 0.7 of a 400 Hz period, after the bin had begun to shake)
  const double dt = sim.timestep();
  while (sim.time() < c.settle)
    sim.step(std::clamp<long>(std::lround(std::ceil((c.settle - sim.time()) / dt)), 1, 100));
  sim.set_wall_enabled(plate, false);
  const double t_open = sim.time();
  const double mass = sim.total_mass();
  double out = 0;
  silo::FlowStallClock stall;  // the bin shakes from the opening: the stall counts from it
  CohesiveHopperOutcome o;
  while (true) {
    sim.step(500);
    const RemovalResult gone = sim.remove_bodies_if([](const BodyState& b) { return b.position.z() < -0.02; });
    out += gone.mass;
    const double t = sim.time() - t_open;
    if (gone.count) stall.grains_left_at(t);
    if (out >= 0.5 * mass) {
      o.end = silo::DischargeEnd::stop_fraction;
      break;
    }
    if (stall.stopped_at(t)) {
      o.end = silo::DischargeEnd::flow_stopped;
      break;
    }
    if (t >= c.window) {
      o.end = silo::DischargeEnd::time_limit;
      break;
    }
  }
  o.discharged_fraction = out / mass;
  o.discharge_s = sim.time() - t_open;
  o.peak_acceleration_g = c.amplitude * std::pow(2 * M_PI * c.frequency, 2) / 9.81;
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

void validate(const CohesiveHopperCase& base, const CutoffSearch& s) {
  validate(s);
  validate_window(base.window, s.criterion);
  validate_window_ladder(base.window, s.longest_window, s.criterion);
  CohesiveHopperCase c = base;
  for (double f : {s.lo, s.hi}) {  // every frequency of the search lies in the bracket: both ends checked
    c.frequency = f;
    validate(c);
  }
}

CutoffResult find_cutoff(CohesiveHopperCase c, const CutoffSearch& s,
                         const std::function<void(const CohesiveHopperCase&, const CohesiveHopperOutcome&)>& report) {
  validate(c, s);
  const std::vector<double> ladder = window_ladder(c.window, s.longest_window);
  return find_cutoff(s, [&](double f, unsigned seed) {
    const auto ends = deciding_ends(s.criterion, ladder, {seed}, [&](double window, const std::vector<unsigned>&) {
      CohesiveHopperCase run = c;
      run.frequency = f;
      run.seed = seed;
      run.window = window;
      const CohesiveHopperOutcome o = run_cohesive_hopper(run);
      if (report) report(run, o);
      return std::vector<silo::DischargeEnd>{o.end};
    });
    return flows(s.criterion, ends.front());
  });
}

}  // namespace demcal::kernel::cases
