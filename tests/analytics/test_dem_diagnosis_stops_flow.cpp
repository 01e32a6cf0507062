// diagnose_dem when a candidate's value stops the flow (a cohesion that arches the bed): the search keeps to the
// flowing side, the values that stopped it are reported, and a declared material that does not flow is refused.
#include "analytics/dem_diagnosis.hpp"
#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>

namespace an = demcal::analytics;

namespace {

// A stand-in for the kernel's silo: rate = 200 (1 - theta/100) exp(-3 p); from p >= kArches on the bed arches (no
// rate) at 30 deg and steeper, as a cohesive bed does above the mass-flow angles.
constexpr double kArches = 0.2;
double model_rate(double theta, double p) {
    if (p >= kArches && theta >= 30) return NAN;
    return 200.0 * (1.0 - theta / 100.0) * std::exp(-3.0 * p);
}

an::SiloMeasurements measured(double p_true) {
    an::SiloMeasurements m;
    m.source = "synthetic";
    const double thetas[] = {20, 30, 40, 50};
    const double scatter[] = {-0.02, 0.0, 0.02};  // a repeat scatter of 2 %
    int line = 2;
    for (std::size_t c = 0; c < 4; ++c) {
        an::SiloCondition cond;
        cond.theta_deg = thetas[c];
        m.conditions.push_back(cond);
        for (double e : scatter) {
            m.condition_of_row.push_back(c);
            m.rate_g_s.push_back(model_rate(thetas[c], p_true) * (1 + e));
            m.lines.push_back(line++);
        }
    }
    return m;
}

an::DemCandidateSetup cohesion_like(const an::SiloMeasurements& m, int* calls) {
    an::DemCandidateSetup s;
    s.spec = {"cohesion", {"grain_grain.surface_energy_J_m2"}, 0.0, 0.3, an::ParameterScale::linear, "test", 0.0};
    s.declared = 0.0;
    s.predict = [&m, calls](const std::vector<double>& values) {
        std::vector<std::vector<double>> out;
        for (double v : values) {
            ++*calls;
            std::vector<double> per;
            for (const auto& c : m.conditions) per.push_back(model_rate(c.theta_deg, v));
            out.push_back(per);
        }
        return out;
    };
    return s;
}

std::vector<double> declared_rates(const an::SiloMeasurements& m, double p) {
    std::vector<double> r;
    for (const auto& c : m.conditions) r.push_back(model_rate(c.theta_deg, p));
    return r;
}

}  // namespace

TEST_CASE("silo-dem: values that stop the flow confine the search to the flowing side and are reported",
          "[diagnose][silo-dem]") {
    const auto data = measured(0.1);
    int calls = 0;
    an::DemDiagnoseOptions o;
    o.grid_points = 5;  // 0, 0.075, 0.15, 0.225, 0.3: the last two arch the bed
    const auto r = an::diagnose_dem(data, declared_rates(data, 0.0), {cohesion_like(data, &calls)}, o);
    REQUIRE(r.candidates.size() == 1);
    const auto& c = r.candidates[0];
    REQUIRE(c.available);
    CHECK(c.stops_flow == std::vector<double>{0.225, 0.3});
    CHECK(c.spec.upper == 0.15);  // the last flowing value run
    CHECK(c.spec.lower == 0.0);
    CHECK(c.fitted == Approx(0.1).margin(0.01));
    CHECK(c.interval_low <= 0.1);
    CHECK(c.interval_high >= 0.1);
    CHECK(r.effect == 0);
    CHECK(r.rmse_after < 0.5 * r.rmse_before);
    const auto j = r.to_json(data);
    CHECK(j["candidates"][0]["stops_flow"].size() == 2);
}

TEST_CASE("silo-dem: a candidate that stops the flow next to the declared value is not tried, and says why",
          "[diagnose][silo-dem]") {
    const auto data = measured(0.0);
    int calls = 0;
    an::DemDiagnoseOptions o;
    o.grid_points = 3;  // 0 (declared), 0.15, 0.3: one flowing value besides the declared one
    auto setup = cohesion_like(data, &calls);
    setup.spec.upper = 0.4;  // grid 0, 0.2, 0.4: both beyond the declared arch the bed
    const auto r = an::diagnose_dem(data, declared_rates(data, 0.0), {setup}, o);
    REQUIRE(r.candidates.size() == 1);
    CHECK_FALSE(r.candidates[0].available);
    CHECK_THAT(r.candidates[0].unavailable, Catch::Matchers::Contains("the flow stops at 0.2"));
    CHECK(r.effect == -1);
}

TEST_CASE("silo-dem: a declared material that does not discharge where the data have a rate is refused",
          "[diagnose][silo-dem]") {
    const auto data = measured(0.1);
    int calls = 0;
    auto rates = declared_rates(data, 0.1);
    rates[2] = NAN;  // (40 deg: no steady rate)
    CHECK_THROWS_WITH(an::diagnose_dem(data, rates, {cohesion_like(data, &calls)}, {}),
                      Catch::Matchers::Contains("does not discharge at theta40"));
    CHECK(calls == 0);
}
