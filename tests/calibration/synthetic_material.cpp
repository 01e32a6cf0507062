#include "synthetic_material.hpp"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include <functional>
#include <memory>

namespace demcal::test {

nlohmann::json synthetic_base_material() {
    return {{"density", 2650.0},          {"young_modulus", 5e7},        {"poisson_ratio", 0.3},
            {"friction_coefficient", 0.5}, {"bond_normal_strength", 2000.0}, {"bond_shear_strength", 2000.0},
            {"particle_form", 1.0},       {"timestep_fraction", 0.5},    {"particle_radius", 0.002},
            {"radius_spread", 0.1},       {"box_length", 0.08},          {"box_width", 0.08},
            {"box_height", 0.04},         {"shear_velocity", 0.05},      {"shear_displacement", 0.004},
            {"damping", 0.2},             {"samples", 40}};
}

// Shapes chosen after Table 3.1: friction linear in both, Young modulus parabolic in both, bond normal strength
// constant, bond shear strength linear in both, particle form parabolic in cohesion and constant in friction.
double SyntheticShearBox::true_mu_b(const nlohmann::json& m) {
    const double f = m.at("friction_coefficient").get<double>();
    const double e = m.at("young_modulus").get<double>() / 5e7;
    const double bs = m.at("bond_shear_strength").get<double>() / 1e3;
    return 0.25 + 0.5 * f - 0.08 * (e - 1) * (e - 1) + 0.01 * bs + 0.02 * (f - 0.5) * (bs - 2);
}

double SyntheticShearBox::true_tau_c(const nlohmann::json& m) {
    const double f = m.at("friction_coefficient").get<double>();
    const double e = m.at("young_modulus").get<double>() / 5e7;
    const double bs = m.at("bond_shear_strength").get<double>();
    const double form = m.at("particle_form").get<double>();
    return 100 + 0.4 * bs + 300 * (f - 0.5) - 150 * (e - 1) * (e - 1) + 400 * (form - 1) * (form - 1);
}

double SyntheticShearBox::interaction_of(const nlohmann::json& m) {
    return (m.at("friction_coefficient").get<double>() - 0.5) * (m.at("bond_shear_strength").get<double>() / 1e3 - 2);
}

calibration::FailureLineEvaluation SyntheticShearBox::operator()(const nlohmann::json& material) {
    ++evaluations;
    const std::string key = material.dump();
    const bool seen = computed.count(key) > 0;
    computed.insert(key);
    std::unique_ptr<gsl_rng, decltype(&gsl_rng_free)> rng(gsl_rng_alloc(gsl_rng_mt19937), gsl_rng_free);
    const double mu = true_mu_b(material) + mu_interaction * interaction_of(material),
                 tau_c = true_tau_c(material) + tau_interaction * interaction_of(material);
    std::vector<double> sigma, tau;
    for (int rep = 0; rep < replicates; ++rep)
        for (std::size_t i = 0; i < normal_stresses.size(); ++i) {
            // One seed per (stress, replicate) like the orchestrator's runs; without CRN the material enters too.
            const unsigned long seed = 1 + rep * 1000 + i;
            const unsigned long material_seed = seed ^ std::hash<std::string>{}(key);
            gsl_rng_set(rng.get(), common_random_numbers ? seed : material_seed);
            double noise = gsl_ran_gaussian(rng.get(), noise_sd);
            gsl_rng_set(rng.get(), material_seed);
            noise += gsl_ran_gaussian(rng.get(), material_noise_sd);
            sigma.push_back(normal_stresses[i]);
            tau.push_back(mu * normal_stresses[i] + tau_c + noise);
        }
    calibration::FailureLineEvaluation ev;
    const int runs = static_cast<int>(sigma.size());
    (seen ? ev.simulations_reused : ev.simulations_run) = runs;
    ev.cpu_s = runs * 1.0;
    ev.peak = analytics::fit_failure_line(sigma, tau);
    ev.residual = ev.peak;
    return ev;
}

}  // namespace demcal::test
