// Benchmark on the analytic shear box: the surrogate loop against the grid and coordinate baselines over the same
// bounds, for several hidden materials. Prints the table written into calibration/README.md.
#include "calibration/calibration_loop.hpp"
#include "synthetic_material.hpp"

#include <catch2/catch.hpp>

#include <cstdio>

using namespace demcal;
using namespace demcal::calibration;

TEST_CASE("benchmark: surrogate loop against grid and coordinate search", "[calibration][bench]") {
    test::SyntheticShearBox box;
    const auto base = test::synthetic_base_material();
    SensitivityOptions so;
    so.params = {"friction_coefficient", "young_modulus", "bond_normal_strength", "bond_shear_strength",
                 "particle_form"};
    const auto study = run_sensitivity_study(base, box.evaluator(), so);
    const std::vector<std::pair<double, double>> hidden{{0.66, 2700}, {0.3, 1200}, {0.72, 1100}, {0.35, 2900}, {0.55, 2200}};
    std::printf("\nhidden (friction, bond shear) | surrogate | coordinate | grid 9x9 (failure lines; study: %d)\n",
                study.evaluations);
    int surrogate_total = 0, coordinate_total = 0, grid_total = 0;
    for (const auto& [f, b] : hidden) {
        nlohmann::json m = base;
        m["friction_coefficient"] = f;
        m["bond_shear_strength"] = b;
        const auto line = *box(m).peak;
        const std::vector<MacroTarget> targets{{"mu_b", line.mu_b, std::nullopt}, {"tau_c", line.tau_c, std::nullopt}};
        const auto controls = choose_controls(study, targets, 0.02);
        CalibrationOptions o;
        o.accept_simulated_interval = false;
        const auto s = calibrate(base, targets, controls, &study, box.evaluator(), o);
        o.method = SearchMethod::coordinate;
        o.max_evaluations = 300;
        const auto c = calibrate(base, targets, controls, nullptr, box.evaluator(), o);
        o.method = SearchMethod::grid;
        const auto g = calibrate(base, targets, controls, nullptr, box.evaluator(), o);
        std::printf("(%.2f, %4.0f Pa) | %d %s | %d %s | %d %s\n", f, b, s.evaluations, to_string(s.status).c_str(),
                    c.evaluations, to_string(c.status).c_str(), g.evaluations, to_string(g.status).c_str());
        CHECK(s.status == CalibrationStatus::converged);
        CHECK(s.evaluations <= 6);
        surrogate_total += s.evaluations;
        coordinate_total += c.evaluations;
        grid_total += g.evaluations;
    }
    std::printf("total | %d | %d | %d\n", surrogate_total, coordinate_total, grid_total);
    CHECK(grid_total >= 5 * surrogate_total);
}
