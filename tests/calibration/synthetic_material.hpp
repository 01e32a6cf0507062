// An analytic stand-in for the YADE shear box, to test the calibration algorithms (not the physics): mu_b and tau_c
// are known functions of the micro parameters (constant, linear or parabolic in each, as in the seed's Table 3.1),
// and each "run" adds a packing noise fixed by its seed, the same for every material (common random numbers).
#pragma once
#include "calibration/macro_target.hpp"

#include <map>
#include <set>
#include <string>
#include <vector>

namespace demcal::test {

struct SyntheticShearBox {
    std::vector<double> normal_stresses{2e3, 4e3, 6e3};  // [Pa]
    int replicates = 1;
    double noise_sd = 20.0;              // [Pa] packing noise of one run's peak shear stress, fixed by its seed
    double material_noise_sd = 4.0;      // [Pa] the part that changes with the material (chaotic dynamics)
    bool common_random_numbers = true;   // false: all the noise changes with the material (fresh packings)
    std::set<std::string> computed;     // materials already "run": their runs count as reused
    int evaluations = 0;

    // friction x bond shear interaction, zero along both axes through the base material (0.5, 2 kPa): a one-at-a-time
    // study cannot see it
    double mu_interaction = 0.0, tau_interaction = 0.0;  // [-], [Pa] per unit of (f - 0.5) (bond_kPa - 2)
    static double interaction_of(const nlohmann::json& m);
    static double true_mu_b(const nlohmann::json& m);
    static double true_tau_c(const nlohmann::json& m);
    calibration::FailureLineEvaluation operator()(const nlohmann::json& material);
    calibration::FailureLineEvaluator evaluator() {
        return [this](const nlohmann::json& m) { return (*this)(m); };
    }
};

nlohmann::json synthetic_base_material();  // examples/materials/sand-tiny.json's values

}  // namespace demcal::test
