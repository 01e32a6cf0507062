// A stand-in for the kernel's silo in diagnose_dem tests: rate = 200 (1 - theta/100) exp(-k p) at angles 20-50 deg,
// "measured" with a repeat scatter of 2 %; from p >= arches_from on the bed arches (no rate) at 30 deg and steeper.
// With steep_near > 0 the rate instead stays nearly flat and falls steeply toward p = steep_near (1 - (p/steep_near)^8 / 2),
// a response no low-degree polynomial over the whole range follows (cohesion near arching).
#pragma once
#include "analytics/dem_diagnosis.hpp"
#include <cmath>
#include <string>
#include <vector>

namespace demcal::test {

struct SyntheticSilo {
    double sensitivity = 3.0;    // k
    double arches_from = INFINITY;
    double steep_near = 0;
    double angle_slope = 0;      // w: the effect's strength varies with the angle, k p (1 + w (theta - 35) / 15)

    double response(double p) const {
        return steep_near > 0 ? 1.0 - 0.5 * std::pow(p / steep_near, 8) : std::exp(-sensitivity * p);
    }

    double rate(double theta, double p) const {
        if (p >= arches_from && theta >= 30) return NAN;
        return 200.0 * (1.0 - theta / 100.0) * response(p * (1 + angle_slope * (theta - 35) / 15));
    }
    // repeats: times the scatter pattern -2 %, 0, +2 % per condition
    analytics::SiloMeasurements measured(double p_true, int repeats = 1) const {
        analytics::SiloMeasurements m;
        m.source = "synthetic";
        const double thetas[] = {20, 30, 40, 50};
        const double scatter[] = {-0.02, 0.0, 0.02};
        int line = 2;
        for (std::size_t c = 0; c < 4; ++c) {
            analytics::SiloCondition cond;
            cond.theta_deg = thetas[c];
            m.conditions.push_back(cond);
            for (int rep = 0; rep < repeats; ++rep)
            for (double e : scatter) {
                m.condition_of_row.push_back(c);
                m.rate_g_s.push_back(rate(thetas[c], p_true) * (1 + e));
                m.lines.push_back(line++);
            }
        }
        return m;
    }
    std::vector<double> rates(const analytics::SiloMeasurements& m, double p) const {
        std::vector<double> r;
        for (const auto& c : m.conditions) r.push_back(rate(c.theta_deg, p));
        return r;
    }
    // A candidate over [0, upper] (declared 0) whose predictions are this model's; counts its runs in *calls.
    analytics::DemCandidateSetup candidate(const std::string& name, const std::string& field, double upper,
                                           const analytics::SiloMeasurements& m, int* calls) const {
        analytics::DemCandidateSetup s;
        s.spec = {name, {field}, 0.0, upper, analytics::ParameterScale::linear, "test", 0.0};
        s.declared = 0.0;
        const SyntheticSilo model = *this;
        s.predict = [model, &m, calls](const std::vector<double>& values) {
            std::vector<std::vector<double>> out;
            for (double v : values) {
                ++*calls;
                out.push_back(model.rates(m, v));
            }
            return out;
        };
        return s;
    }
};

}  // namespace demcal::test
