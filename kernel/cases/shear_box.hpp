// The Jenike-style direct shear box of yade_scripts/shear_box.py, run on the kernel with YADE's laws
// (YadeLawSimulation): the second shear engine (issue 21). The same procedure step for step: the same loose cloud
// (YADE's makeCloud and Python's random numbers, number for number: yade_random.hpp), grown in place, consolidated
// under the same PI-servo lid, bonded, sheared by the same frame at the same speed, sampled the same way, and the
// same result fields. What differs is the engine: the kernel's velocity-Verlet for YADE's leapfrog (the same
// positions), its Richardson quaternion update for YADE's aspherical integrator, its clump inertia for YADE's grid
// (both scaled to the exact union volume), and the wall contacts a sphere keeps with history (3; YADE: any).
#pragma once
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace demcal::kernel::cases {

/// One run's inputs: params.json of yade_scripts/shear_box.py, field for field (units and ranges are declared and
/// checked in orchestrator/shear_params.cpp; validate() below refuses what this engine cannot run).
struct ShearBoxParams {
  double density = 0;               ///< [kg/m^3]
  double young_modulus = 0;         ///< [Pa] particles and walls; kn = 2 Ea Ra Eb Rb / (Ea Ra + Eb Rb)
  double poisson_ratio = 0;         ///< YADE's ks/kn [-]
  double friction_coefficient = 0;  ///< tan of the inter-particle friction angle [-]
  double bond_normal_strength = 0;  ///< [Pa] bond tensile force limit = value * min(R1, R2)^2
  double bond_shear_strength = 0;   ///< [Pa] bond shear force limit = value * min(R1, R2)^2
  double particle_form = 1;         ///< length / width: 1 sphere, > 1 a row of equal spheres
  double timestep_fraction = 0;     ///< of YADE's PWaveTimeStep [-]
  double particle_radius = 0;       ///< mean sphere radius [m]
  double radius_spread = 0;         ///< relative half-width of the uniform radius distribution [-]
  double box_length = 0, box_width = 0, box_height = 0;  ///< [m]; shear along x (length), split at half height
  double normal_stress = 0;         ///< held by the lid [Pa]
  double shear_velocity = 0;        ///< of the upper frame [m/s]
  double shear_displacement = 0;    ///< of the upper frame [m]
  double damping = 0;               ///< YADE's non-viscous local damping [-]
  long seed = 1;                    ///< of the cloud and the clump axes
  int samples = 100;                ///< points of the shear curve
};

/// The procedure's numerical choices: yade_scripts/shear_box.py's constants of the same names (upper case there;
/// tests/kernel/test_shear_box.cpp reads the script and compares them, so the two cannot drift apart). Their reasons
/// are given in the script.
struct ShearBoxProcedure {
  static constexpr double cloud_solid_fraction = 0.25;
  static constexpr double grown_solid_fraction = 0.50;
  static constexpr double expected_solid_fraction = 0.555;
  static constexpr double growth_surface_speed = 0.05;
  static constexpr double consolidation_inertial_number = 0.01;
  static constexpr int servo_period = 10;
  static constexpr double servo_gain = 1.0;
  static constexpr double integral_gain = 0.1;
  static constexpr double stiffness_smoothing = 0.1;
  static constexpr double integral_leak = 0.1;
  static constexpr double integral_band = 0.25;
  static constexpr double approach_below = 0.10;
  static constexpr double approach_rearm_below = 0.50;
  static constexpr double growth_pause_above = 1.0;
  static constexpr double growth_step_limit = 20.0;
  static constexpr int consolidation_chunk = 200;
  static constexpr double consolidation_unbalanced = 0.02;
  static constexpr double consolidation_stress_tol = 0.02;
  static constexpr int consolidation_stable_checks = 3;
  static constexpr double normal_stress_tolerance = 0.10;
  static constexpr double skipped_samples_fraction = 0.05;
  static constexpr double kinetic_energy_speed_factor = 10.0;
};

/// Names this engine and the version of its procedure: part of a run's identity (a change of the physics or the
/// procedure bumps it, so that no cached result of the old one is reused).
inline constexpr const char* kShearBoxEngine = "demcal-kernel-shear-box/3";

/// A run that could not finish: `cause` is one of the script's (params, nan, kinetic_energy, escaped,
/// normal_stress), what() the evidence.
class ShearBoxFailure : public std::runtime_error {
 public:
  ShearBoxFailure(std::string cause, const std::string& details) : std::runtime_error(details), cause(std::move(cause)) {}
  std::string cause;
};

/// The fields of result.json (schema demcal.shear_result/1), as the YADE script writes them.
struct ShearBoxResult {
  std::vector<double> displacement, shear_stress, normal_stress, lid_height;  ///< the sampled curve
  double peak_shear_stress = 0, peak_displacement = 0;
  double residual_shear_stress = 0, residual_shear_stress_std = 0;
  double normal_stress_target = 0, normal_stress_held = 0, normal_stress_rel_dev = 0;
  double porosity = 0;
  int particle_count = 0, sphere_count = 0, spheres_per_particle = 1;
  double sphere_spacing_over_radius = 0;
  long bond_count = 0;
  double sheared_area = 0, consolidated_height = 0;
  long growth_steps = 0, consolidation_steps = 0, steps = 0;
  double consolidation_unbalanced_force = 0, consolidation_overshoot = 0, growth_lid_force_peak_ratio = 0;
  double inertial_number = 0;
  double timestep = 0;
  double wall_time_s = 0;
};

/// Throws ShearBoxFailure("params", ...) naming the field for inputs the procedure cannot run (a box smaller than two
/// particle lengths, a travel beyond half the box, a value out of its physical range).
void validate(const ShearBoxParams& p);

/// Runs the whole test. `log` receives the script's progress lines (consolidation and shear steps). `threads`: the
/// kernel's OpenMP threads (the result does not depend on it). Throws ShearBoxFailure.
ShearBoxResult run_shear_box(const ShearBoxParams& p, const std::function<void(const std::string&)>& log = {},
                             int threads = 1);

}  // namespace demcal::kernel::cases
