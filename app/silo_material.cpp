#include "app/silo_material.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <set>
#include <string>

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"  // json_value_text
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "kernel/silo/silo_case.hpp"  // validate(WheatMaterials)

namespace demcal {

namespace {

namespace ks = kernel::silo;
using json = nlohmann::json;

// Refuses keys other than `known` (keys starting with '_' are comments) and returns the object at `where`.
const json& object_with(const json& j, const std::string& file, const std::string& where,
                        const std::set<std::string>& known) {
    if (!j.is_object()) throw UserError(file + ": " + (where.empty() ? "the top level" : where) + " must be a JSON object");
    for (const auto& [key, value] : j.items()) {
        if (key.rfind("_", 0) == 0 || known.count(key)) continue;
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        throw UserError(file + ": unknown key '" + (where.empty() ? "" : where + ".") + key.substr(0, 40) +
                        "' (known: " + list + ")");
    }
    return j;
}

double number(const json& j, const std::string& file, const std::string& field, const std::string& key) {
    if (!j.contains(key)) throw UserError(file + ": " + field + "." + key + " is missing");
    const json& v = j.at(key);
    if (!v.is_number()) throw UserError(file + ": " + field + "." + key + " = " + analytics::json_value_text(v) + ": must be a number");
    return v.get<double>();
}

ks::Material solid(const json& root, const std::string& file, const std::string& field, bool grain) {
    if (!root.contains(field)) throw UserError(file + ": " + field + " is missing");
    std::set<std::string> keys{"shear_modulus_Pa", "young_Pa", "poisson", "density_kg_m3"};
    if (grain) keys.insert({"shape", "aspect_ratio"});
    const json& j = object_with(root.at(field), file, field, keys);
    if (grain && j.contains("shape") && j.at("shape") != "wheat-clump")
        throw UserError(file + ": " + field + ".shape = " + analytics::json_value_text(j.at("shape")) +
                        ": the silo case has one grain shape, \"wheat-clump\" (the seed's 3-sphere grain)");
    ks::Material m{};
    m.poisson = number(j, file, field, "poisson");
    m.density = number(j, file, field, "density_kg_m3");
    const bool has_g = j.contains("shear_modulus_Pa"), has_e = j.contains("young_Pa");
    if (has_g == has_e)
        throw UserError(file + ": " + field + ": give exactly one of shear_modulus_Pa and young_Pa (G = E / (2 (1 + nu)))");
    m.shear_modulus = has_g ? number(j, file, field, "shear_modulus_Pa")
                            : number(j, file, field, "young_Pa") / (2 * (1 + m.poisson));
    return m;
}

// The grain's length over its width (optional: the seed's 11/6); the family and its bounds: kernel/silo/wheat.hpp.
double grain_aspect_ratio(const json& root, const std::string& file) {
    const json& grain = root.at("grain");
    if (!grain.contains("aspect_ratio")) return ks::wheat_aspect_ratio;
    const double ratio = number(grain, file, "grain", "aspect_ratio");
    if (!(ratio >= ks::min_grain_aspect_ratio && ratio <= ks::max_grain_aspect_ratio))
        throw UserError(file + ": grain.aspect_ratio = " + analytics::number_text(ratio) +
                        ": must lie in [1, 2.6] (the grain's length / width: 1 a sphere, the seed's wheat 1.833; "
                        "beyond 2.6 the three spheres would no longer overlap)");
    return ratio;
}

ks::PairCoefficients pair(const json& root, const std::string& file, const std::string& field) {
    if (!root.contains(field)) throw UserError(file + ": " + field + " is missing");
    const json& j = object_with(root.at(field), file, field,
                                {"restitution", "friction", "rolling_friction", "surface_energy_J_m2"});
    ks::PairCoefficients p{number(j, file, field, "restitution"), number(j, file, field, "friction"),
                           number(j, file, field, "rolling_friction")};
    // optional: a cohesionless pair need not say so
    if (j.contains("surface_energy_J_m2")) p.surface_energy = number(j, file, field, "surface_energy_J_m2");
    return p;
}

}  // namespace

ks::WheatMaterials read_silo_material(const std::string& path, const std::string& what) {
    const json root = read_json_file(path, what);
    const std::string file = "--" + what + " = '" + analytics::shortened_text(path, 200) + "'";  // for the messages
    if (root.is_object() && !root.contains("grain") && (root.contains("young_modulus") || root.contains("density")))
        throw UserError(file + ": a shear box's material (density, young_modulus, ...: demcal shear, sensitivity, "
                        "calibrate), not a silo material (grain, wall, grain_grain, grain_wall)");
    object_with(root, file, "", {"name", "description", "grain", "wall", "grain_grain", "grain_wall"});
    ks::WheatMaterials m;
    m.wheat = solid(root, file, "grain", true);
    m.grain_aspect_ratio = grain_aspect_ratio(root, file);
    m.steel = solid(root, file, "wall", false);
    m.wheat_wheat = pair(root, file, "grain_grain");
    m.wheat_steel = pair(root, file, "grain_wall");
    try {
        ks::validate(m);  // here, so that the message names the file
    } catch (const std::invalid_argument& e) {
        throw UserError(file + ": " + e.what());
    }
    return m;
}

json silo_material_json(const ks::WheatMaterials& m) {
    const auto solid = [](const ks::Material& s) {
        return json{{"shear_modulus_Pa", s.shear_modulus}, {"poisson", s.poisson}, {"density_kg_m3", s.density}};
    };
    const auto pair = [](const ks::PairCoefficients& p) {
        json j{{"restitution", p.restitution}, {"friction", p.friction}, {"rolling_friction", p.rolling_friction}};
        // only when cohesive: a cohesionless material's JSON (and the identities built on it) stays as it was
        if (p.surface_energy > 0) j["surface_energy_J_m2"] = p.surface_energy;
        return j;
    };
    json grain = solid(m.wheat);
    grain["shape"] = "wheat-clump";
    // only when not the seed's: the seed grain's JSON (and the identities built on it) stays as it was
    if (m.grain_aspect_ratio != ks::wheat_aspect_ratio) grain["aspect_ratio"] = m.grain_aspect_ratio;
    return {{"grain", grain}, {"wall", solid(m.steel)}, {"grain_grain", pair(m.wheat_wheat)},
            {"grain_wall", pair(m.wheat_steel)}};
}

}  // namespace demcal
