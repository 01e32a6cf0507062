// The parameters of one YADE direct-shear-box run, as the user writes them (a flat JSON material file) and as the
// template yade_scripts/shear_box.py reads them (params.json). One table declares every field: its unit, meaning,
// default and admissible range, so validation, documentation and the sensitivity study all read the same place.
#pragma once
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace demcal::orchestrator {

struct ParamSpec {
    std::string name;
    std::string unit;
    std::string meaning;
    std::optional<double> default_value;  // none: the user must give it
    double min, max;                      // admissible closed range...
    bool min_exclusive = false, max_exclusive = false;  // ...or open at either end
    bool integer = false;
    bool per_run = false;                 // set by the campaign for each run (normal stress, seed), not in a material
};

// Every field of params.json, in a stable order.
const std::vector<ParamSpec>& shear_param_specs();
const ParamSpec* find_shear_param(const std::string& name);

// The micromechanical parameters a sensitivity study varies (seed, Table 3.1).
const std::vector<std::string>& micromechanical_param_names();
// Throws std::invalid_argument "FIELD: 'name' is not a micromechanical parameter (the list)" unless it is one; FIELD
// is what the caller's user called the list (an option, a JSON field).
void require_micromechanical_param(const std::string& name, const std::string& field);

// Checks a material (all fields except the per-run ones): unknown keys, missing fields, values out of range or not
// numbers, a box smaller than a few particle lengths, a travel shorter than a fraction of a particle, a box whose
// particles or steps (growth and shear) exceed the limits below. Fills defaults. Throws std::invalid_argument whose
// message names the field and the value (prefixed by `where`, e.g. the file name).
nlohmann::json validate_material(const nlohmann::json& material, const std::string& where = "material");

// A complete run: a validated material plus normal_stress and seed; refuses a normal stress that squeezes the
// particles into each other (against young_modulus) or whose consolidation takes more steps than the limit. Throws
// like validate_material. Every campaign checks each of its runs with it before it starts, and so does shear-run.
// Checks one value against its parameter's row of the table, as read (an integer above 2^63 shown as it was typed,
// not wrapped by a conversion); throws std::invalid_argument naming `where`, the field and the range.
void check_shear_param_value(const std::string& name, const nlohmann::json& value, const std::string& where);

nlohmann::json make_run_params(const nlohmann::json& validated_material, double normal_stress, long seed,
                               const std::string& where = "run");

// The work one run implies, estimated before it starts by the procedure's own formulas (yade_scripts/shear_box.py;
// the kernel's shear box follows them): its particles and its time steps.
struct ShearRunWork {
    double particles = 0;            // round(0.555 L W H / mean particle volume), as the run generates them
    double timestep = 0;             // [s] timestep_fraction x PWaveTimeStep of the smallest full-size sphere
    double growth_steps = 0;         // growing the shrunk cloud to full size
    double consolidation_steps = 0;  // the consolidation's own step limit (0 without a normal stress)
    double shear_steps = 0;          // shear_displacement / shear_velocity
    double steps() const { return growth_steps + consolidation_steps + shear_steps; }
};
ShearRunWork estimate_shear_work(const nlohmann::json& validated_material, std::optional<double> normal_stress);

// The most a run may imply (reasons in shear_params.cpp).
inline constexpr double kMaxShearParticles = 1e6;
inline constexpr double kMaxShearSteps = 1e8;

// Longest particle dimension of the material (a clump of spheres in a row with the largest radius) [m].
double max_particle_length(const nlohmann::json& material);

}  // namespace demcal::orchestrator
