// diagnose: effects that depend on a regime (flow mode, a categorical column) or on a condition variable (x*z).
#include "analytics/diagnose.hpp"
#include "analytics/diagnose_synthetic.hpp"
#include "synthetic_spec.hpp"
#include "analytics/discharge_models.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

using namespace demcal::analytics;
using demcal::analytics::test::spec;

namespace {

DataColumn& column(MeasuredData& d, const std::string& name) {
    for (auto& c : d.columns)
        if (c.name == name) return c;
    throw std::invalid_argument("no column " + name);
}

double param(const AddedEffect& e, const std::string& name) {
    for (const auto& p : e.params)
        if (p.name == name) return p.value;
    throw std::invalid_argument("no parameter " + name);
}

// A clean set whose rate is multiplied by factor(row).
template <class Factor>
MeasuredData with_factor(const SyntheticSpec& s, Factor factor) {
    auto d = make_synthetic_set(s);
    auto& w = column(d, "W_kg_s");
    for (std::size_t r = 0; r < d.rows(); ++r) w.values[r] *= factor(d, r);
    return d;
}
}  // namespace

TEST_CASE("diagnose: the flow mode follows the seed's classes, or Jenike's limit with the seed's mixed band", "[diagnose]") {
    CHECK(flow_mode_by_seed_classes(10) == FlowMode::mass);
    CHECK(flow_mode_by_seed_classes(20) == FlowMode::mass);
    CHECK(flow_mode_by_seed_classes(30) == FlowMode::mixed);
    CHECK(flow_mode_by_seed_classes(40) == FlowMode::mixed);
    CHECK(flow_mode_by_seed_classes(50) == FlowMode::funnel);
    CHECK(flow_mode_by_seed_classes(90) == FlowMode::funnel);
    CHECK(flow_mode_of_angle(24.9, 25) == FlowMode::mass);
    CHECK(flow_mode_of_angle(35, 25) == FlowMode::mixed);
    CHECK(flow_mode_of_angle(35.1, 25) == FlowMode::funnel);
}

TEST_CASE("diagnose: a vibration effect that changes sign with the flow mode is named by flow mode", "[diagnose]") {
    // The seed's finding at 30 % between the extremes: +15 % in mass flow at 50 Hz, none in mixed, -15 % in funnel.
    for (std::uint64_t seed : {31u, 32u, 33u}) {
        const auto r = diagnose(make_synthetic_set(spec("oldal", "vibration_by_mode", 0.3, seed)), "oldal");
        INFO("seed " << seed);
        REQUIRE(r.effects.size() == 1);
        const auto& e = r.effects[0];
        CHECK(e.variable == "vibration_Hz");
        CHECK(e.kind == "regime");
        CHECK(e.regime == "flow_mode");
        // Generating slopes: ln(1 +- 0.15)/50 Hz, about +-0.003 per Hz; mixed flow 0.
        CHECK(param(e, "beta[mass]") == Approx(std::log(1.15) / 50).margin(0.0008));
        CHECK(param(e, "beta[funnel]") == Approx(std::log(0.85) / 50).margin(0.0008));
        CHECK(std::abs(param(e, "beta[mixed]")) < 0.0008);
        CHECK(r.after.cv_rmse <= 0.5 * r.before.cv_rmse);
        CHECK(r.params_after[0].value == Approx(0.6).margin(4 * r.params_after[0].std_error));  // Oldal's delta
        CHECK(r.flow_mode_rule.find("seed classes") != std::string::npos);
    }
}

// The set of issue 26: a Rose-Tanaka angle effect and the vibration pattern together; diagnose used to name the angle
// alone, with phi_d biased by the missing term.
static double generating_phi_d(double effect_size) {  // as diagnose_synthetic: the 20 deg hopper gains effect_size
    return std::atan(std::pow(1 + effect_size, -1 / 0.35) / std::tan(20 * M_PI / 180)) * 180 / M_PI;
}

static const AddedEffect* find_effect(const DiagnoseResult& r, const std::string& variable, const std::string& kind) {
    for (const auto& e : r.effects)
        if (e.variable == variable && e.kind == kind) return &e;
    return nullptr;
}

TEST_CASE("diagnose: an angle effect and a flow-mode vibration effect together are both named", "[diagnose]") {
    for (std::uint64_t seed : {35u, 36u}) {
        const auto r =
            diagnose(make_synthetic_set(spec("beverloo", "hopper_angle+vibration_by_mode", 0.25, seed)), "beverloo");
        INFO("seed " << seed);
        CHECK(r.effects.size() == 2);
        const auto* vibration = find_effect(r, "vibration_Hz", "regime");
        const auto* angle = find_effect(r, "theta_deg", "physical");
        REQUIRE(vibration);
        REQUIRE(angle);
        CHECK(vibration->regime == "flow_mode");
        // phi_d of the final fit, with the vibration term beside it, is the generating one.
        CHECK(angle->params[0].value == Approx(generating_phi_d(0.25)).margin(3 * angle->params[0].std_error));
        CHECK(r.after.cv_rmse <= 0.5 * r.before.cv_rmse);
    }
}

TEST_CASE("diagnose: the flow mode by Jenike's limit replaces the seed's classes", "[diagnose]") {
    const auto data = make_synthetic_set(spec("oldal", "vibration_by_mode", 0.3, 34));
    DiagnoseOptions jenike;
    jenike.effective_friction_deg = 40;
    jenike.wall_friction_deg = 30;  // limit 12.5 deg: the 20 deg rows become mixed, 30-40 deg funnel
    const auto r = diagnose(data, "oldal", jenike);
    CHECK(r.flow_mode_rule.find("Jenike's limit 12.53") != std::string::npos);
    // The data follow the seed's classes, so modes from this limit predict them worse out of sample.
    const auto seed_classes = diagnose(data, "oldal");
    REQUIRE(!seed_classes.effects.empty());
    CHECK(seed_classes.effects[0].regime == "flow_mode");
    CHECK(r.after.cv_rmse > seed_classes.after.cv_rmse);
}

TEST_CASE("diagnose: a slope that differs by the values of a named column is found by that column", "[diagnose]") {
    // Operator C's runs lose rate with moisture (35 % over 10-16 %, about its middle, 13 %); A and B's do not. C
    // runs a third of the 36 rows, so in some seeds its moisture spread is too narrow to tell: 6 of 8 at least.
    int found = 0;
    for (std::uint64_t seed = 41; seed <= 48; ++seed) {
        const auto data = with_factor(spec("oldal", "none", 0, seed), [](const MeasuredData& d, std::size_t r) {
            const bool c = d.at("operator").text[r] == "C";
            return c ? std::exp(-std::log(1.35) * (d.at("moisture_pct").values[r] - 13) / 6) : 1.0;
        });
        DiagnoseOptions by_operator;
        by_operator.regime_columns = {"operator"};
        const auto r = diagnose(data, "oldal", by_operator);
        INFO("seed " << seed);
        if (r.effects.empty()) continue;
        CHECK(r.effects[0].variable == "moisture_pct");
        CHECK(r.effects[0].regime == "operator");
        if (r.effects[0].regime != "operator") continue;
        ++found;
        CHECK(param(r.effects[0], "beta[C]") < -2 * std::abs(param(r.effects[0], "beta[A]")));
        // Without the option the operator is no regime: whatever is found is not "by operator".
        for (const auto& e : diagnose(data, "oldal").effects) CHECK(e.regime != "operator");
    }
    CHECK(found >= 6);
}

TEST_CASE("diagnose: a slope that changes continuously with a condition variable is an x*z interaction", "[diagnose]") {
    // The temperature effect (about 20 C) grows with the outlet: none at the smallest, -8 %/C at the largest.
    const auto data = with_factor(spec("oldal", "none", 0, 51), [](const MeasuredData& d, std::size_t r) {
        const double outlet = d.at("outlet_m").values[r], t = d.at("temperature_C").values[r];
        return std::exp(-0.04 * (outlet - 0.025) / 0.025 * (t - 20));
    });
    const auto r = diagnose(data, "oldal");
    REQUIRE(!r.effects.empty());
    CHECK(r.effects[0].variable == "temperature_C");
    CHECK(r.effects[0].kind == "interaction");
    CHECK(r.effects[0].regime == "outlet_m");
    CHECK(param(r.effects[0], "gamma") < 0);
}

TEST_CASE("diagnose: a plain effect is not named by regime or x*z unless the extra slopes differ", "[diagnose]") {
    // A moisture effect that is the same in every condition: each regime or x*z candidate carries moisture's plain
    // part, so against the current model it was as significant as the plain term, and its CV, a few percent lower by
    // chance, named the effect by regime in about a quarter of the sets (an audit: 115-128 of 500). Now its extra
    // slopes must differ from the plain term's by a nested F test at the family's alpha.
    int named = 0, by_regime = 0;
    for (const std::string model : {"oldal", "beverloo", "johanson"})
        for (std::uint64_t seed = 1; seed <= 20; ++seed) {
            const auto r = diagnose(make_synthetic_set(spec(model, "moisture", 0.2, seed)), model);
            for (const auto& e : r.effects) {
                if (e.variable != "moisture_pct") continue;
                ++named;
                if (!e.regime.empty()) {
                    ++by_regime;
                    UNSCOPED_INFO(model << " seed " << seed << ": moisture_pct by " << e.regime);
                }
            }
        }
    CHECK(named >= 57);  // of 60
    CHECK(by_regime <= 2);
}

TEST_CASE("diagnose: regime options that do not suit the data are refused with the field and value named", "[diagnose]") {
    const auto data = make_synthetic_set(spec("oldal", "none", 0, 1));
    DiagnoseOptions unknown;
    unknown.regime_columns = {"flow_regime"};
    CHECK_THROWS_WITH(diagnose(data, "oldal", unknown),
                      Catch::Contains("regime column 'flow_regime'") && Catch::Contains("not in"));
    DiagnoseOptions identifier;
    identifier.regime_columns = {"run_order"};
    CHECK_THROWS_WITH(diagnose(data, "oldal", identifier), Catch::Contains("'run_order' has 36 values"));
    DiagnoseOptions one_angle;
    one_angle.wall_friction_deg = 20;
    CHECK_THROWS_WITH(diagnose(data, "oldal", one_angle), Catch::Contains("needs both friction angles"));
    DiagnoseOptions rough_wall;
    rough_wall.effective_friction_deg = 30;
    rough_wall.wall_friction_deg = 35;
    CHECK_THROWS_WITH(diagnose(data, "oldal", rough_wall), Catch::Contains("phi_w_deg=35"));
}

// On demand: how often the flow-mode effect is named and the CV RMSE halved, and how often clean sets get any effect.
//   build/tests/test_analytics "[rates-regime]"
TEST_CASE("diagnose: rates of the flow-mode effect and of false positives", "[.][rates-regime]") {
    const int seeds = 200;
    std::ostringstream table;
    table << "| set | seeds | effect added | vibration_Hz by flow_mode first | vibration_Hz x theta_deg first | "
             "CV RMSE at most half |\n|---|---|---|---|---|---|\n";
    auto study = [&](const std::string& model, const std::string& effect, double size, double noise) {
        int added = 0, by_mode = 0, by_angle = 0, halved = 0;
        for (int seed = 1; seed <= seeds; ++seed) {
            const auto r = diagnose(make_synthetic_set(spec(model, effect, size, 2000 + seed, noise)), model);
            if (r.effects.empty()) continue;
            ++added;
            const auto& e = r.effects[0];
            by_mode += e.variable == "vibration_Hz" && e.regime == "flow_mode";
            by_angle += e.variable == "vibration_Hz" && e.regime == "theta_deg";
            halved += r.after.cv_rmse <= 0.5 * r.before.cv_rmse;
        }
        table << "| " << model << " + " << effect << " " << size * 100 << " %, noise " << noise * 100 << " % | "
              << seeds << " | " << added << " | " << by_mode << " | " << by_angle << " | " << halved << " |\n";
    };
    for (const std::string model : {"oldal", "beverloo", "oldal-rect", "johanson", "failure-line"})
        study(model, "none", 0, 0.03);
    for (double noise : {0.02, 0.03})
        for (double size : {0.2, 0.25, 0.3}) {
            study("oldal", "vibration_by_mode", size, noise);
            study("beverloo", "vibration_by_mode", size, noise);
        }
    std::cout << table.str();

    std::ostringstream both;
    both << "\n| beverloo + hopper_angle+vibration_by_mode | seeds | both named | only the angle | phi_d within 2 se "
            "of the generating | CV RMSE at most half |\n|---|---|---|---|---|---|\n";
    for (double noise : {0.02, 0.03})
    for (double size : {0.2, 0.25, 0.3}) {
        int named = 0, angle_only = 0, phi_within = 0, halved = 0;
        for (int seed = 1; seed <= seeds; ++seed) {
            const auto r = diagnose(
                make_synthetic_set(spec("beverloo", "hopper_angle+vibration_by_mode", size, 4000 + seed, noise)),
                "beverloo");
            const auto* vibration = find_effect(r, "vibration_Hz", "regime");
            const auto* angle = find_effect(r, "theta_deg", "physical");
            named += vibration && vibration->regime == "flow_mode" && angle;
            angle_only += angle && r.effects.size() == 1;
            if (angle)
                phi_within += std::abs(angle->params[0].value - generating_phi_d(size)) < 2 * angle->params[0].std_error;
            halved += r.after.cv_rmse <= 0.5 * r.before.cv_rmse;
        }
        both << "| " << size * 100 << " % each, noise " << noise * 100 << " % | " << seeds << " | " << named << " | " << angle_only << " | "
             << phi_within << " | " << halved << " |\n";
    }
    std::cout << both.str();
}
