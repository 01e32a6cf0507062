// Cohesion in the silo case (issue 24): a material with a surface energy runs on the JKR law (EDEM's "Hertz-Mindlin
// with JKR cohesion"), a strongly cohesive bed arches over the outlet that the same material without cohesion flows
// through, vibration strong enough breaks that arch, a cohesive run resumes from its checkpoints bit for bit (the law
// is chosen again from the stored settings, the JKR contact history is saved), and bad surface energies are refused
// naming the pair and the value.
//
// Tiny case: 600 grains in a 30 deg cone (D = 70 mm, 30 mm outlet), shear moduli scaled by 1e-3 as the reduced silo
// tests do.
#include "kernel/silo/silo_case.hpp"
#include "silo_resume_check.hpp"

#include "tiny_silo.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace demcal::kernel::silo;

namespace {

SiloCaseSettings tiny_case(double surface_energy) {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    s.materials.wheat_wheat.surface_energy = surface_energy;
    s.materials.wheat_steel.surface_energy = surface_energy;
    s.max_time = 0.4;
    s.stop_fraction = 0.5;
    return s;
}

double fraction_out(const SiloCaseResult& r) { return r.discharge.back().mass / r.filled_mass; }

}  // namespace

TEST_CASE("silo case: a cohesive material arches over the outlet its cohesionless twin flows through",
          "[silo][cohesion]") {
    const SiloCaseResult dry = run_silo_case(tiny_case(0));
    CHECK(dry.contact_law.find("JKR") == std::string::npos);
    CHECK(fraction_out(dry) >= 0.5);  // half out within 0.4 s: the stop fraction ended it
    CHECK(dry.end == DischargeEnd::stop_fraction);

    // gamma = 0.5 J/m^2: pull-off 3 pi gamma R* ~ 3e-3 N between two end spheres (R* = 0.625 mm), 9 grain weights
    const SiloCaseResult wet = run_silo_case(tiny_case(0.5));
    CHECK(wet.contact_law.find("JKR") != std::string::npos);
    INFO("cohesive: " << fraction_out(wet) << " out, " << wet.stop_reason);
    CHECK(fraction_out(wet) < 0.1);
    CHECK(wet.end == DischargeEnd::time_limit);  // 0.4 s: shorter than the stall time

    // the same arch shaken hard (the whole bin, 1 mm along x at 100 Hz: 40 g) from the opening
    SiloCaseSettings shaken = tiny_case(0.5);
    shaken.vibration.frequency = 100;
    shaken.vibration.amplitude = 1e-3;
    const SiloCaseResult broken = run_silo_case(shaken);
    INFO("shaken: " << fraction_out(broken) << " out, " << broken.stop_reason);
    CHECK(fraction_out(broken) > fraction_out(wet) + 0.3);
}

TEST_CASE("silo case: a cohesive run killed at checkpoints resumes to the uninterrupted result bit for bit",
          "[silo][cohesion][checkpoint]") {
    SiloCaseSettings s = tiny_case(0.3);
    s.stop_fraction = 1;
    s.max_time = 0.15;
    const SiloCaseSettings stored = demcal::test::check_resumes_bit_for_bit(s, "cohesion", 0.05);
    CHECK(stored.materials.wheat_wheat.surface_energy == 0.3);
    CHECK(stored.materials.wheat_steel.surface_energy == 0.3);
}

TEST_CASE("silo case: bad surface energies name the pair and the value", "[silo][cohesion]") {
    for (double bad : {-0.1, 101.0}) {
        SiloCaseSettings s = tiny_case(0);
        s.materials.wheat_wheat.surface_energy = bad;
        CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("grain_grain.surface_energy"));
        s = tiny_case(0);
        s.materials.wheat_steel.surface_energy = bad;
        CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("grain_wall.surface_energy"));
    }
}
