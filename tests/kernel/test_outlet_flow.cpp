// The outlet-flow meter (kernel/silo/outlet_flow.hpp): which grains count as passing the outlet, the density and
// speed it reports over a window of frames, its checkpoint; and in a discharge, that its flux estimate rho v A comes
// out near the measured rate.
#include "kernel/silo/outlet_flow.hpp"
#include "kernel/silo/silo_case.hpp"

#include "tiny_silo.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>
#include <vector>

using namespace demcal::kernel;
using namespace demcal::kernel::silo;

TEST_CASE("outlet flow: the grains above the opening and below half its size, averaged over the window's frames",
          "[silo][outlet]") {
    const SiloGeometry cone = SiloGeometry::conical(30, 0.03, 0.07, 0.15);  // outlet radius 15 mm: zone 0 <= z < 15 mm
    const double m = 3e-5;
    OutletFlowMeter meter(cone, m);
    const std::vector<Eigen::Vector3d> positions = {
        {0, 0, 0.005},      // in
        {0.014, 0, 0.014},  // in (r 14 mm, z 14 mm)
        {0.016, 0, 0.005},  // outside the opening's radius
        {0, 0, 0.016},      // above the zone
        {0, 0, -0.001},     // below the outlet plane: leaving
    };
    const std::vector<Eigen::Vector3d> velocities(5, Eigen::Vector3d(0, 0, -0.5));
    std::vector<Eigen::Vector3d> faster = velocities;
    faster[0].z() = -1.5;
    meter.add_frame(positions, velocities, 1.0);
    meter.add_frame(positions, faster, 2.0);
    meter.add_frame({}, {}, 9.0);  // outside the window below

    const OutletFlowResult r = meter.result(0.5, 2.5);
    const double area = M_PI * 0.015 * 0.015, volume = area * 0.015;
    CHECK(r.frames == 2);
    CHECK(r.zone_height == Approx(0.015));
    CHECK(r.zone_volume == Approx(volume));
    CHECK(r.mean_grains == Approx(2));
    CHECK(r.solid_density == Approx(2 * m / volume));
    CHECK(r.downward_speed == Approx((0.5 + 0.5 + 1.5 + 0.5) / 4));
    CHECK(r.flux_rate == Approx(r.solid_density * r.downward_speed * area));
    // an empty window reports no grains, not a division by zero
    const OutletFlowResult none = meter.result(3, 4);
    CHECK(none.frames == 0);
    CHECK(none.solid_density == 0);
    CHECK(none.downward_speed == 0);

    // the checkpoint holds every frame
    std::stringstream state;
    StateWriter w(state);
    meter.save(w);
    w.checksum();
    OutletFlowMeter resumed(cone, m);
    StateReader reader(state, "test state");
    resumed.load(reader);
    reader.checksum();
    CHECK(resumed.result(0, 10).frames == 3);
    CHECK(resumed.result(0.5, 2.5).downward_speed == r.downward_speed);
}

TEST_CASE("outlet flow: a slot's zone spans the outlet's width and the bin's depth", "[silo][outlet]") {
    const SiloGeometry slot = SiloGeometry::rectangular(60, 0.02, 0.1, 0.05, 0.15);  // a = 20 mm, depth 100 mm
    OutletFlowMeter meter(slot, 1.0);
    meter.add_frame({{0.009, 0.049, 0.005}, {0.011, 0, 0.005}, {0, 0.051, 0.005}, {0, 0, 0.011}},
                    std::vector<Eigen::Vector3d>(4, Eigen::Vector3d(0, 0, -1)), 0);
    const OutletFlowResult r = meter.result(-1, 1);
    CHECK(r.mean_grains == 1);
    CHECK(r.zone_volume == Approx(0.02 * 0.1 * 0.01));
}

// A 10 deg hopper of 2000 grains: the bed's surface stays far above the zone over the rate's window (the tiny case's
// 600 grains in a 30 deg hopper drain down to it).
TEST_CASE("outlet flow: in a discharge, rho v A over the outlet is near the measured rate", "[silo][outlet]") {
    SiloCaseSettings s = demcal::test::tiny_silo_case();
    s.geometry = SiloGeometry::conical(10, 0.03, 0.07, 0.15);
    s.particles = 2000;
    s.max_time = 0.3;
    const SiloCaseResult r = run_silo_case(s);
    REQUIRE(r.fit.ok);
    INFO("rate " << r.fit.rate << " kg/s; outlet: " << r.outlet.frames << " frames, " << r.outlet.mean_grains
                 << " grains, density " << r.outlet.solid_density << " kg/m^3, speed " << r.outlet.downward_speed
                 << " m/s, rho v A " << r.outlet.flux_rate << " kg/s");
    CHECK(r.outlet.frames >= 10);
    // no denser than the filled bed, moving down at about the speed of a fall through the outlet's size
    CHECK(r.outlet.solid_density > 0.2 * r.bulk_density);
    CHECK(r.outlet.solid_density < r.bulk_density);
    CHECK(r.outlet.downward_speed > 0.5 * std::sqrt(2 * 9.81 * 0.015));
    CHECK(r.outlet.downward_speed < 2 * std::sqrt(2 * 9.81 * 0.03));
    // the flux estimate within a factor 2 of the rate (density and speed vary inside the zone)
    CHECK(r.outlet.flux_rate > 0.5 * r.fit.rate);
    CHECK(r.outlet.flux_rate < 2 * r.fit.rate);
}
