// The grain's elongation (issue 26's grain-shape candidate): the family of kernel/silo/wheat.hpp keeps the seed's
// volume while its length / width changes, gives the seed's grain bit for bit at the seed's ratio, is refused outside
// its bounds with the field named, survives a checkpoint, and changes the flow the way a longer grain does.
#include "kernel/silo/silo_case.hpp"
#include "kernel/silo/wheat.hpp"
#include "silo_resume_check.hpp"

#include "tiny_silo.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace demcal::kernel::silo;
using Catch::Matchers::Contains;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Volume of the lens two spheres (radii R, r, centres d apart, overlapping) have in common.
double lens_volume(double R, double r, double d) {
    return kPi * std::pow(R + r - d, 2) * (d * d + 2 * d * r - 3 * r * r + 2 * d * R + 6 * r * R - 3 * R * R) /
           (12 * d);
}

double ball(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

}  // namespace

TEST_CASE("grain shape: the union volume of coaxial spheres is exact", "[silo][shape]") {
    CHECK(coaxial_union_volume({{Eigen::Vector3d(0.3, 0, 0), 0.002}}) == Approx(ball(0.002)).epsilon(1e-13));
    // apart: the sum; one inside the other: the larger
    CHECK(coaxial_union_volume({{Eigen::Vector3d(0, 0, 0), 1.0}, {Eigen::Vector3d(3, 0, 0), 0.5}}) ==
          Approx(ball(1.0) + ball(0.5)).epsilon(1e-13));
    CHECK(coaxial_union_volume({{Eigen::Vector3d(0, 0, 0), 1.0}, {Eigen::Vector3d(0.2, 0, 0), 0.5}}) ==
          Approx(ball(1.0)).epsilon(1e-13));
    // the seed's grain: the end spheres (3 mm apart, radii 1.25 mm) overlap the middle one, not each other: two lenses
    const double seed = ball(0.0015) + 2 * ball(0.00125) - 2 * lens_volume(0.0015, 0.00125, 0.0015);
    CHECK(coaxial_union_volume(wheat_clump()) == Approx(seed).epsilon(1e-13));
    CHECK(seed == Approx(wheat_grain_volume()).epsilon(2e-3));  // the seed's 0.0356 g at 1430 kg/m^3
}

TEST_CASE("grain shape: an elongated grain keeps the seed's volume and takes the asked length / width",
          "[silo][shape]") {
    CHECK(wheat_aspect_ratio == Approx(wheat_length / 0.003));
    const double seed_volume = coaxial_union_volume(wheat_clump());
    for (double ratio : {1.0, 1.2, 1.5, 1.7, 2.0, 2.3, 2.6}) {
        INFO("aspect ratio " << ratio);
        const auto g = elongated_wheat_clump(ratio);
        REQUIRE(g.size() == 3);
        CHECK(clump_length(g) / (2 * g[1].radius) == Approx(ratio).epsilon(1e-12));
        CHECK(coaxial_union_volume(g) == Approx(seed_volume).epsilon(1e-12));
        CHECK(g[0].radius / g[1].radius == Approx(1.25 / 1.5).epsilon(1e-14));  // the seed's members, moved
        CHECK(g[0].centre.x() == Approx(-g[2].centre.x()).epsilon(1e-14));
        // the grid-integrated template (what the kernel uses) agrees with the exact volume
        const auto t = wheat_grain_template(1430, ratio);
        CHECK(t.volume == Approx(seed_volume).epsilon(2e-3));
        // the long axis is the one of least inertia, unless the grain is a sphere
        if (ratio > 1.1) CHECK(t.inertia[0] < t.inertia[1]);
    }
    // longer grains are thinner
    CHECK(elongated_wheat_clump(2.4)[1].radius < elongated_wheat_clump(1.4)[1].radius);
}

TEST_CASE("grain shape: the seed's ratio is the seed's grain, bit for bit", "[silo][shape]") {
    const auto g = elongated_wheat_clump(wheat_aspect_ratio), seed = wheat_clump();
    for (std::size_t i = 0; i < seed.size(); ++i) {
        CHECK(g[i].centre == seed[i].centre);
        CHECK(g[i].radius == seed[i].radius);
    }
    const auto t = wheat_grain_template(1430, wheat_aspect_ratio), w = demcal::kernel::wheat_clump_template(1430);
    CHECK(t.mass == w.mass);
    CHECK(t.inertia == w.inertia);
    CHECK(t.offsets == w.offsets);
}

TEST_CASE("grain shape: an aspect ratio outside [1, 2.6] is refused with the field named", "[silo][shape]") {
    for (double bad : {0.99, 2.61, 3.0, std::numeric_limits<double>::quiet_NaN(), -1.0}) {
        INFO(bad);
        CHECK_THROWS_WITH(elongated_wheat_clump(bad), Contains("grain.aspect_ratio"));
        SiloCaseSettings s = demcal::test::tiny_silo_case();
        s.materials.grain_aspect_ratio = bad;
        CHECK_THROWS_WITH(validate(s), Contains("grain.aspect_ratio"));
    }
}

TEST_CASE("grain shape: an elongated-grain run killed at checkpoints resumes bit for bit, its shape stored",
          "[silo][shape][checkpoint]") {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    s.materials.grain_aspect_ratio = 2.2;
    const SiloCaseSettings stored = demcal::test::check_resumes_bit_for_bit(s, "grain-shape", 0.1);
    CHECK(stored.materials.grain_aspect_ratio == 2.2);
}

TEST_CASE("grain shape: longer grains of the same volume discharge slower, rounder ones faster", "[silo][shape]") {
    // the same seed, the same number of grains of the same mass: only the shape differs. Measured on the reduced
    // silo (2000 grains, 30 deg, 22 mm): 72.8 g/s at 1.3, 65.1 at the seed's 1.83, 51.4 at 2.4.
    auto run = [](double ratio) {
        SiloCaseSettings s = demcal::test::tiny_silo_case();
        s.materials.grain_aspect_ratio = ratio;
        s.max_time = 0.4;
        return run_silo_case(s);
    };
    const SiloCaseResult round = run(1.3), seed = run(wheat_aspect_ratio), longer = run(2.4);
    REQUIRE(round.fit.ok);
    REQUIRE(seed.fit.ok);
    REQUIRE(longer.fit.ok);
    CHECK(round.grain_mass == Approx(longer.grain_mass).epsilon(2e-3));
    CHECK(round.fit.rate > seed.fit.rate);
    CHECK(seed.fit.rate > longer.fit.rate);
}
