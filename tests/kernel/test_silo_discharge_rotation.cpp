// The silo case's discharge rotation scheme (demcal silo --discharge-rotation yade): the clumps turn by YADE's
// aspherical leapfrog from the opening on and only then, so the bed is the one the kernel's own scheme fills (the bed a
// cross-check gives YADE); the run resumes from checkpoints bit for bit with the choice stored, and a value that is not
// a scheme is refused by name.
#include "kernel/silo/silo_case.hpp"
#include "silo_resume_check.hpp"

#include "tiny_silo.hpp"

#include <catch2/catch.hpp>

using namespace demcal::kernel::silo;
using demcal::kernel::ClumpRotation;

TEST_CASE("silo case: YADE's clump rotation in the discharge leaves the filling and changes the discharge only a little",
          "[silo][clump-rotation]") {
    // two second-order integrators at the same step: the same flow within a run's own scatter
    demcal::test::check_discharge_switch_keeps_rate(
        demcal::test::tiny_silo_case(),
        [](SiloCaseSettings& s) { s.discharge_clump_rotation = ClumpRotation::yade_leapfrog; }, 0.15);
}

TEST_CASE("silo case: a run discharging on YADE's clump rotation resumes bit for bit, the choice stored",
          "[silo][clump-rotation][checkpoint]") {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    s.discharge_clump_rotation = ClumpRotation::yade_leapfrog;
    // killed while filling (the resumed session must switch at the opening), then in the discharge (it must switch again)
    const SiloCaseSettings stored = demcal::test::check_resumes_bit_for_bit(s, "yade-rotation", 0.05);
    CHECK(stored.discharge_clump_rotation == ClumpRotation::yade_leapfrog);
}

TEST_CASE("silo case: a discharge rotation that is not a scheme is refused by name, and the names are one table",
          "[silo][clump-rotation]") {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    s.discharge_clump_rotation = static_cast<ClumpRotation>(5);
    CHECK_THROWS_WITH(validate(s), Catch::Contains("discharge_clump_rotation") && Catch::Contains("5"));
    for (const auto& [name, scheme] : silo_clump_rotations()) CHECK(silo_clump_rotation_text(scheme) == name);
    CHECK(silo_clump_rotations().at("yade") == ClumpRotation::yade_leapfrog);
    CHECK(silo_clump_rotations().at("richardson") == ClumpRotation::richardson);
}
