#include "analytics/discharge_models.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

namespace demcal::analytics {

namespace {
constexpr double pi = std::numbers::pi;
double rad(double deg) { return deg * pi / 180.0; }
double deg(double rad) { return rad * 180.0 / pi; }

// Smallest outlet-to-particle ratio for which Beverloo-type correlations hold (Mankoc et al. 2007: d > 5-6 d_p).
constexpr double min_outlet_particle_ratio = 6.0;
// Below it no model predicts a steady flow: the seed (2.1) needs d > 3.5-4 d_p for cohesionless grains to discharge
// by gravity at all; smaller outlets clog with stable arches. The upper end, as the seed designed its silo by it.
constexpr double min_free_flow_outlet_ratio = 4.0;
constexpr double min_coarse_particle_size = 0.4e-3;  // [m] below it, a powder: air-retarded flow
// Silo-to-outlet ratio below which wall effects matter (the seed: D/d > 2.5 is conventional).
constexpr double min_silo_outlet_ratio = 2.5;

// A ratio of two decimal inputs on a limit (a 70 mm outlet in a 100 mm silo: a/c = 0.7) lands a rounding error on
// either side of it; the limits are inclusive, so a value within this relative slack of one is on it.
constexpr double limit_slack = 1e-9;
bool below(double value, double limit) { return value < limit * (1 - limit_slack); }
bool above(double value, double limit) { return value > limit * (1 + limit_slack); }

// The outlet's narrowest side: a slot's width a, or its length b where the slot is longer than the silo is deep.
double narrowest_opening(const SiloGeometry& g) {
    return g.shape == SiloShape::rectangular ? std::min(g.outlet, g.depth) : g.outlet;
}
}  // namespace

double beverloo_rate(double outlet, double particle_size, double bulk_density, double c, double k) {
    const double effective = outlet - k * particle_size;
    if (effective <= 0) return 0.0;
    return c * bulk_density * std::sqrt(standard_gravity) * std::pow(effective, 2.5);
}

double beverloo_slot_rate(double slot_length, double slot_width, double particle_size, double bulk_density, double c,
                          double k) {
    const double length = slot_length - k * particle_size, width = slot_width - k * particle_size;
    if (length <= 0 || width <= 0) return 0.0;
    return c * bulk_density * std::sqrt(standard_gravity) * length * std::pow(width, 1.5);
}

// Johanson (1965): at the outlet of a mass-flow hopper the radial stress field gives an outlet velocity
// v = sqrt(B g / (2 (1 + m) tan theta)) with B the outlet diameter (cone, m = 1) or width (wedge, m = 0).
double johanson_conical_rate(double outlet, double half_angle_deg, double bulk_density) {
    const double area = pi * outlet * outlet / 4.0;
    return bulk_density * area * std::sqrt(outlet * standard_gravity / (4.0 * std::tan(rad(half_angle_deg))));
}

double johanson_wedge_rate(double slot_length, double slot_width, double half_angle_deg, double bulk_density) {
    const double area = slot_length * slot_width;
    return bulk_density * area * std::sqrt(slot_width * standard_gravity / (2.0 * std::tan(rad(half_angle_deg))));
}

// Oldal's arch model, derived here from the same assumptions as the seed's rectangular form (eqs. 3.3-3.6): below a
// paraboloid arch f(r) = h (1 - (2r/d)^2) with apex h = delta d the grains fall freely, v(r) = sqrt(2 g f(r)).
// Q = int_0^{d/2} sqrt(2 g delta d) sqrt(1 - (2r/d)^2) 2 pi r dr; with u = 2r/d:
// Q = sqrt(2 g delta d) (pi d^2 / 2) int_0^1 u sqrt(1 - u^2) du = sqrt(2 g delta d) (pi d^2 / 2) / 3
//   = (pi sqrt(2g) / 6) sqrt(delta) d^2.5, and with the effective outlet d - d_p, W = rho_b Q.
// Checked: the same integral over a parabolic cylinder gives the seed's eq. 3.5, (pi/4) sqrt(2 g delta a) a b,
// because int_{-1}^{1} sqrt(1 - u^2) du = pi/2; and the circular form is Beverloo with k = 1, C = 0.7405 sqrt(delta).
// (Not checked against Oldal et al. 2012 itself, which we could not read.)
double oldal_rate(double outlet, double particle_size, double bulk_density, double delta) {
    const double effective = outlet - particle_size;
    if (effective <= 0 || delta <= 0) return 0.0;
    return pi * std::sqrt(2.0 * standard_gravity) / 6.0 * std::sqrt(delta) * bulk_density * std::pow(effective, 2.5);
}

double oldal_rectangular_rate(double depth, double outlet, double particle_size, double bulk_density, double delta) {
    const double effective = outlet - particle_size;
    if (effective <= 0 || delta <= 0) return 0.0;
    return pi * std::sqrt(2.0 * standard_gravity) / 4.0 * std::sqrt(delta) * bulk_density * depth *
           std::pow(effective, 1.5);
}

// Continuous at theta = 90 - phi_d (tan theta tan phi_d = 1); steeper hoppers (smaller theta) discharge faster.
double rose_tanaka_factor(double half_angle_deg, double stagnant_angle_deg) {
    if (half_angle_deg >= 90.0 - stagnant_angle_deg) return 1.0;
    return std::pow(std::tan(rad(half_angle_deg)) * std::tan(rad(stagnant_angle_deg)), -0.35);
}

double jenike_mass_flow_limit_deg(double effective_friction_deg, double wall_friction_deg) {
    if (!(effective_friction_deg > 0 && effective_friction_deg < 90))
        throw std::invalid_argument("delta_e_deg=" + number_text(effective_friction_deg) + " not in (0, 90)");
    if (!(wall_friction_deg >= 0 && wall_friction_deg < 90))
        throw std::invalid_argument("phi_w_deg=" + number_text(wall_friction_deg) + " not in [0, 90)");
    // the approximation's arccos needs sin(delta_e) >= 1/3; bulk solids lie well above (wheat: about 30-40 deg)
    if (std::sin(rad(effective_friction_deg)) < 1.0 / 3.0)
        throw std::invalid_argument("delta_e_deg=" + number_text(effective_friction_deg) +
                                    " is below 19.47 deg, where the approximation of Jenike's mass-flow limit is "
                                    "not defined (sin(delta_e) < 1/3)");
    if (wall_friction_deg >= effective_friction_deg)
        throw std::invalid_argument("phi_w_deg=" + number_text(wall_friction_deg) +
                                    " is not below delta_e_deg=" + number_text(effective_friction_deg) +
                                    ": the wall is rougher than the bulk, no mass flow is possible");
    const double se = std::sin(rad(effective_friction_deg)), sw = std::sin(rad(wall_friction_deg));
    const double beta = 0.5 * (wall_friction_deg + deg(std::asin(sw / se)));
    return 90.0 - 0.5 * deg(std::acos((1.0 - se) / (2.0 * se))) - beta;
}

std::vector<std::string> oldal_rectangular_limit_violations(double depth, double width, double outlet) {
    std::vector<std::string> out;
    const double cb = width / depth, ac = outlet / width;
    if (below(cb, 1.0) || above(cb, 4.0)) out.push_back("c/b = " + number_text(cb) + " outside the validated range 1 <= c/b <= 4");
    if (below(ac, 0.15) || above(ac, 0.7)) out.push_back("a/c = " + number_text(ac) + " outside the validated range 0.15 <= a/c <= 0.7");
    return out;
}

namespace {
struct PlausibleRange {
    double low, high;
    const char* unit;
    const char* why;
};

// `shown`: what precedes the value ("rho_b_kg_m3=", "data.csv: line 3, column rho_b_kg_m3: ")
void check_in_range(const std::string& shown, double v, const PlausibleRange& r) {
    if (!(v >= r.low && v <= r.high))
        throw std::invalid_argument(shown + number_text(v, 10) + " outside [" + number_text(r.low) + ", " +
                                    number_text(r.high) + "]" + (*r.unit ? std::string(" ") + r.unit : std::string()) +
                                    " (" + r.why + ")");
}
}  // namespace

void check_plausible_silo_quantity(const std::string& field, double value, const std::string& where) {
    // the bounds of bulk solids and silos, wide enough for any real case
    static const char* const silo_size = "no silo is larger than 100 m";  // the largest are about 50 m across
    static const std::map<std::string, PlausibleRange> ranges{
        {"outlet_m", {0, 100, "m", silo_size}},
        {"D_m", {0, 100, "m", silo_size}},
        {"b_m", {0, 100, "m", silo_size}},
        {"c_m", {0, 100, "m", silo_size}},
        {"d_p_m", {1e-6, 1, "m", "bulk solids: from 1 um powders to 1 m rocks"}},
        {"rho_b_kg_m3",
         {10, 2e4, "kg/m^3", "bulk solids: from about 30 kg/m^3 (expanded perlite) to about 12000 (tungsten powder)"}},
        {"W_kg_s", {0, 1e5, "kg/s", "the largest ship loaders discharge about 10 t/s"}},
    };
    const auto range = ranges.find(field);
    if (range == ranges.end()) throw std::logic_error("no plausible range for the silo quantity " + field);
    check_in_range(where.empty() ? field + "=" : where + ": ", value, range->second);
}

void validate(const SiloGeometry& g) {
    auto positive = [](const char* field, double v) {
        if (!(std::isfinite(v) && v > 0)) throw std::invalid_argument(std::string(field) + "=" + number_text(v) + " must be > 0");
    };
    positive("outlet_m", g.outlet);
    positive("d_p_m", g.particle_size);
    positive("rho_b_kg_m3", g.bulk_density);
    // Finite but absurd values (a bulk density of 0.001 kg/m^3, a silo 1e99 m across) gave rates reported as valid.
    check_plausible_silo_quantity("outlet_m", g.outlet);
    check_plausible_silo_quantity("d_p_m", g.particle_size);
    check_plausible_silo_quantity("rho_b_kg_m3", g.bulk_density);
    if (!(g.half_angle_deg > 0 && g.half_angle_deg <= 90))
        throw std::invalid_argument("theta_deg=" + number_text(g.half_angle_deg) + " not in (0, 90] (90 = flat bottom)");
    if (g.outlet <= g.particle_size)
        throw std::invalid_argument("outlet_m=" + number_text(g.outlet) + " is not larger than the particles (d_p_m=" +
                                    number_text(g.particle_size) + ")");
    if (g.shape == SiloShape::conical) {
        positive("D_m", g.silo_diameter);
        check_plausible_silo_quantity("D_m", g.silo_diameter);
        if (g.outlet >= g.silo_diameter)
            throw std::invalid_argument("outlet_m=" + number_text(g.outlet) + " is not smaller than the silo, D_m=" +
                                        number_text(g.silo_diameter));
    } else {
        positive("b_m", g.depth);
        positive("c_m", g.width);
        check_plausible_silo_quantity("b_m", g.depth);
        check_plausible_silo_quantity("c_m", g.width);
        if (g.outlet >= g.width)
            throw std::invalid_argument("outlet_m=" + number_text(g.outlet) + " is not smaller than the silo width, c_m=" +
                                        number_text(g.width));
    }
    positive("beverloo_C", g.beverloo_c);
    if (!(g.beverloo_k >= 0)) throw std::invalid_argument("beverloo_k=" + number_text(g.beverloo_k) + " must be >= 0");
    positive("slot_C", g.slot_c);
    positive("delta", g.arch_delta);
    // model constants: several times their literature values at most (C 0.55-0.65, k 1-3, C' ~1.03, delta ~0.5)
    auto plausible = [](const char* field, double v, double lo, double hi, const char* unit, const char* why) {
        check_in_range(std::string(field) + "=", v, {lo, hi, unit, why});
    };
    plausible("beverloo_C", g.beverloo_c, 0, 3, "", "Beverloo's C is 0.55-0.65 in the literature");
    plausible("beverloo_k", g.beverloo_k, 0, 10, "", "Beverloo's k is 1-3 in the literature");
    plausible("slot_C", g.slot_c, 0, 5, "", "Myers and Sellers' C' is about 1");
    plausible("delta", g.arch_delta, 0, 10, "", "Oldal's arch height over the outlet is about 0.5");
    // Beverloo's empty annulus k d_p must leave an opening, or its rate is 0 for any silo (k is 1-3 in the literature)
    const double opening = narrowest_opening(g);
    if (g.beverloo_k * g.particle_size >= opening) {
        // the field that gives the narrowest side: a rectangular outlet is outlet_m by b_m (the silo's depth)
        const std::string side = g.shape == SiloShape::rectangular && g.depth < g.outlet
                                     ? "the outlet's narrower side, the silo depth b_m=" + number_text(g.depth)
                                     : "the outlet, outlet_m=" + number_text(g.outlet);
        throw std::invalid_argument("beverloo_k=" + number_text(g.beverloo_k) + " with d_p_m=" +
                                    number_text(g.particle_size) + ": k d_p = " +
                                    number_text(g.beverloo_k * g.particle_size) + " m is not smaller than " + side +
                                    " m: Beverloo's effective outlet would be empty");
    }
    if (!(g.stagnant_angle_deg > 0 && g.stagnant_angle_deg < 90))
        throw std::invalid_argument("phi_d_deg=" + number_text(g.stagnant_angle_deg) + " not in (0, 90)");
    if (g.effective_friction_deg.has_value() != g.wall_friction_deg.has_value())
        throw std::invalid_argument("delta_e_deg and phi_w_deg go together: give both or neither");
    if (g.effective_friction_deg) jenike_mass_flow_limit_deg(*g.effective_friction_deg, *g.wall_friction_deg);
}

nlohmann::json DischargePrediction::to_json() const {
    nlohmann::json j{{"model", model}, {"valid", valid}, {"warnings", warnings}};
    j["W_kg_s"] = rate ? nlohmann::json(*rate) : nlohmann::json(nullptr);
    return j;
}

namespace {

// Jenike's conical limit decides the flow pattern; for a wedge the plane-flow limit is wider, so the conical limit
// only proves mass flow there (theta below it), it cannot prove funnel flow.
struct FlowPatternCheck {
    std::optional<bool> mass_flow;  // unknown without the effective and wall friction angles
    std::string note = "flow pattern unknown: give delta_e_deg and phi_w_deg to check it";
};

FlowPatternCheck check_flow_pattern(const SiloGeometry& g) {
    FlowPatternCheck c;
    const double theta = g.half_angle_deg;
    if (theta >= 90) {  // a flat bottom: no hopper wall to slide along, funnel flow whatever the frictions
        c.mass_flow = false;
        c.note = "funnel flow (flat bottom, theta = 90)";
        return c;
    }
    if (!g.effective_friction_deg) return c;
    const double limit = jenike_mass_flow_limit_deg(*g.effective_friction_deg, *g.wall_friction_deg);
    if (theta < limit) {
        c.mass_flow = true;
        c.note = "mass flow (theta " + number_text(theta) + " < Jenike limit " + number_text(limit) + " deg)";
    } else if (g.shape == SiloShape::conical) {
        c.mass_flow = false;
        c.note = "funnel flow (theta " + number_text(theta) + " >= Jenike limit " + number_text(limit) + " deg)";
    } else {
        c.note = "theta " + number_text(theta) + " >= conical Jenike limit " + number_text(limit) +
                 " deg; the plane-flow limit of a wedge is wider, flow pattern not decided";
    }
    return c;
}

// The checks the models share, each adding its warning to a prediction (and invalidating it where it rules it out).
// A model made for one flow pattern: not valid where the check found the other, a warning where it could not tell.
enum class ModelFlow { mass, funnel };
void check_model_flow(DischargePrediction& p, const FlowPatternCheck& flow, ModelFlow made_for) {
    if (!flow.mass_flow) {
        p.warnings.push_back(flow.note);
    } else if (*flow.mass_flow != (made_for == ModelFlow::mass)) {
        p.valid = false;
        p.warnings.push_back(std::string(made_for == ModelFlow::mass ? "a mass-flow" : "a funnel-flow") +
                             " model used in " + flow.note);
    }
}

// An outlet of fewer than `min_grains` grains across its narrowest side: not valid, with what then happens.
void check_outlet_grains(DischargePrediction& p, const SiloGeometry& g, double min_grains, const char* consequence) {
    const double grains = narrowest_opening(g) / g.particle_size;
    if (below(grains, min_grains)) {
        p.valid = false;
        p.warnings.push_back("outlet/d_p = " + number_text(grains) + " < " + number_text(min_grains) + ": " +
                             consequence);
    }
}

// Beverloo-type correlations: fitted to outlets of more than 6 grains.
void check_outlet_ratio(DischargePrediction& p, const SiloGeometry& g) {
    check_outlet_grains(p, g, min_outlet_particle_ratio, "intermittent flow and clogging, correlation not valid");
}

// Every model: an outlet of fewer than 4 grains arches over, with no steady flow to predict.
void check_free_flow(DischargePrediction& p, const SiloGeometry& g) {
    check_outlet_grains(p, g, min_free_flow_outlet_ratio,
                        "stable arches likely (the seed: d > 3.5-4 d_p for a gravity discharge), no steady flow to "
                        "predict");
}

// Every model here is for coarse, free-flowing grains: below about 0.4 mm the interstitial air's pressure gradient
// slows the flow (Nedderman 1992, Statics and Kinematics of Granular Materials) and they overpredict it.
void check_coarse_particles(DischargePrediction& p, const SiloGeometry& g) {
    if (p.rate && g.particle_size < min_coarse_particle_size) {
        p.valid = false;
        p.warnings.push_back("d_p = " + number_text(g.particle_size) + " m < " + number_text(min_coarse_particle_size) +
                             " m: a fine powder, the interstitial air slows the flow, the model overpredicts");
    }
}

// A model of the other silo shape: no rate, and why.
bool refuse_shape(DischargePrediction& p, const SiloGeometry& g, SiloShape applies_to) {
    if (g.shape == applies_to) return false;
    p.valid = false;
    p.warnings.push_back(std::string("applies to ") + (applies_to == SiloShape::conical ? "conical" : "rectangular") +
                         " silos only");
    return true;
}

// One function per model: its rate where it applies, its warnings.
DischargePrediction predict_beverloo(const SiloGeometry& g, const FlowPatternCheck& flow) {
    DischargePrediction p;
    p.model = "beverloo";
    if (refuse_shape(p, g, SiloShape::conical)) return p;
    p.rate = beverloo_rate(g.outlet, g.particle_size, g.bulk_density, g.beverloo_c, g.beverloo_k);
    check_outlet_ratio(p, g);
    check_model_flow(p, flow, ModelFlow::funnel);  // the seed (2.3): Beverloo's correlation is for funnel flow
    if (below(g.silo_diameter / g.outlet, min_silo_outlet_ratio))
        p.warnings.push_back("D/d = " + number_text(g.silo_diameter / g.outlet) + " < 2.5: wall effects likely");
    if (rose_tanaka_factor(g.half_angle_deg, g.stagnant_angle_deg) > 1.0)
        p.warnings.push_back("hopper steeper than the stagnant zone (theta < 90 - phi_d): Beverloo "
                             "underestimates, see beverloo+rose-tanaka");
    check_coarse_particles(p, g);
    return p;
}

DischargePrediction predict_beverloo_rose_tanaka(const SiloGeometry& g) {
    DischargePrediction p;
    p.model = "beverloo+rose-tanaka";
    if (refuse_shape(p, g, SiloShape::conical)) return p;
    p.rate = beverloo_rate(g.outlet, g.particle_size, g.bulk_density, g.beverloo_c, g.beverloo_k) *
             rose_tanaka_factor(g.half_angle_deg, g.stagnant_angle_deg);
    check_outlet_ratio(p, g);
    check_coarse_particles(p, g);
    return p;
}

DischargePrediction predict_beverloo_slot(const SiloGeometry& g, const FlowPatternCheck& flow) {
    DischargePrediction p;
    p.model = "beverloo-slot";
    if (refuse_shape(p, g, SiloShape::rectangular)) return p;
    p.rate = beverloo_slot_rate(g.depth, g.outlet, g.particle_size, g.bulk_density, g.slot_c, g.beverloo_k);
    check_outlet_ratio(p, g);
    check_model_flow(p, flow, ModelFlow::funnel);
    check_coarse_particles(p, g);
    return p;
}

DischargePrediction predict_johanson(const SiloGeometry& g, const FlowPatternCheck& flow) {
    const bool conical = g.shape == SiloShape::conical;
    const double theta = g.half_angle_deg;
    DischargePrediction p;
    p.model = conical ? "johanson-conical" : "johanson-wedge";
    if (theta >= 90.0) {
        p.valid = false;
        p.warnings.push_back("flat bottom (theta = 90): Johanson's hopper model does not apply");
        return p;
    }
    p.rate = conical ? johanson_conical_rate(g.outlet, theta, g.bulk_density)
                     : johanson_wedge_rate(g.depth, g.outlet, theta, g.bulk_density);
    check_free_flow(p, g);
    check_model_flow(p, flow, ModelFlow::mass);
    check_coarse_particles(p, g);
    return p;
}

DischargePrediction predict_oldal(const SiloGeometry& g, const FlowPatternCheck& flow) {
    DischargePrediction p;
    p.model = "oldal";
    if (refuse_shape(p, g, SiloShape::conical)) return p;
    p.rate = oldal_rate(g.outlet, g.particle_size, g.bulk_density, g.arch_delta);
    check_free_flow(p, g);
    check_model_flow(p, flow, ModelFlow::funnel);
    check_coarse_particles(p, g);
    return p;
}

DischargePrediction predict_oldal_rectangular(const SiloGeometry& g, const FlowPatternCheck& flow) {
    DischargePrediction p;
    p.model = "oldal-rect";
    if (refuse_shape(p, g, SiloShape::rectangular)) return p;
    p.rate = oldal_rectangular_rate(g.depth, g.outlet, g.particle_size, g.bulk_density, g.arch_delta);
    for (auto& w : oldal_rectangular_limit_violations(g.depth, g.width, g.outlet)) {
        p.valid = false;
        p.warnings.push_back(w);
    }
    check_free_flow(p, g);
    check_model_flow(p, flow, ModelFlow::funnel);
    check_coarse_particles(p, g);
    return p;
}

}  // namespace

std::vector<DischargePrediction> predict_discharge(const SiloGeometry& g) {
    validate(g);
    const FlowPatternCheck flow = check_flow_pattern(g);
    return {predict_beverloo(g, flow), predict_beverloo_rose_tanaka(g), predict_beverloo_slot(g, flow),
            predict_johanson(g, flow), predict_oldal(g, flow), predict_oldal_rectangular(g, flow)};
}

SiloGeometry geometry_from_json(const nlohmann::json& j) {
    if (!j.is_object()) throw std::invalid_argument("geometry: expected a JSON object, got " + json_value_text(j));
    SiloGeometry g;
    auto number = [&](const std::string& key) -> std::optional<double> {
        if (!j.contains(key)) return std::nullopt;
        const auto& v = j.at(key);
        if (!v.is_number()) throw std::invalid_argument("geometry: " + key + "=" + json_value_text(v) + " is not a number");
        return v.get<double>();
    };
    auto required = [&](const std::string& key) {
        auto v = number(key);
        if (!v) throw std::invalid_argument("geometry: missing key " + key);
        return *v;
    };
    static const std::vector<std::string> known{"geometry", "D_m",        "b_m",        "c_m",        "outlet_m",
                                                "theta_deg", "d_p_m",     "rho_b_kg_m3", "beverloo_C", "beverloo_k",
                                                "slot_C",    "delta",     "phi_d_deg",   "delta_e_deg", "phi_w_deg"};
    for (const auto& [key, value] : j.items())  // (a key starting with '_' is a comment, as in the silo's files)
        if (std::find(known.begin(), known.end(), key) == known.end() && key.rfind('_', 0) != 0)
            throw std::invalid_argument("geometry: unknown key " + shortened_text(key) + "=" + json_value_text(value));
    if (!j.contains("geometry") || !j.at("geometry").is_string())
        throw std::invalid_argument("geometry: key geometry must be \"conical\" or \"rectangular\"" +
                                    (j.contains("geometry") ? ", got " + json_value_text(j.at("geometry")) : std::string()));
    const auto shape = j.at("geometry").get<std::string>();
    if (shape == "conical") {
        g.shape = SiloShape::conical;
        g.silo_diameter = required("D_m");
        for (const char* k : {"b_m", "c_m", "slot_C"})  // (slot_C: Myers and Sellers' slot, rectangular outlets only)
            if (j.contains(k)) throw std::invalid_argument(std::string("geometry: ") + k + " is for rectangular silos");
    } else if (shape == "rectangular") {
        g.shape = SiloShape::rectangular;
        g.depth = required("b_m");
        g.width = required("c_m");
        if (j.contains("D_m")) throw std::invalid_argument("geometry: D_m is for conical silos");
    } else {
        throw std::invalid_argument("geometry: geometry=\"" + shortened_text(shape) + "\", expected conical or rectangular");
    }
    g.outlet = required("outlet_m");
    g.half_angle_deg = required("theta_deg");
    g.particle_size = required("d_p_m");
    g.bulk_density = required("rho_b_kg_m3");
    if (auto v = number("beverloo_C")) g.beverloo_c = *v;
    if (auto v = number("beverloo_k")) g.beverloo_k = *v;
    if (auto v = number("slot_C")) g.slot_c = *v;
    if (auto v = number("delta")) g.arch_delta = *v;
    if (auto v = number("phi_d_deg")) g.stagnant_angle_deg = *v;
    g.effective_friction_deg = number("delta_e_deg");
    g.wall_friction_deg = number("phi_w_deg");
    try {
        validate(g);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("geometry: ") + e.what());
    }
    return g;
}

}  // namespace demcal::analytics
