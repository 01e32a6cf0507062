// The discharge rate: the slope of the discharged mass against time over the steady part of the discharge.
#pragma once
#include <string>
#include <vector>

namespace demcal::kernel::silo {

struct DischargeSample {
    double time;  // since the outlet was opened [s]
    double mass;  // discharged mass [kg]
};

struct DischargeFit {
    bool ok = false;         // false when fewer than 3 samples lie in the window (message says why)
    std::string message;
    double rate = 0;         // slope [kg/s]
    double rate_se = 0;      // standard error of the slope [kg/s]
    double intercept = 0;    // [kg]
    // Batch estimate: the window cut into `batches` equal time spans, a slope fitted in each; the standard error of
    // their mean (sd / sqrt(batches)). It sees the fluctuation of the flow that rate_se (correlated samples) misses.
    double rate_batch_se = 0;
    int batches = 0;
    double r_squared = 0;
    int n = 0;               // samples used
    double t_begin = 0, t_end = 0;        // the time window used [s]
    double lower_fraction = 0.2, upper_fraction = 0.8;  // of the reference mass
    double reference_mass = 0;            // the mass the fractions refer to [kg]
};

// Ordinary least squares of mass on time over the samples whose mass lies within
// [lower_fraction, upper_fraction] x reference_mass (the steady part: the start-up after opening and the
// emptying of the last grains are left out). reference_mass is the total mass in the silo when it was opened.
DischargeFit fit_discharge_rate(const std::vector<DischargeSample>& samples, double reference_mass,
                                double lower_fraction = 0.2, double upper_fraction = 0.8);

}  // namespace demcal::kernel::silo
