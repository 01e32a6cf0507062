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

// Checks a material (all fields except the per-run ones): unknown keys, missing fields, values out of range or not
// numbers, a box smaller than a few particle lengths. Fills defaults. Throws std::invalid_argument whose message names
// the field and the value (prefixed by `where`, e.g. the file name).
nlohmann::json validate_material(const nlohmann::json& material, const std::string& where = "material");

// A complete run: a validated material plus normal_stress and seed. Throws like validate_material.
nlohmann::json make_run_params(const nlohmann::json& validated_material, double normal_stress, long seed);

// Longest particle dimension of the material (a clump of spheres in a row with the largest radius) [m].
double max_particle_length(const nlohmann::json& material);

}  // namespace demcal::orchestrator
