// The silo case's facet walls in the discharge (demcal silo --discharge-wall-facets N): from the opening on, the cone
// and the cylinder are the N-sided facet polygons yade_scripts/silo.py builds, so the bed is the one the exact walls
// fill; the run resumes from checkpoints bit for bit with the choice stored; a bad count is refused by name.
#include "kernel/silo/silo_case.hpp"
#include "silo_resume_check.hpp"

#include "tiny_silo.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace demcal::kernel;
using namespace demcal::kernel::silo;

TEST_CASE("silo facet walls: silo.py's polygons, two triangles a side, the facets at the walls' mean radius",
          "[silo][walls]") {
    const SiloCaseSettings s = demcal::test::tiny_silo_case();
    const SiloGeometry& g = s.geometry;
    const int sides = 24;
    const double wall_top = g.top() + 0.01;
    const std::vector<Wall> walls = silo_facet_walls(g, 0, wall_top, sides, nullptr, VibratingPart::bin);
    REQUIRE(walls.size() == std::size_t(4 * sides));
    // a point at the middle of a cylinder side, on the exact wall's radius, at mid height: the facet's face touches a
    // sphere there with the mean-radius offset, (1 - (pi/N)/tan(pi/N)) R inside the exact wall
    const double R = g.top_half(), z = 0.5 * (g.hopper_height() + wall_top);
    const double mid_angle = M_PI / sides;  // between vertices 0 and 1
    const Vec3 on_exact_wall(R * std::cos(mid_angle), R * std::sin(mid_angle), z);
    const double facet_distance = R * (M_PI / sides) / std::tan(M_PI / sides);
    const double r = 0.001;
    const Vec3 centre = on_exact_wall * ((R - 0.5 * r) / R);  // a sphere pressed half its radius into the exact wall
    Vec3 n;
    double dn = 0, dist = 0, deepest = 0;
    for (const Wall& w : walls)
        if (w.contact(centre, r, n, dn, dist)) deepest = std::max(deepest, dn);
    CHECK(deepest == Approx(r - (facet_distance - (R - 0.5 * r))).epsilon(1e-9));
    CHECK_THROWS(silo_facet_walls(SiloGeometry::rectangular(60, 0.02, 0.03, 0.06, 0.1), 0, 0.2, sides, nullptr, VibratingPart::bin));
}

TEST_CASE("silo case: facet walls in the discharge leave the filling and change the discharge only a little",
          "[silo][walls]") {
    demcal::test::check_discharge_switch_keeps_rate(
        demcal::test::tiny_silo_case(), [](SiloCaseSettings& s) { s.discharge_wall_facets = 36; }, 0.15);
}

TEST_CASE("silo case: a run discharging on facet walls resumes bit for bit, the choice stored", "[silo][walls][checkpoint]") {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    s.discharge_wall_facets = 36;
    const SiloCaseSettings stored = demcal::test::check_resumes_bit_for_bit(s, "wall-facets", 0.05);
    CHECK(stored.discharge_wall_facets == 36);
}

TEST_CASE("silo case: a facet count out of range, or facets on a rectangular silo, is refused by name", "[silo][walls]") {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    for (int bad : {-1, 5, 11, 2001}) {
        s.discharge_wall_facets = bad;
        CHECK_THROWS_WITH(validate(s), Catch::Contains("discharge_wall_facets") && Catch::Contains(std::to_string(bad)));
    }
    s.discharge_wall_facets = 72;
    s.geometry = SiloGeometry::rectangular(60, 0.02, 0.03, 0.06, 0.1);
    CHECK_THROWS_WITH(validate(s), Catch::Contains("discharge_wall_facets") && Catch::Contains("conical"));
}
