#include "analytics/diagnose_synthetic.hpp"

#include "analytics/diagnose.hpp"
#include "analytics/discharge_models.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace demcal::analytics {

namespace {

std::string format(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return buf;
}

struct Table {
    MeasuredData data;
    DataColumn& column(const std::string& name, bool numeric) {
        for (auto& c : data.columns)
            if (c.name == name) return c;
        data.columns.push_back(DataColumn{name, numeric, {}, {}});
        return data.columns.back();
    }
    void number(const std::string& name, double v) {
        auto& c = column(name, true);
        c.values.push_back(v);
        c.text.push_back(std::isnan(v) ? std::string() : format(v));
    }
    void text(const std::string& name, const std::string& v) { column(name, false).text.push_back(v); }
};

// One experimental condition (the silo set-up or the normal stress).
struct Condition {
    double outlet = 0, theta = 0, dp = 0, rho = 0, depth = 0, sigma = 0;
};

// What a spec asks for, once it is known to be consistent.
struct SpecKind {
    bool shear = false, rectangular = false;
    bool by_mode = false;       // vibration's effect depends on the flow mode
    bool hopper_angle = false;  // Rose-Tanaka's angle factor
};

SpecKind checked_kind(const SyntheticSpec& spec) {
    SpecKind k;
    k.shear = spec.model == "failure-line";
    k.rectangular = spec.model == "oldal-rect";
    if (!k.shear && !k.rectangular && spec.model != "oldal" && spec.model != "beverloo" && spec.model != "johanson")
        throw std::invalid_argument("synthetic set: unknown model " + spec.model);
    const bool known = spec.effect == "none" || std::any_of(synthetic_effects().begin(), synthetic_effects().end(),
                                                            [&](const auto& e) { return e.first == spec.effect; });
    if (!known) throw std::invalid_argument("synthetic set: unknown effect " + spec.effect);
    if ((spec.effect == "curved_locus") != k.shear &&
        (spec.effect == "curved_locus" || spec.effect == "hopper_angle" || spec.effect == "annulus"))
        throw std::invalid_argument("synthetic set: effect " + spec.effect + " does not apply to " + spec.model);
    k.by_mode = spec.effect == "vibration_by_mode" || spec.effect == "hopper_angle+vibration_by_mode";
    k.hopper_angle = spec.effect == "hopper_angle" || spec.effect == "hopper_angle+vibration_by_mode";
    if (k.by_mode && spec.model != "beverloo" && spec.model != "oldal")
        throw std::invalid_argument("synthetic set: effect " + spec.effect + " needs a conical model that ignores "
                                    "the angle (beverloo, oldal), not " + spec.model);
    if (spec.replicates < 1) throw std::invalid_argument("synthetic set: replicates must be >= 1");
    return k;
}

// A factorial design of conditions, like a lab campaign.
std::vector<Condition> design_conditions(const SyntheticSpec& spec, const SpecKind& kind) {
    std::vector<Condition> conditions;
    if (kind.shear) {
        for (double sigma : {1e3, 2e3, 4e3, 6e3, 8e3, 10e3, 12e3, 15e3}) conditions.push_back({0, 0, 0, 0, 0, sigma});
        return conditions;
    }
    const std::vector<double> outlets = kind.rectangular ? std::vector<double>{0.02, 0.035, 0.05}
                                                         : std::vector<double>{0.025, 0.035, 0.05};
    // The flow-mode effect needs every mode: the seed's seven angles (mass 10-20, mixed 30-40, funnel 50-70).
    const std::vector<double> angles = kind.by_mode                ? std::vector<double>{10, 20, 30, 40, 50, 60, 70}
                                       : spec.model == "johanson" ? std::vector<double>{10, 20, 30}
                                       : kind.rectangular         ? std::vector<double>{20, 60}
                                                                  : std::vector<double>{20, 40, 60};
    const std::vector<double> depths = kind.rectangular ? std::vector<double>{0.04, 0.07} : std::vector<double>{0};
    for (double depth : depths)
        for (double outlet : outlets)
            for (double dp : {0.003, 0.005})
                for (double theta : angles)
                    conditions.push_back({outlet, theta, dp, dp < 0.004 ? 820.0 : 780.0, depth, 0});
    return conditions;
}

// The model and effect enter the seed so that one seed gives independent noise to different sets.
std::mt19937_64 seeded_rng(const SyntheticSpec& spec) {
    std::uint64_t mixed = 1469598103934665603ull;  // FNV-1a
    for (char ch : spec.model + "/" + spec.effect) mixed = (mixed ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
    return std::mt19937_64(spec.seed ^ mixed);
}

// Every condition's replicates, in a randomised run order (rows are written in run order).
struct RunPlan {
    std::vector<Condition> runs;
    std::vector<int> replicate;
    std::vector<std::size_t> order;
};

RunPlan plan_runs(const std::vector<Condition>& conditions, int replicates, std::mt19937_64& rng) {
    RunPlan plan;
    for (const auto& c : conditions)
        for (int r = 1; r <= replicates; ++r) {
            plan.runs.push_back(c);
            plan.replicate.push_back(r);
        }
    plan.order.resize(plan.runs.size());
    for (std::size_t i = 0; i < plan.order.size(); ++i) plan.order[i] = i;
    std::shuffle(plan.order.begin(), plan.order.end(), rng);
    return plan;
}

// The decoy covariates of one run (noise unless the effect lives in one of them).
struct Covariates {
    double moisture = 0, temperature = 0, vibration = 0;
    std::string op;
};

constexpr double kMaxVibrationHz = 50;  // vibration_Hz is 0, 25 or 50

// The undeclared effects' strengths, set from effect_size at the design's extremes.
struct EffectScales {
    double k0 = 1, exponent = 2.5;
    double k_true = 0;  // annulus: k chosen so that the smallest outlet with the largest grains loses effect_size
    double phi_d = 0;   // Rose-Tanaka: phi_d chosen so that the steepest hopper gains effect_size
};

EffectScales effect_scales(const SyntheticSpec& spec, const SpecKind& kind) {
    const double min_outlet = kind.rectangular ? 0.02 : 0.025, max_dp = 0.005, min_theta = 20;
    EffectScales e;
    e.k0 = spec.model == "johanson" ? 0.0 : 1.0;
    e.exponent = kind.rectangular ? 1.5 : 2.5;
    e.k_true = (min_outlet - std::pow(1 - spec.effect_size, 1 / e.exponent) * (min_outlet - e.k0 * max_dp)) / max_dp;
    e.phi_d = std::atan(std::pow(1 + spec.effect_size, -1 / 0.35) / std::tan(min_theta * M_PI / 180)) * 180 / M_PI;
    return e;
}

// The generating model's response at a condition, without the effect.
double model_response(const SyntheticSpec& spec, const SpecKind& kind, const Condition& c) {
    constexpr double mu_b = 0.55, tau_c = 400, sigma0 = 7e3;
    if (kind.shear) {
        const double n_exp = spec.effect == "curved_locus" ? 1 - spec.effect_size : 1.0;
        return tau_c + mu_b * sigma0 * std::pow(c.sigma / sigma0, n_exp);
    }
    if (spec.model == "beverloo") return beverloo_rate(c.outlet, c.dp, c.rho, 0.58, 1.5);
    if (spec.model == "johanson") return johanson_conical_rate(c.outlet, c.theta, c.rho);
    if (kind.rectangular) return oldal_rectangular_rate(c.depth, c.outlet, c.dp, c.rho, 0.45);
    return oldal_rate(c.outlet, c.dp, c.rho, 0.6);
}

// y with the spec's effect applied, at run `i` of `n` (the drift's clock).
double with_effect(double y, const SyntheticSpec& spec, const SpecKind& kind, const EffectScales& scales,
                   const Condition& c, const Covariates& v, std::size_t i, std::size_t n) {
    if (spec.effect == "moisture") y *= 1 - spec.effect_size * (v.moisture - 13) / 6;
    if (spec.effect == "drift") y *= 1 - spec.effect_size * i / (n - 1.0);
    if (spec.effect == "operator" && v.op == "C") y *= 1 + spec.effect_size;
    if (kind.hopper_angle) y *= rose_tanaka_factor(c.theta, scales.phi_d);
    if (kind.by_mode) {
        // +effect_size/2 in mass flow at the strongest vibration, -effect_size/2 in funnel flow: effect_size apart.
        const auto mode = flow_mode_by_seed_classes(c.theta);
        const double sign = mode == FlowMode::mass ? 1.0 : mode == FlowMode::funnel ? -1.0 : 0.0;
        y *= 1 + sign * spec.effect_size / 2 * v.vibration / kMaxVibrationHz;
    }
    if (spec.effect == "annulus")
        y *= std::pow((c.outlet - scales.k_true * c.dp) / (c.outlet - scales.k0 * c.dp), scales.exponent);
    return y;
}

// Row `i` of the table; its response is a placeholder until the noise scale is known.
void write_row(Table& t, const SpecKind& kind, const Condition& c, const Covariates& v, int replicate,
               std::size_t i) {
    if (kind.shear) {
        t.number("sigma_Pa", c.sigma);
    } else {
        t.text("geometry", kind.rectangular ? "rectangular" : "conical");
        if (kind.rectangular) {
            t.number("b_m", c.depth);
            t.number("c_m", 0.1);
        } else {
            t.number("D_m", 0.105);
        }
        t.number("outlet_m", c.outlet);
        t.number("theta_deg", c.theta);
        t.number("d_p_m", c.dp);
        t.number("rho_b_kg_m3", c.rho);
    }
    t.number(kind.shear ? "tau_Pa" : "W_kg_s", 0);
    t.number("replicate", replicate);
    t.number("run_order", static_cast<double>(i + 1));
    t.number("moisture_pct", v.moisture);
    t.number("temperature_C", std::round(v.temperature * 10) / 10);
    t.text("operator", v.op);
    t.number("vibration_Hz", v.vibration);
    t.data.lines.push_back(static_cast<int>(i + 2));
}

}  // namespace

const std::vector<std::pair<std::string, std::string>>& synthetic_effects() {
    static const std::vector<std::pair<std::string, std::string>> effects{
        {"moisture", "moisture_pct"}, {"hopper_angle", "theta_deg"}, {"annulus", "d_p_m"},
        {"drift", "run_order"},       {"operator", "operator"},      {"curved_locus", "sigma_Pa"},
        {"vibration_by_mode", "vibration_Hz"}, {"hopper_angle+vibration_by_mode", "vibration_Hz"}, {"outlier", ""}};
    return effects;
}

MeasuredData make_synthetic_set(const SyntheticSpec& spec) { return make_synthetic(spec).data; }

SyntheticSet make_synthetic(const SyntheticSpec& spec) {
    const SpecKind kind = checked_kind(spec);
    auto rng = seeded_rng(spec);
    const RunPlan plan = plan_runs(design_conditions(spec, kind), spec.replicates, rng);
    const EffectScales scales = effect_scales(spec, kind);
    // the draws of a row in a fixed order (moisture, temperature, operator, vibration): one seed, one table
    std::normal_distribution<double> normal(0, 1);
    std::uniform_real_distribution<double> moisture_dist(10, 16);
    std::uniform_int_distribution<int> operator_dist(0, 2), vibration_dist(0, 2);
    Table t;
    t.data.source = "synthetic(" + spec.model + "," + spec.effect + ",seed " + std::to_string(spec.seed) + ")";
    const std::size_t n = plan.runs.size();
    std::vector<double> clean(n);
    for (std::size_t i = 0; i < n; ++i) {
        const auto& c = plan.runs[plan.order[i]];
        Covariates v;
        v.moisture = std::round(moisture_dist(rng) * 10) / 10;
        v.temperature = 20 + 2 * normal(rng);
        v.op = std::string(1, static_cast<char>('A' + operator_dist(rng)));
        v.vibration = kMaxVibrationHz / 2 * vibration_dist(rng);
        clean[i] = with_effect(model_response(spec, kind, c), spec, kind, scales, c, v, i, n);
        write_row(t, kind, c, v, plan.replicate[plan.order[i]], i);
    }
    SyntheticSet set;
    if (spec.effect == "outlier") {
        const std::size_t row = std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
        clean[row] *= 1 + (std::bernoulli_distribution(0.5)(rng) ? 1 : -1) * spec.effect_size;
        set.outlier_line = t.data.lines[row];
    }
    double mean = 0;
    for (double v : clean) mean += v / n;
    auto& response = t.column(kind.shear ? "tau_Pa" : "W_kg_s", true);
    for (std::size_t i = 0; i < n; ++i) {
        const double e = normal(rng);
        response.values[i] = kind.shear ? clean[i] + spec.noise * mean * e : clean[i] * std::exp(spec.noise * e);
        response.text[i] = format(response.values[i]);
    }
    set.data = std::move(t.data);
    return set;
}

}  // namespace demcal::analytics
