#include "orchestrator/shear_params.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace demcal::orchestrator {

namespace {
constexpr double inf = std::numeric_limits<double>::infinity();

std::string format_value(const nlohmann::json& v) { return analytics::json_value_text(v); }

std::string range_text(const ParamSpec& s) {
    std::ostringstream o;
    o << (s.min_exclusive ? "(" : "[") << s.min << ", " << s.max << (s.max_exclusive ? ")" : "]");
    return o.str();
}
}  // namespace

const std::vector<ParamSpec>& shear_param_specs() {
    // Defaults of the test set-up follow the seed (box 0.1 x 0.1 x 0.05 m); the micromechanical ones have none.
    static const std::vector<ParamSpec> specs = {
        {"density", "kg/m^3", "particle material density", std::nullopt, 0, 1e5, true},
        {"young_modulus", "Pa", "Young modulus of the particle material (YADE CohFrictMat.young)", std::nullopt, 0, 1e13,
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
        {"damping", "-", "YADE NewtonIntegrator (Cundall) damping", 0.2, 0, 1, false, true},
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
}
}  // namespace

nlohmann::json validate_material(const nlohmann::json& material, const std::string& where) {
    if (!material.is_object()) throw std::invalid_argument(where + ": a material must be a JSON object");
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [key, value] : material.items()) {
        if (key == "name" || key == "description" || key.rfind("_comment", 0) == 0) {  // documentation, not physics
            if (!value.is_string())
                throw std::invalid_argument(where + ": field '" + key + "' must be a string, got " + format_value(value));
            continue;
        }
        const ParamSpec* s = find_shear_param(key);
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
    return out;
}

nlohmann::json make_run_params(const nlohmann::json& validated_material, double normal_stress, long seed) {
    nlohmann::json p = validated_material;
    p["normal_stress"] = normal_stress;
    p["seed"] = seed;
    check_value(*find_shear_param("normal_stress"), p["normal_stress"], "run");
    check_value(*find_shear_param("seed"), p["seed"], "run");
    return p;
}

}  // namespace demcal::orchestrator
