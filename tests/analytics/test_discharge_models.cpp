#include "analytics/discharge_models.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

using namespace demcal::analytics;

// The seed's model silo: D = 105 mm, d = 35 mm, d/d_p = 6.36 (d_p = 5.5 mm); rho_b = 800 kg/m^3 (wheat, EN 1991-4).
// Hand computations (calculator), g = 9.81, sqrt(g) = 3.132092:
//   Beverloo C = 0.58, k = 1.5: d - k d_p = 0.02675, 0.02675^2.5 = 1.170333e-4 -> W = 0.58*800*3.132092*1.170333e-4
//   = 0.170083 kg/s.
//   Oldal delta = 0.5: (d - d_p)^2.5 = 0.0295^2.5 = 1.494703e-4, pi sqrt(2g)/6 = 2.319137 -> W = 2.319137 * 0.707107
//   * 800 * 1.494703e-4 = 0.196100 kg/s.
//   Johanson conical, theta = 30: A = pi 0.035^2/4 = 9.621128e-4 m^2, v = sqrt(0.035*9.81/(4 tan 30)) = 0.385596 m/s
//   -> W = 800 * 9.621128e-4 * 0.385596 = 0.296780 kg/s.
TEST_CASE("circular discharge models reproduce hand-computed rates", "[discharge]") {
    CHECK(beverloo_rate(0.035, 0.0055, 800, 0.58, 1.5) == Approx(0.170083).epsilon(1e-5));
    CHECK(oldal_rate(0.035, 0.0055, 800, 0.5) == Approx(0.196100).epsilon(1e-5));
    CHECK(johanson_conical_rate(0.035, 30, 800) == Approx(0.296780).epsilon(1e-5));
    // An outlet blocked by the empty annulus passes nothing.
    CHECK(beverloo_rate(0.01, 0.0075, 800, 0.58, 1.5) == 0.0);
}

// Rectangular: b = 50 mm deep, c = 100 mm wide, slot a = 30 mm, d_p = 5.5 mm, rho_b = 800.
//   Oldal-rect delta = 0.5: pi sqrt(2g)/4 = 3.478705, (a - d_p)^1.5 = 0.0245^1.5 = 3.834840e-3
//   -> W = 3.478705 * 0.707107 * 800 * 0.05 * 3.834840e-3 = 0.377341 kg/s.
//   Johanson wedge, theta = 30: A = 0.05*0.03 = 1.5e-3 m^2, v = sqrt(0.2943/(2 tan 30)) = sqrt(0.254870) = 0.504847
//   -> W = 800 * 1.5e-3 * 0.504847 = 0.605817 kg/s.
//   Myers-Sellers slot C' = 1.03, k = 1.5: (0.05 - 0.00825)(0.03 - 0.00825)^1.5 = 0.04175 * 3.207574e-3
//   -> W = 1.03 * 800 * 3.132092 * 1.339162e-4 = 0.345627 kg/s.
TEST_CASE("rectangular discharge models reproduce hand-computed rates", "[discharge]") {
    CHECK(oldal_rectangular_rate(0.05, 0.03, 0.0055, 800, 0.5) == Approx(0.377341).epsilon(1e-5));
    CHECK(johanson_wedge_rate(0.05, 0.03, 30, 800) == Approx(0.605817).epsilon(1e-5));
    CHECK(beverloo_slot_rate(0.05, 0.03, 0.0055, 800, 1.03, 1.5) == Approx(0.345627).epsilon(1e-5));
}

TEST_CASE("Oldal's circular form equals the integral of free fall below a paraboloid arch", "[discharge]") {
    // Midpoint rule over the outlet disc, independent of the closed form derived in discharge_models.cpp.
    const double d = 0.04, dp = 0.004, delta = 0.7, rho = 750, g = standard_gravity;
    const double de = d - dp;
    const int steps = 200000;
    double q = 0;
    for (int i = 0; i < steps; ++i) {
        const double r = (i + 0.5) * (de / 2) / steps;
        const double height = delta * de * (1 - std::pow(2 * r / de, 2));
        q += std::sqrt(2 * g * height) * 2 * std::numbers::pi * r * (de / 2) / steps;
    }
    CHECK(oldal_rate(d, dp, rho, delta) == Approx(rho * q).epsilon(1e-6));
    // ... and is Beverloo with k = 1, C = (pi sqrt 2 / 6) sqrt(delta) = 0.74048 sqrt(delta).
    CHECK(oldal_rate(d, dp, rho, delta) == Approx(beverloo_rate(d, dp, rho, 0.740480 * std::sqrt(delta), 1.0)).epsilon(1e-6));
}

TEST_CASE("Rose-Tanaka factor and Jenike's mass-flow limit", "[discharge]") {
    // theta = 20, phi_d = 45: (tan 20 * 1)^-0.35 = 0.363970^-0.35 = 1.424384
    CHECK(rose_tanaka_factor(20, 45) == Approx(1.424384).epsilon(1e-6));
    CHECK(rose_tanaka_factor(50, 45) == 1.0);                                  // shallower than the stagnant zone
    CHECK(rose_tanaka_factor(44.999, 45) == Approx(1.0).epsilon(1e-4));        // continuous at theta = 90 - phi_d
    // delta_e = 50, phi_w = 20: sin 50 = 0.766044, acos(0.152704) = 81.2160 -> 40.6080; asin(0.342020/0.766044)
    // = 26.5184 -> beta = 23.2592; theta_c = 90 - 40.6080 - 23.2592 = 26.1328 (Jenike's chart reads about 26).
    CHECK(jenike_mass_flow_limit_deg(50, 20) == Approx(26.1328).epsilon(1e-4));
    // Smoother walls keep wider hoppers in mass flow.
    CHECK(jenike_mass_flow_limit_deg(50, 10) > jenike_mass_flow_limit_deg(50, 20));
    CHECK_THROWS_WITH(jenike_mass_flow_limit_deg(30, 35), Catch::Contains("phi_w_deg=35"));
    // below 19.47 deg the approximation's arccos has no value: refused rather than NaN
    CHECK_THROWS_WITH(jenike_mass_flow_limit_deg(15, 5), Catch::Contains("delta_e_deg=15"));
    CHECK(std::isfinite(jenike_mass_flow_limit_deg(19.5, 5)));
}

TEST_CASE("the rectangular Oldal model says when it is used outside its limits", "[discharge]") {
    CHECK(oldal_rectangular_limit_violations(0.05, 0.1, 0.03).empty());
    const auto wide = oldal_rectangular_limit_violations(0.02, 0.1, 0.03);  // c/b = 5
    REQUIRE(wide.size() == 1);
    CHECK_THAT(wide[0], Catch::Contains("c/b = 5"));
    CHECK(oldal_rectangular_limit_violations(0.05, 0.1, 0.08).size() == 1);  // a/c = 0.8

    nlohmann::json j{{"geometry", "rectangular"}, {"b_m", 0.02}, {"c_m", 0.1},         {"outlet_m", 0.03},
                     {"theta_deg", 60},          {"d_p_m", 0.004}, {"rho_b_kg_m3", 780}};
    const auto preds = predict_discharge(geometry_from_json(j));
    bool seen = false;
    for (const auto& p : preds)
        if (p.model == "oldal-rect") {
            seen = true;
            CHECK_FALSE(p.valid);
            CHECK(p.rate.has_value());
        }
    CHECK(seen);
}

namespace {
// Checks that every model predict gives a rate for `geometry` is invalid (with a warning holding `warning`, when
// given); returns how many were checked.
int every_rated_model_invalid(const nlohmann::json& geometry, const std::string& warning = "") {
    int evaluated = 0;
    for (const auto& p : predict_discharge(geometry_from_json(geometry))) {
        if (!p.rate) continue;
        ++evaluated;
        INFO(p.model);
        CHECK_FALSE(p.valid);
        if (!warning.empty())
            CHECK(std::any_of(p.warnings.begin(), p.warnings.end(),
                              [&](const std::string& w) { return w.find(warning) != std::string::npos; }));
    }
    return evaluated;
}
}  // namespace

TEST_CASE("a ratio typed on a validity limit is within it (the limits are inclusive)", "[discharge]") {
    // the seed's 100 mm wide silo with a 70 mm outlet: 0.07 / 0.1 rounds to 0.7000000000000001 in doubles
    CHECK(oldal_rectangular_limit_violations(0.025, 0.1, 0.07).empty());  // a/c = 0.7, c/b = 4
    CHECK(oldal_rectangular_limit_violations(0.1, 0.1, 0.015).empty());   // a/c = 0.15, c/b = 1
    CHECK(oldal_rectangular_limit_violations(0.025, 0.1, 0.0701).size() == 1);
    // d = 24.6 mm, d_p = 4.1 mm: outlet/d_p = 6 exactly as typed (6 * 0.0041 rounds above 0.0246)
    nlohmann::json j{{"geometry", "conical"}, {"D_m", 0.105},     {"outlet_m", 0.0246}, {"theta_deg", 60},
                     {"d_p_m", 0.0041},      {"rho_b_kg_m3", 800}};
    for (const auto& p : predict_discharge(geometry_from_json(j))) {
        INFO(p.model);
        if (p.model == "beverloo" || p.model == "beverloo+rose-tanaka") CHECK(p.valid);
    }
}

TEST_CASE("an outlet of fewer than 4 grains arches: no model predicts a steady flow", "[discharge]") {
    // 9 mm outlet, 5.5 mm grains (1.6 grains across), funnel flow: Oldal was reported valid
    nlohmann::json j{{"geometry", "conical"}, {"D_m", 0.105},      {"outlet_m", 0.009}, {"theta_deg", 60},
                     {"d_p_m", 0.0055},      {"rho_b_kg_m3", 712}, {"delta_e_deg", 40}, {"phi_w_deg", 20}};
    CHECK(every_rated_model_invalid(j) >= 4);
    auto mass_flow = j;  // 20 deg, below Jenike's 27: Johanson's mass-flow model was reported valid
    mass_flow["theta_deg"] = 20;
    CHECK(every_rated_model_invalid(mass_flow, "outlet/d_p = 1.6") >= 3);
    // a slot of 3 grains (a 15 mm slot, 5 mm grains) in a wedge inside Oldal's limits: oldal-rect was reported valid
    const nlohmann::json slot{{"geometry", "rectangular"}, {"b_m", 0.05},      {"c_m", 0.1},     {"outlet_m", 0.015},
                              {"theta_deg", 60},           {"d_p_m", 0.005}, {"rho_b_kg_m3", 712}};
    CHECK(every_rated_model_invalid(slot) >= 3);
    // the slot's length counts too: a 70 mm slot across a silo 25 mm deep, 7.5 mm grains (3.3 along its length)
    const nlohmann::json short_slot{{"geometry", "rectangular"}, {"b_m", 0.025},      {"c_m", 0.1},
                                    {"outlet_m", 0.07},          {"theta_deg", 60},   {"d_p_m", 0.0075},
                                    {"rho_b_kg_m3", 712}};
    CHECK(every_rated_model_invalid(short_slot, "outlet/d_p = 3.33") >= 3);
    j["outlet_m"] = 0.023;  // 4.2 grains: free flow, Oldal's model (funnel flow here) holds; Beverloo needs 6
    for (const auto& p : predict_discharge(geometry_from_json(j))) {
        INFO(p.model);
        if (p.model == "oldal") CHECK(p.valid);
        if (p.model == "beverloo") CHECK_FALSE(p.valid);
    }
}

TEST_CASE("a flat-bottomed silo is in funnel flow without the friction angles", "[discharge]") {
    const nlohmann::json j{{"geometry", "conical"}, {"D_m", 0.105},     {"outlet_m", 0.035}, {"theta_deg", 90},
                           {"d_p_m", 0.0055},      {"rho_b_kg_m3", 800}};
    for (const auto& p : predict_discharge(geometry_from_json(j))) {
        INFO(p.model);
        if (p.model == "beverloo" || p.model == "oldal") {
            CHECK(p.valid);
            CHECK(std::none_of(p.warnings.begin(), p.warnings.end(),
                               [](const std::string& w) { return w.find("unknown") != std::string::npos; }));
        }
    }
}

TEST_CASE("predict marks flow-pattern and shape mismatches", "[discharge]") {
    nlohmann::json j{{"geometry", "conical"},   {"D_m", 0.105},     {"outlet_m", 0.035}, {"theta_deg", 20},
                     {"d_p_m", 0.0055},        {"rho_b_kg_m3", 800}, {"delta_e_deg", 50}, {"phi_w_deg", 20}};
    for (const auto& p : predict_discharge(geometry_from_json(j))) {
        if (p.model == "johanson-conical") CHECK(p.valid);       // 20 < 26.1: mass flow
        if (p.model == "oldal") CHECK_FALSE(p.valid);            // a funnel-flow model in mass flow
        if (p.model == "beverloo") CHECK_FALSE(p.valid);         // so is Beverloo's (the seed, 2.3)
        if (p.model == "beverloo+rose-tanaka") CHECK(p.valid);   // the hopper's correction
        if (p.model == "oldal-rect") CHECK_FALSE(p.rate.has_value());
    }
    j["theta_deg"] = 60;
    for (const auto& p : predict_discharge(geometry_from_json(j))) {
        if (p.model == "johanson-conical") CHECK_FALSE(p.valid);
        if (p.model == "oldal") CHECK(p.valid);
        if (p.model == "beverloo") CHECK(p.valid);
    }
}

TEST_CASE("geometry JSON errors name the key and the value", "[discharge]") {
    nlohmann::json j{{"geometry", "conical"}, {"D_m", 0.105}, {"outlet_m", 0.035}, {"theta_deg", 30},
                     {"d_p_m", 0.0055},      {"rho_b_kg_m3", 800}};
    CHECK_NOTHROW(geometry_from_json(j));
    auto with = [&](const char* key, nlohmann::json v) {
        auto k = j;
        k[key] = v;
        return k;
    };
    CHECK_THROWS_WITH(geometry_from_json(with("outlet_mm", 35)), Catch::Contains("unknown key outlet_mm"));
    CHECK_NOTHROW(geometry_from_json(with("_comment", "measured 2026-11-30")));  // a comment, as in the silo's files
    // the narrowest side of a rectangular outlet is named by its field: b_m, which was called "the outlet"
    const nlohmann::json slot{{"geometry", "rectangular"}, {"b_m", 0.005}, {"c_m", 0.1},  {"outlet_m", 0.03},
                              {"theta_deg", 60},           {"d_p_m", 0.004}, {"rho_b_kg_m3", 800}};
    CHECK_THROWS_WITH(geometry_from_json(slot), Catch::Contains("the outlet's narrower side, the silo depth b_m=0.005"));
    // Myers and Sellers' slot constant on a conical outlet was ignored (probe 59b)
    CHECK_THROWS_WITH(geometry_from_json(with("slot_C", 2)), Catch::Contains("slot_C is for rectangular silos"));
    CHECK_THROWS_WITH(geometry_from_json(with("d_p_m", -0.001)), Catch::Contains("d_p_m=-0.001"));
    CHECK_THROWS_WITH(geometry_from_json(with("d_p_m", 0.04)), Catch::Contains("not larger than the particles"));
    CHECK_THROWS_WITH(geometry_from_json(with("outlet_m", 0.2)), Catch::Contains("D_m=0.105"));
    CHECK_THROWS_WITH(geometry_from_json(with("theta_deg", 95)), Catch::Contains("theta_deg=95"));
    CHECK_THROWS_WITH(geometry_from_json(with("rho_b_kg_m3", "heavy")), Catch::Contains("rho_b_kg_m3=\"heavy\""));
    CHECK_THROWS_WITH(geometry_from_json(with("geometry", "hexagonal")), Catch::Contains("hexagonal"));
    auto missing = j;
    missing.erase("D_m");
    CHECK_THROWS_WITH(geometry_from_json(missing), Catch::Contains("missing key D_m"));
}

TEST_CASE("absurd but finite geometries are refused with the field and its plausible range", "[discharge]") {
    // a bulk density of 0.001 kg/m^3 or a silo 1e99 m across gave rates reported as valid
    const nlohmann::json conical{{"geometry", "conical"}, {"D_m", 0.105},     {"outlet_m", 0.035}, {"theta_deg", 30},
                                 {"d_p_m", 0.0055},      {"rho_b_kg_m3", 800}};
    const nlohmann::json rectangular{{"geometry", "rectangular"}, {"b_m", 0.2},     {"c_m", 0.4}, {"outlet_m", 0.1},
                                     {"theta_deg", 30},           {"d_p_m", 0.004}, {"rho_b_kg_m3", 800}};
    CHECK_NOTHROW(geometry_from_json(conical));
    CHECK_NOTHROW(geometry_from_json(rectangular));
    struct Case {
        const nlohmann::json& base;
        const char* key;
        double value;
    };
    for (const Case& c : {Case{conical, "rho_b_kg_m3", 0.001}, Case{conical, "rho_b_kg_m3", 1e308},
                          Case{conical, "D_m", 1e99}, Case{conical, "D_m", 250}, Case{conical, "d_p_m", 1e-9},
                          Case{conical, "beverloo_C", 1e6}, Case{conical, "beverloo_k", 11},
                          Case{conical, "delta", 1e8}, Case{rectangular, "slot_C", 7}, Case{rectangular, "b_m", 1e5},
                          Case{rectangular, "c_m", 101}}) {
        auto j = c.base;
        j[c.key] = c.value;
        INFO(c.key << " = " << c.value);
        CHECK_THROWS_WITH(geometry_from_json(j), Catch::Contains(std::string(c.key) + "=") && Catch::Contains("outside ["));
    }
    auto just_over = conical;  // the value shown as given: "D_m=100 outside [0, 100]" contradicted itself
    just_over["D_m"] = 100.0001;
    CHECK_THROWS_WITH(geometry_from_json(just_over), Catch::Contains("D_m=100.0001 outside [0, 100]"));
    auto huge = conical;  // a large silo inside the bounds is fine
    huge["D_m"] = 40.0;
    huge["outlet_m"] = 0.5;
    CHECK_NOTHROW(geometry_from_json(huge));
}

TEST_CASE("predict marks every model invalid for a fine powder", "[discharge]") {
    nlohmann::json j{{"geometry", "conical"}, {"D_m", 0.105},    {"outlet_m", 0.035}, {"theta_deg", 30},
                     {"d_p_m", 0.0055},      {"rho_b_kg_m3", 800}};
    for (const auto& p : predict_discharge(geometry_from_json(j)))
        if (p.rate) CHECK(std::none_of(p.warnings.begin(), p.warnings.end(),
                                       [](const std::string& w) { return w.find("fine powder") != std::string::npos; }));
    j["d_p_m"] = 1e-4;  // 100 um: air-retarded flow
    CHECK(every_rated_model_invalid(j, "fine powder") >= 3);
}
