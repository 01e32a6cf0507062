// Measured-like data sets with a known generating process, for testing and demonstrating `diagnose`: a discharge or
// shear model plus (optionally) one effect the model lacks, replicates, relative noise, and decoy covariates
// (replicate, run_order, moisture_pct, temperature_C, operator, vibration_Hz) that are pure noise unless the effect
// lives in them. Seeded: the same spec gives the same table.
#pragma once
#include "analytics/measured_data.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace demcal::analytics {

struct SyntheticSpec {
    std::string model = "oldal";  // generating model: beverloo | johanson | oldal | oldal-rect | failure-line
    // The undeclared effect: none | moisture (moisture_pct) | hopper_angle (theta_deg, Rose-Tanaka) |
    // annulus (d_p_m, empty annulus k d_p with k above the model's) | drift (run_order) | operator (operator C reads
    // high) | curved_locus (sigma_Pa, failure-line only) | vibration_by_mode (vibration_Hz raises W in mass flow, leaves
    // it in mixed flow, lowers it in funnel flow, as the seed measured; the seed's seven angles 10-70 deg; beverloo
    // and oldal only) | hopper_angle+vibration_by_mode (both at effect_size: the kind of set on which issue 26 found
    // diagnose naming the angle alone) | outlier (one row, chosen by the seed, off by effect_size with a random sign:
    // a gross error, not an effect).
    std::string effect = "none";
    double effect_size = 0.2;  // relative change of the response between the extremes of the effect (0.2 = 20 %)
    double noise = 0.03;       // sd of the relative noise of W (or of tau, relative to the mean tau)
    int replicates = 2;        // runs per condition
    std::uint64_t seed = 1;
};

// The effects make_synthetic_set knows and the column each one lives in.
const std::vector<std::pair<std::string, std::string>>& synthetic_effects();

struct SyntheticSet {
    MeasuredData data;
    int outlier_line = 0;  // file line of the gross outlier (effect "outlier"), else 0
};

// Throws std::invalid_argument for an unknown model/effect or an effect the model's data cannot carry.
SyntheticSet make_synthetic(const SyntheticSpec& spec);
MeasuredData make_synthetic_set(const SyntheticSpec& spec);  // make_synthetic(spec).data

}  // namespace demcal::analytics
