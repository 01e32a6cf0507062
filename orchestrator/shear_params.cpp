#include "orchestrator/shear_params.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace demcal::orchestrator {

namespace {
constexpr double inf = std::numeric_limits<double>::infinity();

std::string format_value(const nlohmann::json& v) { return analytics::json_value_text(v); }

std::string range_text(const ParamSpec& s) {
    std::ostringstream o;
    o.precision(15);  // whole: 2147483647 printed as 2.14748e+09 looked like a bound 2147483648 stays inside
    o << (s.min_exclusive ? "(" : "[") << s.min << ", " << s.max << (s.max_exclusive ? ")" : "]");
    return o.str();
}
}  // namespace

const std::vector<ParamSpec>& shear_param_specs() {
    // Defaults of the test set-up follow the seed (box 0.1 x 0.1 x 0.05 m); the micromechanical ones have none.
    static const std::vector<ParamSpec> specs = {
        // >= 10: below the lightest granular solid (expanded polystyrene beads, 15-30 kg/m^3; the silo's materials
        // have the same bound). Lighter grains change nothing but the time step, sqrt(density / young_modulus), at the
        // procedure's fixed growth and shear speeds: 1e-3 kg/m^3 made sand-tiny a 2e7-step run.
        {"density", "kg/m^3", "particle material density", std::nullopt, 10, 1e5},
        // <= 1e12: diamond's 1.05e12 is the stiffest solid; 1e13 passed and made a 2 s tiny box a run of 15 min
        {"young_modulus", "Pa", "Young modulus of the particle material (YADE CohFrictMat.young)", std::nullopt, 0, 1e12,
         true},
        {"poisson_ratio", "-",
         "YADE's linear-law stiffness ratio ks/kn (CohFrictMat.poisson); it carries the name of a Poisson ratio",
         std::nullopt, 0, 0.5, true, true},  // a Poisson ratio lies in (-1, 0.5); a stiffness ratio must be > 0
        {"friction_coefficient", "-", "inter-particle friction coefficient, tan of YADE's frictionAngle", std::nullopt,
         0, 10},
        {"bond_normal_strength", "Pa", "bond normal (tensile) strength, CohFrictMat.normalCohesion; 0 = no bonds",
         std::nullopt, 0, 1e12},
        {"bond_shear_strength", "Pa", "bond shear strength, CohFrictMat.shearCohesion; 0 = no bonds", std::nullopt, 0,
         1e12},
        {"particle_form", "-", "aspect ratio length/width of a particle: 1 = sphere, > 1 = clump of spheres in a row",
         1.0, 1, 3},
        {"timestep_fraction", "-", "time step as a fraction of the critical step (YADE PWaveTimeStep)", std::nullopt, 0,
         1, true},
        {"particle_radius", "m", "mean radius of the spheres", std::nullopt, 0, 1, true},
        {"radius_spread", "-", "relative half-width of the uniform radius distribution", 0.1, 0, 0.9, false, true},
        {"box_length", "m", "box length, the shear direction x", 0.1, 0, 10, true},
        {"box_width", "m", "box width y", 0.1, 0, 10, true},
        {"box_height", "m", "box height z (split at mid-height)", 0.05, 0, 10, true},
        {"shear_velocity", "m/s", "velocity of the upper half", 0.05, 0, 10, true},
        {"shear_displacement", "m", "total shear displacement", 0.01, 0, 10, true},
        // <= 0.9: the local damping drags every grain, and its drag grows into the measured strength (sand-tiny at
        // 5 kPa: tau/sigma 0.76 at 0.2, 1.25 at 0.9, 3.8 at 0.99, 950 at 0.9999999); YADE's set-ups use 0.2-0.4
        {"damping", "-", "YADE NewtonIntegrator (Cundall) damping", 0.2, 0, 0.9},
        {"samples", "-", "points of the sampled shear curve", 100, 10, 100000, false, false, true},
        {"normal_stress", "Pa", "normal stress held by the lid", std::nullopt, 0, 1e10, true, false, false, true},
        {"seed", "-", "packing seed", std::nullopt, 0, 2147483647, false, false, true, true},
    };
    return specs;
}

const ParamSpec* find_shear_param(const std::string& name) {
    for (const auto& s : shear_param_specs())
        if (s.name == name) return &s;
    return nullptr;
}

const std::vector<std::string>& micromechanical_param_names() {
    static const std::vector<std::string> names = {"density",           "young_modulus",        "poisson_ratio",
                                                   "friction_coefficient", "bond_normal_strength", "bond_shear_strength",
                                                   "particle_form",     "timestep_fraction"};
    return names;
}

void require_micromechanical_param(const std::string& name, const std::string& field) {
    const auto& micro = micromechanical_param_names();
    if (std::find(micro.begin(), micro.end(), name) != micro.end()) return;
    std::string list;
    for (const auto& m : micro) list += (list.empty() ? "" : ", ") + m;
    throw std::invalid_argument(field + ": '" + name + "' is not a micromechanical parameter (" + list + ")");
}

double max_particle_length(const nlohmann::json& m) {
    const double r_max = m.at("particle_radius").get<double>() * (1 + m.at("radius_spread").get<double>());
    return 2 * r_max * m.at("particle_form").get<double>();
}

namespace {
void check_value(const ParamSpec& s, const nlohmann::json& v, const std::string& where) {
    if (!v.is_number())
        throw std::invalid_argument(where + ": field '" + s.name + "' must be a number [" + s.unit + "], got " +
                                    format_value(v));
    const double x = v.get<double>();
    const bool below = s.min_exclusive ? !(x > s.min) : !(x >= s.min);
    const bool above = s.max_exclusive ? !(x < s.max) : !(x <= s.max);
    if (!std::isfinite(x) || below || above)
        throw std::invalid_argument(where + ": field '" + s.name + "' = " + format_value(v) + " is outside " +
                                    range_text(s) + " " + s.unit + " (" + s.meaning + ")");
    if (s.integer && x != std::floor(x))
        throw std::invalid_argument(where + ": field '" + s.name + "' = " + format_value(v) + " must be an integer");
}

void check_geometry(const nlohmann::json& m, const std::string& where) {
    // Fewer than a few particle lengths across the box and the sample is no longer a continuum (the seed's ratio is
    // box/clump = 15.9); below 4 the failure line measures the particles, not the material.
    constexpr double min_particles_across = 4.0;
    const double len = max_particle_length(m);
    for (const char* dim : {"box_length", "box_width", "box_height"}) {
        const double d = m.at(dim).get<double>();
        if (d < min_particles_across * len) {
            std::ostringstream o;
            o << where << ": field '" << dim << "' = " << d << " m is smaller than " << min_particles_across
              << " particle lengths (" << min_particles_across * len << " m for particle_radius = "
              << m.at("particle_radius").get<double>() << " m, particle_form = " << m.at("particle_form").get<double>()
              << ")";
            throw std::invalid_argument(o.str());
        }
    }
    if (m.at("shear_displacement").get<double>() > 0.5 * m.at("box_length").get<double>())
        throw std::invalid_argument(where + ": field 'shear_displacement' = " + format_value(m.at("shear_displacement")) +
                                    " m is more than half the box length " + format_value(m.at("box_length")) + " m");
    // A failure line needs every sample sheared through its peak, and the peak comes once the grains of the shear band
    // have moved over their neighbours: after 0.5-1 particle length (sand-tiny: 0.71; sand.json: 0.9-1.3). A shorter
    // travel than a quarter of a particle length ends before any failure, its "peak" only the last sample (1e-12 m
    // gave a peak at 3 um). The repository's shortest travel is 0.33 of one (sand-scale-tiny at r = 4.5 mm).
    constexpr double min_travel_particle_lengths = 0.25;
    const double r = m.at("particle_radius").get<double>(), form = m.at("particle_form").get<double>();
    if (m.at("shear_displacement").get<double>() < min_travel_particle_lengths * 2 * r * form) {
        std::ostringstream o;
        o << where << ": field 'shear_displacement' = " << format_value(m.at("shear_displacement"))
          << " m is shorter than a quarter of a particle length (" << min_travel_particle_lengths * 2 * r * form
          << " m for particle_radius = " << r << " m, particle_form = " << form
          << "): the sample would not be sheared through its peak";
        throw std::invalid_argument(o.str());
    }
}

// ---- the work a run implies

// The procedure's numbers the estimate needs: yade_scripts/shear_box.py's constants of the same names (the kernel's
// ShearBoxProcedure copies them and tests/kernel/test_shear_box.cpp compares the two; a real run is compared with
// this estimate in tests/orchestrator/test_shear_run_work.cpp).
constexpr double kCloudSolidFraction = 0.25, kGrownSolidFraction = 0.50, kExpectedSolidFraction = 0.555;
constexpr double kGrowthSurfaceSpeed = 0.05;  // [m/s]
constexpr double kConsolidationInertialNumber = 0.01;
constexpr double kConsolidationChunk = 200;

// The script's clump_layout and union_volume for spheres of radius 1: n in a row, their centres `spacing` apart.
std::pair<int, double> clump_layout(double form) {
    if (form <= 1.0 + 1e-12) return {1, 0.0};
    const int n = 1 + static_cast<int>(std::ceil(2 * (form - 1) - 1e-9));
    return {n, 2 * (form - 1) / (n - 1)};
}
double unit_union_volume(int n, double spacing) {
    const double sphere = 4.0 / 3.0 * M_PI;
    if (n == 1) return sphere;
    return n * sphere - (n - 1) * M_PI * (4 + spacing) * std::pow(2 - spacing, 2.0) / 12.0;
}

// The box's time step when its smallest sphere has radius smallest_radius: timestep_fraction of that sphere's
// elastic wave crossing time, r sqrt(density / young_modulus), as both engines set it.
static double shear_timestep(const nlohmann::json& m, double smallest_radius) {
    return m.at("timestep_fraction").get<double>() * smallest_radius *
           std::sqrt(m.at("density").get<double>() / m.at("young_modulus").get<double>());
}

// What one run may cost. Values each in their range can still make a run that ends on no machine: 1 um grains in a
// 4 cm box (4e12 particles), a time step fraction of 1e-12 or a shear velocity of 1 nm/s (1e12 steps); they were
// planned and started, and ran until killed. The limits lie far above every run of the repository (sand-tiny: 525
// particles and 1.2e5 steps, the consolidation's step limit counted in full; the seed's 0.1 x 0.1 x 0.05 m box of
// r = 1 mm particles, the smallest it studies: 66 000 particles) and above any run a user would wait for. A million
// particles: placing the cloud alone (makeCloud, YADE's and the kernel's copy, is O(n^2)) takes hours, and each
// step 2000 times sand-tiny's. 1e8 steps: hours for sand-tiny's 525 particles (the kernel makes about 1e4 of its steps
// a second) and weeks for the seed's box at r = 1 mm, while shearing sand.json at a laboratory speed (1 mm/min)
// takes 5e7.
// Both engines take one step at least per sample (shear_steps = max(samples, travel / (v dt))): more samples than the
// travel's steps moved the frame past shear_displacement (samples 20000 on sand-tiny: 6.56 mm for 4 mm, and a peak line
// of 2530 Pa against 1533; at 100000 the frame left the box). The fewest steps the travel can take is at the largest
// time step a run can draw, that of a smallest sphere as large as r (1 + radius_spread).
static void check_samples_within_travel(const nlohmann::json& m, const std::string& where) {
    auto d = [&](const char* k) { return m.at(k).get<double>(); };
    const double largest_step = shear_timestep(m, d("particle_radius") * (1 + d("radius_spread")));
    const double fewest_steps = std::floor(d("shear_displacement") / (d("shear_velocity") * largest_step));
    if (d("samples") <= fewest_steps) return;
    throw std::invalid_argument(where + ": samples = " + analytics::number_text(d("samples")) +
                                " is more than the shear's time steps (at least " +
                                analytics::number_text(fewest_steps, 12) +
                                ": shear_displacement / (shear_velocity x time step)); a sample takes one step at "
                                "least, so the frame would travel past shear_displacement: at most " +
                                analytics::number_text(fewest_steps, 12));
}

void check_work(const nlohmann::json& m, std::optional<double> normal_stress, const std::string& where) {
    const ShearRunWork w = estimate_shear_work(m, normal_stress);
    auto v = [&](const char* k) { return analytics::number_text(m.at(k).get<double>()); };
    if (!(w.particles <= kMaxShearParticles))
        throw std::invalid_argument(
            where + ": particle_radius = " + v("particle_radius") + " m (particle_form = " + v("particle_form") +
            ") gives about " + analytics::number_text(w.particles, 2) + " particles in the " + v("box_length") + " x " +
            v("box_width") + " x " + v("box_height") + " m box (box_length x box_width x box_height; limit " +
            analytics::number_text(kMaxShearParticles) + " particles per run)");
    check_samples_within_travel(m, where);
    if (w.steps() <= kMaxShearSteps) return;
    std::string phase;  // the phase that takes the most steps, with the fields that set it
    if (w.shear_steps >= w.growth_steps && w.shear_steps >= w.consolidation_steps)
        phase = "shearing shear_displacement = " + v("shear_displacement") + " m at shear_velocity = " +
                v("shear_velocity") + " m/s takes about " + analytics::number_text(w.shear_steps, 2) + " steps";
    else if (w.consolidation_steps >= w.growth_steps)
        phase = "consolidating under normal_stress = " + analytics::number_text(*normal_stress) +
                " Pa may take about " + analytics::number_text(w.consolidation_steps, 2) +
                " steps (its step limit: the lid comes down at most at the quasi-static speed " +
                analytics::number_text(kConsolidationInertialNumber) +
                " box_height / (particle length x sqrt(density / normal_stress)), density = " + v("density") +
                " kg/m^3)";
    else
        phase = "growing the particles to full size at " + analytics::number_text(kGrowthSurfaceSpeed) +
                " m/s takes about " + analytics::number_text(w.growth_steps, 2) + " steps";
    throw std::invalid_argument(
        where + ": " + phase + " at a time step of " + analytics::number_text(w.timestep, 3) +
        " s (timestep_fraction = " + v("timestep_fraction") + " of the critical step of particle_radius = " +
        v("particle_radius") + " m, radius_spread = " + v("radius_spread") + ", density = " + v("density") +
        " kg/m^3, young_modulus = " + v("young_modulus") + " Pa): about " + analytics::number_text(w.steps(), 2) +
        " steps in all (limit " + analytics::number_text(kMaxShearSteps) + " steps per run)");
}

// The lid holds a stress on grains that weigh on it from below only through the packing: below the weight of the
// box's own grains per area (density x solid fraction x g x box_height, with a loose solid fraction of 0.5) it cannot
// settle at the target. sand-tiny at 100 Pa (its grains: 260 Pa by this bound) consolidated for 700,000 steps to
// 384 Pa and failed after 52 s; at 10 Pa it ran for minutes.
constexpr double kLooseSolidFraction = 0.5;
constexpr double kGravity = 9.81;

// The least normal stress a box holds: its grains' weight over its area (density x 0.5 x g x box_height).
double self_weight_stress(const nlohmann::json& p) {
    return p.at("density").get<double>() * kLooseSolidFraction * kGravity * p.at("box_height").get<double>();
}

void check_stress_above_self_weight(const nlohmann::json& p, double normal_stress, const std::string& where) {
    const double weight = self_weight_stress(p);
    if (normal_stress < weight)
        throw std::invalid_argument(where + ": normal_stress = " + analytics::number_text(normal_stress) +
                                    " Pa is below the weight of the box's grains (about " +
                                    analytics::number_text(weight, 3) +
                                    " Pa: density x 0.5 x g x box_height): the lid cannot hold so little");
}

// Contact overlap under the lid's stress, relative to the particle diameter d. A packing at solid fraction phi with Z
// contacts per particle carries a stress sigma with a mean contact force F = pi d^2 sigma / (phi Z) (Rothenburg and
// Bathurst), and the linear law's kn is E r = E d / 2, so delta / d = 2 pi sigma / (phi Z E): about 2.3 sigma / E at
// phi = 0.55, Z = 5. Above 5 % of a diameter the sample is squeezed rather than sheared: sand-tiny at 5 kPa (kernel,
// seed 1) was compressed by 6 % with E = 100 sigma (estimate 2.3 %), by 19 % with E = 25 sigma (9 %; porosity 0.35,
// below random close packing) and failed with E = 10 sigma (no upper half left above the shear plane); with 1e-3 Pa
// its spheres escaped. Every material of the repository stays below 0.4 % (E >= 1.4e7 Pa at <= 20 kPa).
constexpr double kOverlapPerStressRatio = 2.3;
constexpr double kMaxRelativeOverlap = 0.05;

void check_overlap(const nlohmann::json& p, double normal_stress, const std::string& where) {
    const double young = p.at("young_modulus").get<double>();
    const double overlap = kOverlapPerStressRatio * normal_stress / young;
    if (!(overlap <= kMaxRelativeOverlap))
        throw std::invalid_argument(
            where + ": young_modulus = " + analytics::number_text(young) + " Pa under normal_stress = " +
            analytics::number_text(normal_stress) + " Pa: the contacts would overlap by about " +
            analytics::number_text(overlap, 2) + " particle diameters (" +
            analytics::number_text(kOverlapPerStressRatio) + " normal_stress / young_modulus; at most " +
            analytics::number_text(kMaxRelativeOverlap) + ", so young_modulus >= " +
            analytics::number_text(kOverlapPerStressRatio / kMaxRelativeOverlap * normal_stress, 3) +
            " Pa at this stress)");
}
}  // namespace

namespace {
// A bond holds until its tensile force normal_cohesion r^2 stretches the linear spring kn = E r: a stretch of
// (bond_normal_strength / young_modulus) r before it breaks. Above one radius (a strain at break above 1) no solid
// bridge is meant, and every pair within that stretch must be watched each step: the kernel's neighbour reach grows
// with it (1e12 Pa on sand-tiny: 1 ms per step instead of 0.08 ms, a run of hours).
void check_bond_stretch(const nlohmann::json& m, const std::string& where) {
    const double young = m.at("young_modulus").get<double>();
    for (const char* bond : {"bond_normal_strength", "bond_shear_strength"}) {
        const double strength = m.at(bond).get<double>();
        if (strength > young)
            throw std::invalid_argument(where + ": " + bond + " = " + analytics::number_text(strength) +
                                        " Pa is above young_modulus = " + analytics::number_text(young) +
                                        " Pa: a bond would stretch by more than a particle radius before it breaks "
                                        "(strength / young_modulus > 1)");
    }
}
}  // namespace

ShearRunWork estimate_shear_work(const nlohmann::json& m, std::optional<double> normal_stress) {
    auto d = [&](const char* k) { return m.at(k).get<double>(); };
    const double r = d("particle_radius"), spread = d("radius_spread"), form = d("particle_form");
    const double L = d("box_length"), W = d("box_width"), H = d("box_height");
    const auto [n, spacing] = clump_layout(form);
    const double particle_volume = unit_union_volume(n, spacing) * r * r * r * (1 + spread * spread);  // mean
    ShearRunWork w;
    w.particles = std::max(1.0, std::nearbyint(kExpectedSolidFraction * L * W * H / particle_volume));
    // the cloud starts shrunk by size_factor; the time step is the smallest sphere's, r (1 - spread) at full size
    const double size_factor = std::cbrt(kCloudSolidFraction * unit_union_volume(n, spacing) /
                                         (kGrownSolidFraction * 4.0 / 3.0 * M_PI * std::pow(form, 3.0)));
    w.timestep = shear_timestep(m, r * (1 - spread));
    w.growth_steps = std::ceil(r * std::log(1 / size_factor) / (kGrowthSurfaceSpeed * size_factor * w.timestep));
    w.shear_steps = std::max(d("samples"), std::ceil(d("shear_displacement") / (d("shear_velocity") * w.timestep)));
    if (normal_stress) {
        // the consolidation's step limit: twice the cloud's height at the lid's quasi-static speed, 20 checks more
        const double cloud_height = w.particles * particle_volume / (L * W * kGrownSolidFraction);
        const double lid_speed =
            kConsolidationInertialNumber * H / (2 * r * form * std::sqrt(d("density") / *normal_stress));
        w.consolidation_steps = std::ceil(2 * cloud_height / lid_speed / w.timestep) + 20 * kConsolidationChunk;
    }
    return w;
}

nlohmann::json validate_material(const nlohmann::json& material, const std::string& where) {
    if (!material.is_object()) throw std::invalid_argument(where + ": a material must be a JSON object");
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [key, value] : material.items()) {
        // documentation, not physics: any "_" key, as the silo's material and geometry files take (probe 61: "_note"
        // was an unknown field). Not passed on: the YADE script, which takes "_comment..." keys, never sees them.
        if (key == "name" || key == "description" || key.rfind('_', 0) == 0) {
            if (!value.is_string())
                throw std::invalid_argument(where + ": field '" + key + "' must be a string, got " + format_value(value));
            continue;
        }
        const ParamSpec* s = find_shear_param(key);
        if (!s && (material.contains("grain") || material.contains("grain_grain")))  // the other kind of material
            throw std::invalid_argument(where + ": a silo material (grain, wall, grain_grain, grain_wall: demcal silo "
                                        "--material), not a shear box's (density, young_modulus, poisson_ratio, "
                                        "friction_coefficient, ...)");
        if (!s) throw std::invalid_argument(where + ": unknown field '" + analytics::shortened_text(key) + "' = " + format_value(value));
        if (s->per_run)
            throw std::invalid_argument(where + ": field '" + key + "' = " + format_value(value) +
                                        " is set per run by the campaign (use --normal-stress / --seed)");
        check_value(*s, value, where);
        out[key] = value;
    }
    for (const auto& s : shear_param_specs()) {
        if (s.per_run || out.contains(s.name)) continue;
        if (!s.default_value)
            throw std::invalid_argument(where + ": missing field '" + s.name + "' [" + s.unit + "] (" + s.meaning + ")");
        out[s.name] = s.integer ? nlohmann::json(static_cast<long>(*s.default_value)) : nlohmann::json(*s.default_value);
    }
    check_geometry(out, where);
    // No run holds less than the grains' weight (check_stress_above_self_weight): a modulus the overlap rule refuses
    // there refuses every run of the material, so it is refused here, where commands without a stress read it
    // (enlarge took E = 0.5 Pa and fitted laws through it).
    check_overlap(out, self_weight_stress(out), where + " (at the box's own weight, the least stress it holds)");
    check_work(out, std::nullopt, where);
    return out;
}

void check_shear_param_value(const std::string& name, const nlohmann::json& value, const std::string& where) {
    const ParamSpec* spec = find_shear_param(name);
    if (!spec) throw std::logic_error("no shear parameter " + name);
    check_value(*spec, value, where);
}

nlohmann::json make_run_params(const nlohmann::json& validated_material, double normal_stress, long seed,
                               const std::string& where) {
    nlohmann::json p = validated_material;
    p["normal_stress"] = normal_stress;
    p["seed"] = seed;
    check_value(*find_shear_param("normal_stress"), p["normal_stress"], where);
    check_value(*find_shear_param("seed"), p["seed"], where);
    check_stress_above_self_weight(p, normal_stress, where);
    check_overlap(p, normal_stress, where);
    check_bond_stretch(p, where);  // (after the overlap: an absurd modulus is named as such first)
    check_work(p, normal_stress, where);
    return p;
}

}  // namespace demcal::orchestrator
