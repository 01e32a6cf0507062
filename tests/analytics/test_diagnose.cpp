// diagnose on seeded measured-like sets whose generating process holds an effect the model lacks, and on clean
// controls with decoy columns (replicate, run_order, moisture, temperature, operator, vibration).
#include "analytics/diagnose.hpp"
#include "analytics/diagnose_synthetic.hpp"
#include "synthetic_spec.hpp"

#include <catch2/catch.hpp>

#include <fstream>
#include <iostream>
#include <sstream>

using namespace demcal::analytics;
using demcal::analytics::test::spec;


TEST_CASE("diagnose names the column of an undeclared effect and halves the CV error", "[diagnose]") {
    struct Case {
        std::string model, effect, column;
        double size;
    };
    // Effects of 20-30 % between their extremes under 3 % noise, two replicates per condition, three seeds each.
    const std::vector<Case> cases{{"oldal", "moisture", "moisture_pct", 0.3},
                                  {"beverloo", "hopper_angle", "theta_deg", 0.3},
                                  {"oldal-rect", "drift", "run_order", 0.3},
                                  {"oldal", "operator", "operator", 0.25},
                                  {"oldal", "annulus", "d_p_m", 0.4},
                                  {"johanson", "moisture", "moisture_pct", 0.3}};
    for (const auto& c : cases)
        for (std::uint64_t seed : {11u, 12u, 13u}) {
            const auto r = diagnose(make_synthetic_set(spec(c.model, c.effect, c.size, seed)), c.model);
            INFO(c.model << " + " << c.effect << ", seed " << seed);
            REQUIRE(!r.effects.empty());
            CHECK(r.effects.front().variable == c.column);
            CHECK(r.effects.size() == 1);
            CHECK(r.after.cv_rmse <= 0.5 * r.before.cv_rmse);
            CHECK(r.effects.front().p_holm < 0.01);
        }
}

TEST_CASE("a curved yield locus is found in shear data", "[diagnose]") {
    for (std::uint64_t seed : {21u, 22u, 23u}) {
        const auto r = diagnose(make_synthetic_set(spec("failure-line", "curved_locus", 0.3, seed, 0.01, 3)),
                                "failure-line");
        INFO("seed " << seed);
        REQUIRE(r.effects.size() == 1);
        CHECK(r.effects[0].variable == "sigma_Pa");
        CHECK(r.effects[0].params[0].value == Approx(0.7).margin(0.1));  // the generating exponent n = 1 - 0.3
        CHECK(r.after.cv_rmse < r.before.cv_rmse);
    }
}

TEST_CASE("diagnose recovers the generating constants with honest uncertainties", "[diagnose]") {
    // Oldal with delta = 0.6 and a moisture effect of 20 % between 10 and 16 % moisture: beta = ln-slope ~ -0.2/6.
    const auto r = diagnose(make_synthetic_set(spec("oldal", "moisture", 0.2, 5, 0.02, 3)), "oldal");
    REQUIRE(r.effects.size() == 1);
    const auto& delta = r.params_after[0];
    CHECK(delta.name == "delta");
    CHECK(std::abs(delta.value - 0.6) < 4 * delta.std_error);
    CHECK(delta.std_error < 0.02);
    const auto& beta = r.effects[0].params[0];
    CHECK(beta.value == Approx(-0.2 / 6).margin(4 * beta.std_error));
    // Before the effect, the model lacks fit against the pure error of the replicates; after, it does not.
    REQUIRE(r.lack_of_fit_before.has_value());
    REQUIRE(r.lack_of_fit_after.has_value());
    CHECK(r.lack_of_fit_before->p_value < r.lack_of_fit_after->p_value);
}

TEST_CASE("clean controls with decoy columns get no effect", "[diagnose]") {
    // 10 seeds for each of the five models; the long study (200 seeds each) is the [.][rates] test below.
    int added = 0, runs = 0;
    for (const std::string model : {"oldal", "beverloo", "oldal-rect", "johanson", "failure-line"})
        for (std::uint64_t seed = 100; seed < 110; ++seed) {
            const auto r = diagnose(make_synthetic_set(spec(model, "none", 0, seed)), model);
            ++runs;
            if (!r.effects.empty()) ++added;
            else CHECK(r.after.rmse == r.before.rmse);
        }
    INFO(added << " of " << runs << " clean sets got an effect");
    CHECK(added <= runs / 20);  // at most 5 %
}

TEST_CASE("diagnose rejects data that do not suit the model", "[diagnose]") {
    const auto rect = make_synthetic_set(spec("oldal-rect", "none", 0, 1));
    CHECK_THROWS_WITH(diagnose(rect, "beverloo"), Catch::Contains("applies to conical silos only"));
    CHECK_THROWS_WITH(diagnose(rect, "oldal-rect-2"), Catch::Contains("unknown"));
    CHECK_THROWS_WITH(diagnose(rect, "failure-line"), Catch::Contains("missing column sigma_Pa"));
}

TEST_CASE("diagnose of degenerate data - identical rows get no effect and are not determined - one normal stress is refused",
          "[diagnose]") {
    // every row a copy of the first (a file pasted 36 times): nothing varies, nothing scatters
    auto same = make_synthetic_set(spec("oldal", "moisture", 0.2, 7));
    for (auto& c : same.columns) {
        if (c.numeric) std::fill(c.values.begin(), c.values.end(), c.values.front());
        std::fill(c.text.begin(), c.text.end(), c.text.front());
    }
    const auto r = diagnose(same, "oldal");
    CHECK(r.effects.empty());
    bool said = false;
    for (const auto& w : r.undetermined) said = said || w.find("no scatter to test an effect against") != std::string::npos;
    CHECK(said);
    CHECK(r.to_json().at("determined") == false);
    bool repeats = false;
    for (const auto& w : r.warnings) repeats = repeats || w.find("duplicate rows, equal to earlier rows in every cell") != std::string::npos;
    CHECK(repeats);
    // one row pasted twice into a clean set: fitted, and said (held-back suite: no word of it)
    auto pasted = make_synthetic_set(spec("oldal", "moisture", 0.2, 7));
    for (auto& c : pasted.columns) {
        if (c.numeric) c.values.push_back(c.values.front());
        c.text.push_back(c.text.front());
    }
    pasted.lines.push_back(pasted.lines.back() + 1);
    const auto twice = diagnose(pasted, "oldal");
    bool said_twice = false;
    for (const auto& w : twice.warnings)
        said_twice = said_twice || w.find("1 duplicate row, equal to an earlier row in every cell (lines " +
                                          std::to_string(pasted.lines.front()) + " and ") != std::string::npos;
    CHECK(said_twice);
    // a failure line with every stress equal has no slope to fit
    auto shear = make_synthetic_set(spec("failure-line", "none", 0, 3));
    auto& sigma = const_cast<demcal::analytics::DataColumn&>(shear.at("sigma_Pa"));
    std::fill(sigma.values.begin(), sigma.values.end(), 15000.0);
    std::fill(sigma.text.begin(), sigma.text.end(), std::string("15000"));
    CHECK_THROWS_WITH(diagnose(shear, "failure-line"), Catch::Contains("sigma_Pa: every row has the normal stress 15000"));
    // a shear strength that falls as the normal stress rises (the columns swapped) is no failure line of a bulk solid
    auto falling = make_synthetic_set(spec("failure-line", "none", 0, 3));
    auto& tau = const_cast<demcal::analytics::DataColumn&>(falling.at("tau_Pa"));
    const auto& s = falling.at("sigma_Pa").values;
    for (std::size_t r = 0; r < tau.values.size(); ++r) tau.values[r] = 2e5 - 0.9 * s[r] + 50.0 * (r % 3);
    CHECK_THROWS_WITH(diagnose(falling, "failure-line"), Catch::Contains("the failure line's slope mu_b = -0.9") &&
                                                           Catch::Contains("is negative"));
}

TEST_CASE("the JSON result has the documented shape", "[diagnose]") {
    const auto r = diagnose(make_synthetic_set(spec("oldal", "moisture", 0.2, 7)), "oldal");
    const auto j = r.to_json();
    CHECK(j.at("model") == "oldal");
    CHECK(j.at("n") == 36);
    for (const char* part : {"before", "after"})
        for (const char* key : {"rmse", "cv_rmse", "mape"}) CHECK(j.at(part).at(key).is_number());
    REQUIRE(j.at("effects").size() == 1);
    const auto& e = j.at("effects")[0];
    CHECK(e.at("variable") == "moisture_pct");
    CHECK(e.at("form").is_string());
    CHECK(e.at("params").at("beta").is_number());
    CHECK(e.at("p_value").is_number());
    // The search's CV runs without the flagged rows (none, or a clean row by chance: outlier_alpha).
    CHECK(e.at("cv_rmse_after") ==
          Approx(j.at("outliers").at("without_outliers").at("cv_rmse").get<double>()).epsilon(1e-6));
    CHECK(j.at("outliers").at("rows").is_array());
}

// On demand: the false-positive rate on clean controls and the recovery rate of effects, over many seeds.
//   build/tests/test_analytics "[rates]"
TEST_CASE("rates of false positives and of effect recovery", "[.][rates]") {
    const int seeds = 200;
    std::ostringstream table;
    table << "| set | seeds | effect added | right column first | CV RMSE at most half |\n|---|---|---|---|---|\n";
    auto study = [&](const std::string& model, const std::string& effect, const std::string& column, double size,
                     double noise, int replicates) {
        int added = 0, right = 0, halved = 0;
        for (int seed = 1; seed <= seeds; ++seed) {
            const auto r = diagnose(make_synthetic_set(spec(model, effect, size, 1000 + seed, noise, replicates)), model);
            if (!r.effects.empty()) ++added;
            if (!r.effects.empty() && r.effects[0].variable == column) ++right;
            if (r.after.cv_rmse <= 0.5 * r.before.cv_rmse) ++halved;
        }
        table << "| " << model << " + " << effect << " " << size * 100 << " %, noise " << noise * 100 << " %, "
              << replicates << " reps | " << seeds << " | " << added << " | " << right << " | " << halved << " |\n";
    };
    for (const std::string model : {"oldal", "beverloo", "oldal-rect", "johanson", "failure-line"})
        study(model, "none", "", 0, 0.03, 2);
    for (double size : {0.05, 0.1, 0.2, 0.3}) {
        study("oldal", "moisture", "moisture_pct", size, 0.03, 2);
        study("beverloo", "hopper_angle", "theta_deg", size, 0.03, 2);
        study("oldal-rect", "drift", "run_order", size, 0.03, 2);
        study("oldal", "operator", "operator", size, 0.03, 2);
        study("oldal", "annulus", "d_p_m", size, 0.03, 2);
    }
    study("failure-line", "curved_locus", "sigma_Pa", 0.3, 0.01, 3);
    study("failure-line", "moisture", "moisture_pct", 0.2, 0.03, 2);
    std::cout << table.str();
}

// On demand: writes the example data sets of examples/diagnose/.
//   build/tests/test_analytics "[write-examples]"
TEST_CASE("write the example data sets", "[.][write-examples]") {
    auto write = [](const SyntheticSpec& s, const std::string& name) {
        std::ofstream out(std::string(DEMCAL_SOURCE_DIR) + "/examples/diagnose/" + name);
        out << "# generated by test_analytics \"[write-examples]\": " << s.model << " + " << s.effect << " "
            << s.effect_size << ", noise " << s.noise << ", seed " << s.seed << "\n"
            << to_csv(make_synthetic_set(s));
    };
    write(spec("oldal", "moisture", 0.2, 42), "oldal_moisture.csv");
    write(spec("oldal", "none", 0, 42), "oldal_clean.csv");
    write(spec("beverloo", "hopper_angle", 0.3, 42), "beverloo_hopper_angle.csv");
    write(spec("oldal-rect", "drift", 0.2, 42), "oldal_rect_drift.csv");
    write(spec("failure-line", "curved_locus", 0.3, 42, 0.01, 3), "shear_curved.csv");
    write(spec("oldal", "vibration_by_mode", 0.25, 42), "oldal_vibration_by_mode.csv");
    write(spec("oldal", "outlier", 0.3, 42), "oldal_outlier.csv");
    write(spec("beverloo", "hopper_angle+vibration_by_mode", 0.25, 42), "beverloo_angle_vibration.csv");
}

TEST_CASE("parameters the data cannot pin down are reported not determined, not as a fit", "[diagnose]") {
    auto load = [](const std::string& csv) {
        std::istringstream in(csv);
        auto data = parse_csv(in, "set.csv");
        validate_measured(data, MeasuredKind::discharge);
        return data;
    };
    const std::string header = "geometry,D_m,outlet_m,theta_deg,d_p_m,rho_b_kg_m3,W_kg_s\n";
    // one condition repeated: Beverloo's C and k trade against each other (k = 1.27 +/- 0 was "determined")
    std::string one = header;
    for (int i = 0; i < 5; ++i) one += "conical,0.105,0.05,60,0.005,780,0.60" + std::to_string(i + 1) + "\n";
    // only the bulk density varies: W is proportional to it for any k (C = 0.62 +/- 1.1e5 was "determined")
    std::string density = header;
    for (int i = 0; i < 6; ++i)
        density += "conical,0.105,0.05,60,0.005," + std::to_string(700 + 50 * i) + "," +
                   std::to_string(0.000777 * (700 + 50 * i) * (1 + 0.002 * (i % 2))) + "\n";
    for (const std::string& csv : {one, density}) {
        INFO(csv);
        const auto r = diagnose(load(csv), "beverloo");
        CHECK(r.to_json().at("determined") == false);
        bool said = false;
        for (const auto& w : r.undetermined) said = said || w.find("are not identifiable from these data") != std::string::npos;
        CHECK(said);
    }
    // the committed example with its conditions varied stays determined
    std::ifstream file(std::string(DEMCAL_SOURCE_DIR) + "/examples/diagnose/beverloo_hopper_angle.csv");
    std::stringstream text;
    text << file.rdbuf();
    CHECK(diagnose(load(text.str()), "beverloo").to_json().at("determined") == true);
    // the same rates in g/s under W_kg_s (probe 59b: C = 589 fitted, exit 0): C outside its physical range
    std::string grams;
    std::istringstream rows(text.str());
    for (std::string line; std::getline(rows, line);) {
        if (!line.empty() && line[0] != '#' && line.rfind("geometry", 0) != 0) {
            std::vector<std::string> cells;
            std::istringstream split(line);
            for (std::string c; std::getline(split, c, ',');) cells.push_back(c);
            cells[6] = std::to_string(1000 * std::stod(cells[6]));  // W_kg_s, the 7th column
            line.clear();
            for (const auto& c : cells) line += (line.empty() ? "" : ",") + c;
        }
        grams += line + "\n";
    }
    const auto r = diagnose(load(grams), "beverloo");
    CHECK(r.to_json().at("determined") == false);
    bool said = false;
    for (const auto& w : r.undetermined) said = said || w.find("beverloo's C = ") != std::string::npos;
    CHECK(said);
}
