// diagnose: outliers named by their file line (externally studentized residuals, Bonferroni), never made an effect.
#include "analytics/diagnose.hpp"
#include "analytics/diagnose_synthetic.hpp"
#include "synthetic_spec.hpp"

#include <catch2/catch.hpp>
#include <gsl/gsl_fit.h>

#include <cmath>
#include <iostream>
#include <sstream>

using namespace demcal::analytics;
using demcal::analytics::test::spec;

namespace {

// Multiplies the response of the row at file line `line` by `factor`.
void spoil(MeasuredData& d, const std::string& response, int line, double factor) {
    for (auto& c : d.columns)
        if (c.name == response)
            for (std::size_t r = 0; r < d.rows(); ++r)
                if (d.lines[r] == line) c.values[r] *= factor;
}
}  // namespace

TEST_CASE("diagnose: a gross outlier is named by its line and adds no effect", "[diagnose]") {
    for (std::uint64_t seed : {61u, 62u, 63u, 64u}) {
        const auto set = make_synthetic(spec("oldal", "outlier", 0.3, seed));
        const auto r = diagnose(set.data, "oldal");
        INFO("seed " << seed << ", outlier at line " << set.outlier_line);
        REQUIRE(r.outliers.rows.size() == 1);
        CHECK(r.outliers.rows[0].line == set.outlier_line);
        CHECK(std::abs(r.outliers.rows[0].studentized) > r.outliers.threshold);
        CHECK(r.effects.empty());
        // Without it the mean error falls by about its 30 % over 36 rows (0.8 points).
        CHECK(r.outliers.without_outliers.rmse < r.outliers.with_outliers.rmse);
        CHECK(r.outliers.with_outliers.mape - r.outliers.without_outliers.mape > 0.5);
        CHECK(!r.outliers.dropped);
        CHECK(r.after.rmse == r.outliers.with_outliers.rmse);
    }
}

TEST_CASE("diagnose: an outlier in a set with a real effect: the effect is found and the row named", "[diagnose]") {
    auto data = make_synthetic_set(spec("oldal", "moisture", 0.3, 65));
    const int line = data.lines[7];
    spoil(data, "W_kg_s", line, 0.65);
    const auto r = diagnose(data, "oldal");
    REQUIRE(r.effects.size() == 1);
    CHECK(r.effects[0].variable == "moisture_pct");
    REQUIRE(r.outliers.rows.size() == 1);
    CHECK(r.outliers.rows[0].line == line);
}

TEST_CASE("diagnose: --drop-outliers reports the fits without the flagged rows", "[diagnose]") {
    const auto set = make_synthetic(spec("oldal", "outlier", 0.3, 66));
    DiagnoseOptions drop;
    drop.drop_outliers = true;
    const auto kept = diagnose(set.data, "oldal");
    const auto dropped = diagnose(set.data, "oldal", drop);
    REQUIRE(dropped.outliers.rows.size() == 1);
    CHECK(dropped.outliers.dropped);
    CHECK(dropped.after.rmse == Approx(dropped.outliers.without_outliers.rmse));
    CHECK(dropped.after.rmse < kept.after.rmse);
    // Oldal's delta moves towards the generating 0.6 without the spoilt row.
    CHECK(std::abs(dropped.params_after[0].value - 0.6) < std::abs(kept.params_after[0].value - 0.6));
    const auto j = dropped.to_json().at("outliers");
    CHECK(j.at("rows")[0].at("line") == set.outlier_line);
    CHECK(j.at("dropped") == true);
}

TEST_CASE("diagnose: the studentized residual of a straight line is the leave-one-out prediction error over its sd",
          "[diagnose]") {
    // The failure line is linear in its parameters, so the deletion formulas are exact: compare with a refit
    // without the row (gsl_fit_linear) and the standard error of its prediction there.
    auto data = make_synthetic_set(spec("failure-line", "none", 0, 67, 0.02, 3));
    const int line = data.lines[4];
    spoil(data, "tau_Pa", line, 1.25);
    const auto r = diagnose(data, "failure-line");
    REQUIRE(r.effects.empty());
    REQUIRE(r.outliers.rows.size() == 1);
    REQUIRE(r.outliers.rows[0].line == line);
    std::vector<double> x, y;
    const auto& sigma = data.at("sigma_Pa").values;
    const auto& tau = data.at("tau_Pa").values;
    for (std::size_t i = 0; i < data.rows(); ++i)
        if (i != 4) {
            x.push_back(sigma[i]);
            y.push_back(tau[i]);
        }
    double c0, c1, c00, c01, c11, sse, estimate, estimate_error;
    gsl_fit_linear(x.data(), 1, y.data(), 1, x.size(), &c0, &c1, &c00, &c01, &c11, &sse);
    gsl_fit_linear_est(sigma[4], c0, c1, c00, c01, c11, &estimate, &estimate_error);
    const double s2 = sse / (x.size() - 2.0);
    const double expected = (tau[4] - estimate) / std::sqrt(s2 + estimate_error * estimate_error);
    CHECK(r.outliers.rows[0].studentized == Approx(expected).epsilon(1e-3));
}

TEST_CASE("diagnose: the Bonferroni threshold rises as the outlier alpha falls", "[diagnose]") {
    auto data = make_synthetic_set(spec("oldal", "none", 0, 68));
    DiagnoseOptions loose;
    loose.outlier_alpha = 0.5;
    const auto r = diagnose(data, "oldal", loose);
    CHECK(r.outliers.threshold < diagnose(data, "oldal").outliers.threshold);  // a looser alpha, a lower bar
}

// On demand: how often a gross outlier is named and an effect added, and how often clean rows are flagged.
//   build/tests/test_analytics "[rates-outliers]"
TEST_CASE("diagnose: rates of outlier naming", "[.][rates-outliers]") {
    const int seeds = 200;
    std::ostringstream table;
    table << "| set | seeds | outlier row named | other rows flagged | effect added |\n|---|---|---|---|---|\n";
    auto study = [&](const std::string& model, const std::string& effect, double size) {
        int named = 0, others = 0, added = 0;
        for (int seed = 1; seed <= seeds; ++seed) {
            const auto set = make_synthetic(spec(model, effect, size, 3000 + seed));
            const auto r = diagnose(set.data, model);
            for (const auto& o : r.outliers.rows) (o.line == set.outlier_line ? named : others) += 1;
            added += !r.effects.empty();
        }
        table << "| " << model << " + " << effect << " " << size * 100 << " % | " << seeds << " | "
              << (effect == "outlier" ? std::to_string(named) : "-") << " | " << others << " | " << added << " |\n";
    };
    for (const std::string model : {"oldal", "beverloo", "oldal-rect", "johanson"}) {
        study(model, "none", 0);
        for (double size : {0.15, 0.2, 0.3}) study(model, "outlier", size);
    }
    std::cout << table.str();
}
