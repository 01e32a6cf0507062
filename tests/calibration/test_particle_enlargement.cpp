// The particle-enlargement study (calibration/particle_enlargement) on an analytic shear box whose restoring laws
// are known: E*(r) = A r + B and nu*(r) = C r^-D with the seed's constants (eqs. 3.1-3.2), mu_b moved by E and tau_c
// by nu away from them, a packing noise fixed by seed, and a CPU time per run of K r^-P. The study must find the
// laws, their intervals must cover the truth, and the laws' materials must restore the reference line.
#include "calibration/particle_enlargement.hpp"

#include <catch2/catch.hpp>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>

using namespace demcal;
using namespace demcal::calibration;

namespace {

// The seed's laws in SI units: E in Pa, r in m (A = 91.52 MPa/mm, B = 148.86 MPa; C = 0.2344 mm^D, D = 1.282).
constexpr double true_a = 91.52e9, true_b = 148.86e6, true_d = 1.282;
const double true_c = 0.2344 * std::pow(1e-3, 1.282);
constexpr double cost_k = 2e-11, cost_p = 4.0;  // CPU per run [s] = K r^-P: 200 s at 1 mm, 12.5 s at 2 mm
constexpr double r0 = 1e-3;

double restoring_e(double r) { return true_a * r + true_b; }
double restoring_nu(double r) { return true_c * std::pow(r, -true_d); }

nlohmann::json base_material() {
    return {{"density", 2650.0},          {"young_modulus", restoring_e(r0)}, {"poisson_ratio", restoring_nu(r0)},
            {"friction_coefficient", 0.5}, {"bond_normal_strength", 2000.0},   {"bond_shear_strength", 2000.0},
            {"particle_form", 1.0},       {"timestep_fraction", 0.5},         {"particle_radius", r0},
            {"radius_spread", 0.1},       {"box_length", 0.1},                {"box_width", 0.1},
            {"box_height", 0.05},         {"shear_velocity", 0.05},           {"shear_displacement", 0.004},
            {"damping", 0.2},             {"samples", 40}};
}

// mu_b rises and tau_c rises as the material leaves the restoring laws (the seed's enlarged particles with the base
// parameters show a higher mu_b); each run adds a packing noise fixed by its seed (common random numbers).
FailureLineEvaluation synthetic_line(const nlohmann::json& m) {
    const double r = m.at("particle_radius"), e = m.at("young_modulus"), nu = m.at("poisson_ratio");
    const double mu_b = 0.6 + 0.3 * (restoring_e(r) - e) / restoring_e(r0);
    const double tau_c = 1000 + 2000 * (nu - restoring_nu(r)) / restoring_nu(r0);
    std::unique_ptr<gsl_rng, decltype(&gsl_rng_free)> rng(gsl_rng_alloc(gsl_rng_mt19937), gsl_rng_free);
    FailureLineEvaluation ev;
    std::vector<double> sigma, tau;
    int seed = 1;
    for (double s : {2e3, 4e3, 6e3, 8e3})
        for (int rep = 0; rep < 2; ++rep, ++seed) {
            gsl_rng_set(rng.get(), seed);
            sigma.push_back(s);
            tau.push_back(mu_b * s + tau_c + gsl_ran_gaussian(rng.get(), 3.0));
            orchestrator::RunRecord run;
            run.state = orchestrator::RunState::done;
            gsl_rng_set(rng.get(), 1000 + seed + static_cast<int>(r * 1e6));  // timing noise: 5 % per run
            run.cpu_s = cost_k * std::pow(r, -cost_p) * (1 + gsl_ran_gaussian(rng.get(), 0.05));
            run.wall_s = 1.1 * run.cpu_s;
            run.result = {{"particle_count", std::round(0.6 * 5e-4 / (4.18879 * r * r * r))},
                          {"steps", std::round(0.01 / (0.05 * 1e-5 * r / r0))},
                          {"timestep", 1e-5 * r / r0}};
            ev.outcome.runs.push_back(run);
        }
    ev.simulations_run = static_cast<int>(sigma.size());
    ev.cpu_s = 0;
    for (const auto& run : ev.outcome.runs) ev.cpu_s += run.cpu_s;
    ev.peak = analytics::fit_failure_line(sigma, tau);
    ev.residual = ev.peak;
    return ev;
}

EnlargementOptions seed_radii_options() {
    EnlargementOptions o;
    o.radii = {1e-3, 1.5e-3, 2e-3, 3e-3};
    o.tolerance = 0.01;
    o.calibration.accept_simulated_interval = false;
    o.calibration.max_evaluations = 8;
    // the restoring E at 3 mm (423 MPa) lies beyond the default study range (base +/- 50 %)
    o.bounds = {{"young_modulus", {1e8, 1e9}}, {"poisson_ratio", {0.01, 0.45}}};
    return o;
}

bool covers(const analytics::LawParameter& p, double truth) { return p.low <= truth && truth <= p.high; }

}  // namespace

TEST_CASE("the enlargement study recovers known laws, and their materials restore the reference line",
          "[calibration][enlargement]") {
    const auto study = run_enlargement_study(base_material(), synthetic_line, seed_radii_options());
    INFO(study.markdown());
    CHECK(study.problems.empty());
    REQUIRE(study.calibrations.size() == 3);
    for (const auto& c : study.calibrations) CHECK(c.converged());

    // step 1: mu_b grows linearly with r at the base parameters (the seed's fig. 3.4), the cost falls as r^-4
    REQUIRE(study.mu_b_trend);
    CHECK(study.mu_b_trend->shape == analytics::ResponseShape::linear);
    CHECK(study.mu_b_trend->selected().coefficients[1].value > 0);
    REQUIRE(study.cpu_law);
    CHECK(study.cpu_law->determined());
    CHECK(covers(study.cpu_law->params[1], cost_p));
    CHECK(study.bases.front().cost.particles > study.bases.back().cost.particles);
    // the work (particles x steps, r^-3 r^-1 here) follows its own power law, free of timing noise
    REQUIRE(study.work_law);
    CHECK(study.work_law->params[1].value == Approx(4).margin(0.05));

    // step 3: A, B, C, D inside their intervals, and the intervals are informative (not +/- everything)
    REQUIRE(study.young_law);
    REQUIRE(study.poisson_law);
    CHECK(covers(study.young_law->params[0], true_a));
    CHECK(covers(study.young_law->params[1], true_b));
    CHECK(covers(study.poisson_law->params[0], true_c));
    CHECK(covers(study.poisson_law->params[1], true_d));
    CHECK(study.young_law->params[0].std_error < 0.2 * true_a);
    CHECK(study.poisson_law->params[1].std_error < 0.2 * true_d);

    // step 4: the laws' materials keep mu_b and tau_c within the tolerance at every radius, and save cost
    REQUIRE(study.verifications.size() == 4);
    for (const auto& v : study.verifications) {
        CHECK(v.not_run_because.empty());
        CHECK(v.within_tolerance);
    }
    CHECK(study.verifications[2].cost_saved > 0.9);  // doubling the radius: 1 - 2^-4 = 94 %

    const auto j = study.to_json();
    CHECK(j.at("per_radius").size() == 4);
    const double saved_by_doubling = j.at("cost").at("saved_by_doubling").at("value").get<double>();
    CHECK(saved_by_doubling == Approx(1 - std::pow(2.0, -cost_p)).margin(0.03));
    // the seed's units (eqs. 3.1-3.2: E in MPa, r in mm): C_mm was C_m 1e-3^+D before 2026-12-06, about 5e-9 here
    const auto& seed = j.at("laws_in_seed_units");
    CHECK(seed.at("A_MPa_per_mm").get<double>() == Approx(91.52).epsilon(0.15));
    CHECK(seed.at("B_MPa").get<double>() == Approx(148.86).epsilon(0.15));
    CHECK(seed.at("C_mm").get<double>() == Approx(0.2344).epsilon(0.15));
    CHECK(seed.at("D").get<double>() == Approx(1.282).epsilon(0.15));
    CHECK(j.at("poisson_ratio_meaning").get<std::string>().find("ks/kn") != std::string::npos);
}

TEST_CASE("a study whose calibrations cannot move the line reports the laws as undetermined",
          "[calibration][enlargement]") {
    // mu_b and tau_c move with r but neither E nor nu moves them back: no calibration converges, no law is fitted
    const FailureLineEvaluator inert = [](const nlohmann::json& m) {
        nlohmann::json frozen = m;
        frozen["young_modulus"] = restoring_e(r0);
        frozen["poisson_ratio"] = restoring_nu(r0);
        return synthetic_line(frozen);
    };
    auto options = seed_radii_options();
    options.calibration.max_evaluations = 3;
    const auto study = run_enlargement_study(base_material(), inert, options);
    CHECK_FALSE(study.problems.empty());
    CHECK_FALSE(study.young_law);
    CHECK(study.verifications.empty());
    bool names_calibration = false;
    for (const auto& p : study.problems) names_calibration |= p.find("calibration at r = ") != std::string::npos;
    CHECK(names_calibration);
}

TEST_CASE("a reference line whose interval on mu_b holds 0 stops the study before any calibration",
          "[calibration][enlargement]") {
    // probe 59: a 3-point reference of mu_b 0.79 +/- 1.66 accepted every radius's line at its start ("converged"),
    // and E(r) was fitted through calibrations that never moved
    int evaluations = 0;
    const FailureLineEvaluator noisy = [&](const nlohmann::json& m) {
        ++evaluations;
        FailureLineEvaluation ev = synthetic_line(m);
        std::vector<double> sigma, tau;
        const double scatter[] = {2000, -2000, -1000, 1500};  // Pa: a box far too small for its stresses
        int k = 0;
        for (double s : {2e3, 4e3, 6e3, 8e3}) {
            sigma.push_back(s);
            tau.push_back(0.6 * s + 1000 + scatter[k++]);
        }
        ev.peak = analytics::fit_failure_line(sigma, tau);
        ev.residual = ev.peak;
        return ev;
    };
    auto options = seed_radii_options();
    const auto study = run_enlargement_study(base_material(), noisy, options);
    INFO(study.markdown());
    const auto& ref = study.bases.front().line;
    REQUIRE(ref.mu_b > 0);  // the premise: a positive slope whose interval holds 0
    REQUIRE(ref.mu_b_low < 0);
    CHECK(evaluations == static_cast<int>(options.radii.size()));  // step 1 only
    CHECK(study.calibrations.empty());
    CHECK_FALSE(study.young_law);
    REQUIRE(study.problems.size() == 1);
    CHECK_THAT(study.problems.front(), Catch::Contains("an interval that holds 0 accepts every line") &&
                                           Catch::Contains("the study stops before the calibrations"));
}

TEST_CASE("a calibration accepted by an interval rather than the tolerance is warned with its distance",
          "[calibration][enlargement]") {
    // with a tolerance of 1e-6, below the lines' own intervals (noise 3 Pa), a calibration is accepted by an interval
    // (the reference's or its own), which the study then reports
    auto options = seed_radii_options();
    options.tolerance = 1e-6;
    options.calibration.accept_simulated_interval = true;
    const auto study = run_enlargement_study(base_material(), synthetic_line, options);
    INFO(study.markdown());
    int by_interval = 0, warned = 0;
    for (const auto& c : study.calibrations)
        by_interval += c.converged() && c.result.iterations.at(c.result.best).accepted_by != "tolerance";
    for (const auto& w : study.warnings) warned += w.find(", not the tolerance:") != std::string::npos;
    CHECK(by_interval > 0);
    CHECK(warned == by_interval);
}

TEST_CASE("bad radii are refused before any evaluation, naming the field and the value", "[calibration][enlargement]") {
    int evaluations = 0;
    const FailureLineEvaluator counting = [&](const nlohmann::json& m) {
        ++evaluations;
        return synthetic_line(m);
    };
    auto refused = [&](std::vector<double> radii, const std::string& expected) {
        auto o = seed_radii_options();
        o.radii = std::move(radii);
        try {
            run_enlargement_study(base_material(), counting, o);
            FAIL("accepted radii " << o.radii.size());
        } catch (const std::invalid_argument& e) {
            INFO(e.what());
            CHECK(std::string(e.what()).find(expected) != std::string::npos);
        }
    };
    refused({1e-3, 2e-3, 1.5e-3}, "radius 3 = 0.0015 m after 0.002 m");
    refused({1e-3, 1e-3, 2e-3}, "must increase");
    refused({-1e-3, 1e-3, 2e-3}, "radius 1 = -0.001 m must be a positive number");
    refused({1e-3, 2e-3}, "radii: 2 given, need at least 3");
    // 6 mm spheres (13.2 mm long with the spread): 4 of them are more than the 5 cm box height
    refused({1e-3, 2e-3, 6e-3}, "radii = 0.006 m: field 'box_height'");
    auto other_range = seed_radii_options();
    other_range.study.ranges = {{"friction_coefficient", {0.2, 0.8}}};
    CHECK_THROWS_WITH(run_enlargement_study(base_material(), counting, other_range),
                      Catch::Contains("range: 'friction_coefficient' is not a control"));
    CHECK(evaluations == 0);
}

TEST_CASE("the box ratio follows ASTM D3080 and separates the seed's 3 mm from its 5 and 7 mm spheres",
          "[calibration][enlargement]") {
    auto seed_box = base_material();  // 0.1 x 0.1 x 0.05 m, radius spread 0.1
    for (double r_mm : {1.0, 1.5, 2.0, 3.0}) {
        seed_box["particle_radius"] = r_mm * 1e-3;
        CHECK(box_ratio(seed_box).adequate());
    }
    for (double r_mm : {5.0, 7.0}) {
        seed_box["particle_radius"] = r_mm * 1e-3;
        CHECK_FALSE(box_ratio(seed_box).adequate());
        CHECK(box_ratio(seed_box).warning().find("ASTM D3080") != std::string::npos);
    }
}
