// Silo case parts that do not run the DEM: geometry, wheat defaults, rate fit, flow-pattern measure, section, output.
#include "kernel/silo/discharge_fit.hpp"
#include "kernel/silo/flow_pattern.hpp"
#include "kernel/silo/section_field.hpp"
#include "kernel/silo/silo_geometry.hpp"
#include "kernel/silo/silo_output.hpp"
#include "kernel/silo/wheat.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

using namespace demcal::kernel::silo;
using Catch::Matchers::Contains;

namespace {
constexpr double pi = 3.14159265358979323846;
std::string invalid_message(const SiloGeometry& g, double dp = wheat_length) {
    try {
        validate(g, dp);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}
}  // namespace

TEST_CASE("silo geometry: the seed's conical silo", "[silo]") {
    const auto g = SiloGeometry::conical(10);
    REQUIRE_NOTHROW(validate(g, wheat_length));
    CHECK(g.hopper_height() == Approx(0.035 / std::tan(10 * pi / 180)).epsilon(1e-12));
    CHECK(g.half_size_at(0) == Approx(0.0175));
    CHECK(g.half_size_at(g.hopper_height() + 0.1) == Approx(0.0525));
    // frustum volume + cylinder volume
    const double h = g.hopper_height();
    const double v = pi * h / 3 * (0.0175 * 0.0175 + 0.0175 * 0.0525 + 0.0525 * 0.0525) + pi * 0.0525 * 0.0525 * 0.4;
    CHECK(g.volume() == Approx(v).epsilon(1e-9));
    CHECK(g.volume_below(h / 2) < g.volume_below(h));
    // a point on the axis at mid hopper height is inside; one beyond the slanted wall is not
    CHECK(g.contains({0, 0, h / 2}, 0.0015));
    CHECK_FALSE(g.contains({g.half_size_at(h / 2), 0, h / 2}, 0.0015));
    CHECK(g.distance_to_side_wall({0, 0, h + 0.1}) == Approx(0.0525));
    CHECK(g.distance_to_side_wall({0, 0, h / 2}) == Approx(g.half_size_at(h / 2) * std::cos(10 * pi / 180)));
    const auto g70 = SiloGeometry::conical(70);
    CHECK(g70.hopper_height() == Approx(0.035 / std::tan(70 * pi / 180)));
}

TEST_CASE("silo geometry: rectangular hopper", "[silo]") {
    const auto g = SiloGeometry::rectangular(60, 0.03, 0.05, 0.1);
    REQUIRE_NOTHROW(validate(g, wheat_length));
    CHECK(g.hopper_height() == Approx(0.035 / std::tan(60 * pi / 180)));
    CHECK(g.outlet_area() == Approx(0.03 * 0.05));
    CHECK(g.volume() == Approx((0.03 + 0.1) / 2 * g.hopper_height() * 0.05 + 0.1 * 0.05 * 0.4));
    CHECK(g.distance_to_side_wall({0, 0.02, 0.3}) == Approx(0.005));
    CHECK(g.transverse({-0.01, 0.02, 0.1}) == Approx(0.01));
}

TEST_CASE("silo geometry: bad input names the field and the value", "[silo]") {
    CHECK_THAT(invalid_message(SiloGeometry::conical(0)), Contains("theta = 0"));
    CHECK_THAT(invalid_message(SiloGeometry::conical(90)), Contains("theta = 90"));
    CHECK_THAT(invalid_message(SiloGeometry::conical(-5)), Contains("theta = -5"));
    CHECK_THAT(invalid_message(SiloGeometry::conical(30, 0.01)), Contains("outlet = 0.01"));
    CHECK_THAT(invalid_message(SiloGeometry::conical(30, 0.01)), Contains("particle sizes"));
    CHECK_THAT(invalid_message(SiloGeometry::conical(30, 0.035, 0.03)), Contains("diameter = 0.03"));
    CHECK_THAT(invalid_message(SiloGeometry::conical(30, 0.035, 0.105, -1)), Contains("body_height = -1"));
    CHECK_THAT(invalid_message(SiloGeometry::conical(0.01)), Contains("theta = 0.01"));
    CHECK_THAT(invalid_message(SiloGeometry::rectangular(30, 0.03, 0.01, 0.1)), Contains("b (depth) = 0.01"));
    CHECK_THAT(invalid_message(SiloGeometry::rectangular(30, 0.12, 0.05, 0.1)), Contains("c (width) = 0.1"));
    CHECK_THAT(invalid_message(SiloGeometry::rectangular(30, 0.03, 0.05, 0.1), 0), Contains("particle_size = 0"));
}

TEST_CASE("wheat grain and Table 2.1 defaults", "[silo]") {
    const auto c = wheat_clump();
    REQUIRE(c.size() == 3);
    CHECK(c[1].radius == 0.0015);
    CHECK(c[0].radius == 0.00125);
    CHECK((c[2].centre - c[1].centre).norm() == Approx(0.0015));
    CHECK(wheat_equivalent_diameter() == Approx(0.00362).epsilon(0.01));
    WheatMaterials m;
    CHECK(m.wheat.shear_modulus == 3.58e8);
    CHECK(m.wheat_wheat.restitution == 0.5);
    CHECK(m.wheat_steel.friction == 0.25);
    // the reference note: 8.33 us for R = 1.25 mm
    CHECK(rayleigh_time_step(m.wheat, 0.00125) == Approx(8.33e-6).epsilon(0.01));
    m.stiffness_scale = 0.01;
    CHECK(rayleigh_time_step(m.wheat_scaled(), 0.00125) == Approx(8.33e-5).epsilon(0.01));
}

TEST_CASE("discharge rate: least squares over the steady part", "[silo]") {
    std::vector<DischargeSample> s;
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0, 1e-4);
    // start-up curvature below 10 %, a linear part at 0.2 kg/s, then a tail
    for (int i = 0; i <= 500; ++i) {
        const double t = i * 0.002;
        double m = t < 0.1 ? 0.1 * t * t / 0.1 : 0.01 + 0.2 * (t - 0.1);
        m = std::min(m, 0.15);
        s.push_back({t, m + noise(rng)});
    }
    const auto f = fit_discharge_rate(s, 0.15);
    REQUIRE(f.ok);
    CHECK(f.rate == Approx(0.2).epsilon(0.01));
    CHECK(f.r_squared > 0.999);
    CHECK(f.rate_se > 0);
    CHECK(f.rate_se < 0.002);
    CHECK(f.n > 50);
    CHECK(f.batches == 4);
    CHECK(f.rate_batch_se > 0);
    CHECK(f.rate_batch_se < 0.01);
    CHECK(fit_discharge_rate({{0, 0}, {1, 1}}, 1).ok == false);
    // nothing discharged: the window of a zero mass held every sample and fitted 0 g/s with R^2 = 1, "determined"
    std::vector<DischargeSample> none;
    for (int k = 0; k < 20; ++k) none.push_back({0.01 * k, 0.0});
    const auto empty = fit_discharge_rate(none, 0.0);
    CHECK_FALSE(empty.ok);
    CHECK(empty.message == "nothing was discharged");
    // a mass that does not change inside the window (all samples on one plateau) determines no rate either
    std::vector<DischargeSample> plateau;
    for (int k = 0; k < 20; ++k) plateau.push_back({0.01 * k, 0.05});
    CHECK_FALSE(fit_discharge_rate(plateau, 0.1).ok);
}

TEST_CASE("flow pattern: synthetic mass, funnel and mixed velocity fields", "[silo]") {
    const auto g = SiloGeometry::conical(30);
    const double hh = g.hopper_height();
    auto frame = [&](double wall_factor, std::vector<Eigen::Vector3d>& p, std::vector<Eigen::Vector3d>& v) {
        p.clear();
        v.clear();
        for (double z = 0.003; z < hh; z += 0.003)
            for (double f = 0.05; f < 1.0; f += 0.05) {
                const double half = g.half_size_at(z);
                p.emplace_back(f * half - 0.001, 0, z);
                const bool wall = (half - (f * half - 0.001)) * std::cos(pi / 6) <= 0.0055;  // the measure's wall layer
                v.emplace_back(0, 0, wall ? -0.2 * wall_factor : -0.2);
            }
    };
    for (double wf : {0.9, 0.02, 0.35}) {
        FlowPatternClassifier c(g);
        std::vector<Eigen::Vector3d> p, v;
        frame(wf, p, v);
        c.add_frame(p, v);
        c.add_frame(p, v);
        const auto r = c.result();
        CHECK(r.frames == 2);
        CHECK(r.wall_samples > 0);
        CHECK(r.ratio == Approx(wf).epsilon(1e-9));
        CHECK(r.pattern == (wf > 0.5 ? FlowPattern::mass : wf < 0.25 ? FlowPattern::funnel : FlowPattern::mixed));
        CHECK_THAT(r.measure, Contains("mass flow >= 0.5"));
    }
    FlowPatternClassifier empty(g);
    CHECK(empty.result().pattern == FlowPattern::undetermined);
}

TEST_CASE("section field and output files", "[silo]") {
    const auto g = SiloGeometry::conical(45, 0.035, 0.105, 0.1);
    SectionField sec(g, 0.005, 0.006, g.top());
    sec.add_frame({{0.001, 0.0, 0.02}, {0.001, 0.02, 0.02}}, {{0, 0, -0.5}, {0, 0, -9}});
    sec.add_frame({{0.001, 0.0, 0.02}}, {{0, 0, -0.3}});
    int hits = 0;
    for (int i = 0; i < sec.nx(); ++i)
        for (int k = 0; k < sec.nz(); ++k)
            if (!std::isnan(sec.vz(i, k))) {
                ++hits;
                CHECK(sec.vz(i, k) == Approx(-0.4));
            }
    CHECK(hits == 1);
    const auto dir = std::filesystem::temp_directory_path() / "demcal_test_silo_parts";
    std::filesystem::create_directories(dir);
    sec.write_grid(dir / "grid.dat");
    sec.write_outline(dir / "outline.dat");
    CHECK(discharge_csv_text({{0, 0, 0}, {0.1, 0.02, 560}}) ==
          "time_s,discharged_mass_kg,discharged_grains\n0,0,0\n0.1,0.02,560\n");
    SphereSnapshot s;
    s.positions = {{0, 0, 0.1}};
    s.velocities = {{0, 0, -1}};
    s.radii = {0.0015};
    s.clump = {0};
    write_vtk(dir / "s.vtk", s, 0.5);
    const std::string vtk = demcal::test::read_file(dir / "s.vtk");
    CHECK_THAT(vtk, Contains("POINTS 1 double"));
    CHECK_THAT(vtk, Contains("VECTORS velocity double"));
    CHECK_FALSE(std::filesystem::exists(dir / "s.vtk.tmp"));  // written beside, then renamed
    std::filesystem::remove_all(dir);
}
