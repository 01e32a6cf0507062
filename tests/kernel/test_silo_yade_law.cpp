// The silo case on YADE's Hertz-Mindlin (SiloContactLaw::yade, demcal silo --contact-law yade): the law a cross-check
// runs in both codes. It fills and discharges like the kernel's own law without rolling friction (the same grains, a
// different tangential law: close, not equal), refuses what it cannot model (rolling friction, cohesion) by name, and
// resumes from checkpoints bit for bit with the choice stored in them.
#include "kernel/silo/silo_case.hpp"
#include "silo_resume_check.hpp"

#include "tiny_silo.hpp"

#include <catch2/catch.hpp>

using namespace demcal::kernel::silo;
using Catch::Contains;

namespace {

// The tiny silo without rolling friction (YADE's silo.py default has none), on the given law.
SiloCaseSettings rolling_free(SiloContactLaw law) {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    s.materials.wheat_wheat.rolling_friction = 0;
    s.materials.wheat_steel.rolling_friction = 0;
    s.contact_law = law;
    return s;
}

}  // namespace

TEST_CASE("silo on YADE's law: the same bed fills, discharges at a rate close to the kernel's own law's, not equal",
          "[silo][yade-law]") {
    const SiloCaseResult edem = run_silo_case(rolling_free(SiloContactLaw::edem));
    const SiloCaseResult yade = run_silo_case(rolling_free(SiloContactLaw::yade));
    CHECK_THAT(yade.contact_law, Contains("YADE"));
    CHECK_THAT(edem.contact_law, !Contains("YADE"));
    // the same grains generated and poured: the filled mass is the same, the packing (and so the steps) may differ
    CHECK(yade.filled_mass == edem.filled_mass);
    REQUIRE(yade.fit.ok);
    REQUIRE(edem.fit.ok);
    CHECK_FALSE(demcal::test::same_discharge(yade, edem));
    // one law's tangential spring for another, at friction 0.3: a few per cent on the rate, not tens
    INFO("rate YADE law " << yade.fit.rate << " kg/s, kernel law " << edem.fit.rate << " kg/s");
    CHECK(yade.fit.rate / edem.fit.rate == Approx(1.0).margin(0.15));
}

TEST_CASE("silo on YADE's law: rolling friction and cohesion are refused by name, not dropped", "[silo][yade-law]") {
    SiloCaseSettings s = rolling_free(SiloContactLaw::yade);
    CHECK_NOTHROW(validate(s));
    s.materials.wheat_steel.rolling_friction = 0.01;
    CHECK_THROWS_WITH(validate(s), Contains("grain_wall.rolling_friction") && Contains("0.01") && Contains("yade"));
    s = rolling_free(SiloContactLaw::yade);
    s.materials.wheat_wheat.surface_energy = 0.05;
    CHECK_THROWS_WITH(validate(s), Contains("grain_grain.surface_energy") && Contains("0.05") && Contains("cohesion"));
    s = rolling_free(static_cast<SiloContactLaw>(9));
    CHECK_THROWS_WITH(validate(s), Contains("contact_law") && Contains("9"));
    // the kernel's own law keeps both
    s = demcal::test::tiny_silo_case();
    s.materials.wheat_wheat.surface_energy = 0.05;
    CHECK_NOTHROW(validate(s));
}

TEST_CASE("silo on YADE's law: a run killed at checkpoints resumes bit for bit, its law stored",
          "[silo][yade-law][checkpoint]") {
    const SiloCaseSettings stored =
        demcal::test::check_resumes_bit_for_bit(rolling_free(SiloContactLaw::yade), "yade-law", 0.05);
    CHECK(stored.contact_law == SiloContactLaw::yade);
}
