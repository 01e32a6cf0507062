// The reduced silo cases (issue 3, "How we will know"): 10 deg is mass flow and 70 deg funnel flow by the kernel's own
// classifier, the discharged mass is linear in time (R^2 > 0.99 over the steady part), mass is conserved and the rate
// is of the magnitude Beverloo predicts.
//
// Reduced case: 4000 wheat grains (the seed's clump and Table 2.1 coefficients) in a silo of D = 70 mm with a 30 mm
// outlet (d/d_p = 5.5 with the grain's 5.5 mm length, 8.3 with its 3.62 mm equivalent diameter: above Beverloo's
// ~5-6 d_p), shear moduli scaled by 1e-3 (G = 3.58e5 Pa) and dt = 0.25 of the Rayleigh step (66 us). Softer contacts
// allow the 3.2 times larger step; measured on the 70 deg case (seed 1): 0.1227 kg/s at scale 1e-3 against
// 0.1217 kg/s at 1e-2 (0.8 %), the flow-pattern ratio 0.043 against 0.044. The largest static overlap under the
// 5-10 cm bed is about 3 % of the radius. Both cases together ran in about 95 s on one thread (Release, machine
// shared with other jobs).
#include "kernel/silo/silo_case.hpp"
#include "silo_resume_check.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include <unistd.h>

using namespace demcal::kernel::silo;

namespace {

SiloCaseSettings reduced_case(double theta_deg) {
    SiloCaseSettings s;
    s.geometry = SiloGeometry::conical(theta_deg, 0.03, 0.07, 0.15);
    s.particles = 4000;
    s.materials.stiffness_scale = 1e-3;
    s.fill_time_max = 0.5;
    s.max_time = 4;
    s.threads = 1;
    s.seed = 1;
    return s;
}

// Beverloo W = C rho_b sqrt(g) (d - k d_p)^2.5, C = 0.58, k = 1.5, d_p the grain's equivalent diameter, times the
// Rose-Tanaka hopper factor (tan theta tan 45 deg)^-0.35 below 45 deg (a steep hopper discharges faster).
double beverloo(const SiloCaseSettings& s, double bulk_density) {
    const double d = s.geometry.outlet, dp = wheat_equivalent_diameter();
    const double w = 0.58 * bulk_density * std::sqrt(s.gravity) * std::pow(d - 1.5 * dp, 2.5);
    const double th = s.geometry.half_angle_deg * 3.14159265358979323846 / 180;
    return s.geometry.half_angle_deg < 45 ? w * std::pow(std::tan(th), -0.35) : w;
}

// 600 grains in a 30 deg wedge hopper (slot 30 mm x 30 mm deep, 60 mm wide, 100 mm body): about a second.
SiloCaseSettings small_rectangular_case() {
    SiloCaseSettings s;
    s.geometry = SiloGeometry::rectangular(30, 0.03, 0.03, 0.06, 0.1);
    s.particles = 600;
    s.materials.stiffness_scale = 1e-3;
    s.fill_time_max = 0.4;
    s.max_time = 0.3;
    s.threads = 1;
    return s;
}

void check_common(const SiloCaseSettings& s, const SiloCaseResult& r) {
    INFO("rate " << r.fit.rate << " +/- " << r.fit.rate_se << " kg/s, R^2 " << r.fit.r_squared << ", flow "
                 << to_string(r.flow.pattern) << " ratio " << r.flow.ratio << ", " << r.stop_reason << ", wall "
                 << r.wall_s << " s");
    CHECK(r.grains == s.particles);
    CHECK(r.fill_at_rest);
    // mass conservation: every grain is in the silo or discharged, and the recorded mass is theirs
    CHECK(r.grains_in_silo + r.grains_discharged == r.grains);
    CHECK(r.filled_mass == Approx(r.grains * r.grain_mass).epsilon(1e-9));
    REQUIRE_FALSE(r.discharge.empty());
    CHECK(r.discharge.back().grains == r.grains_discharged);
    CHECK(r.discharge.back().mass == Approx(r.grains_discharged * r.grain_mass).epsilon(1e-9));
    for (size_t i = 1; i < r.discharge.size(); ++i) REQUIRE(r.discharge[i].mass >= r.discharge[i - 1].mass);
    // the rate: linear steady part, finite, positive, of Beverloo's magnitude (within a factor 2 either way)
    REQUIRE(r.fit.ok);
    CHECK(std::isfinite(r.fit.rate));
    CHECK(r.fit.rate > 0);
    CHECK(r.fit.r_squared > 0.99);
    CHECK(r.fit.n > 20);
    const double w = beverloo(s, r.bulk_density);
    INFO("Beverloo (with the hopper factor) " << w << " kg/s, bulk density " << r.bulk_density);
    CHECK(r.bulk_density > 600);
    CHECK(r.bulk_density < 1000);
    CHECK(r.fit.rate > 0.5 * w);
    CHECK(r.fit.rate < 2.0 * w);
}

}  // namespace

TEST_CASE("reduced silo case, 10 deg hopper: mass flow, linear discharge", "[silo][slow]") {
    const auto s = reduced_case(10);
    const auto r = run_silo_case(s);
    check_common(s, r);
    INFO("wall/axis velocity ratio " << r.flow.ratio);
    CHECK(r.flow.pattern == FlowPattern::mass);
    CHECK(r.emptied());
}

TEST_CASE("reduced silo case, 70 deg hopper: funnel flow, linear discharge", "[silo][slow]") {
    const auto s = reduced_case(70);
    const auto r = run_silo_case(s);
    check_common(s, r);
    INFO("wall/axis velocity ratio " << r.flow.ratio);
    CHECK(r.flow.pattern == FlowPattern::funnel);
    CHECK(r.flow.wall_samples > 100);
}

TEST_CASE("silo case: bad settings name the field and the value", "[silo]") {
    auto s = reduced_case(30);
    s.particles = 0;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("particles = 0"));
    s = reduced_case(30);
    s.stop_fraction = 1.5;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("stop_fraction = 1.5"));
    s = reduced_case(95);
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("theta = 95"));
    s = reduced_case(30);
    s.geometry.outlet = 0.012;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("outlet = 0.012"));
    s = reduced_case(30);
    s.materials.stiffness_scale = 0;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("stiffness_scale = 0"));
    s = reduced_case(30);
    s.wall_limit = 3600;  // without a checkpoint to resume from, the session's work would be lost at the limit
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("wall_limit = 3600") &&
                                       Catch::Matchers::Contains("checkpoint"));
    // held-back suite: a friction coefficient of 10, a stiffening by 100
    s = reduced_case(30);
    s.materials.wheat_steel.friction = 10;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("friction = 10") && Catch::Matchers::Contains("[0, 2]"));
    s.materials.wheat_steel.friction = 2;  // the bound itself is taken
    CHECK_NOTHROW(validate(s));
    s.materials.stiffness_scale = 1.5;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("stiffness_scale = 1.5"));
    // a stop fraction leaves at least 10 grains in the rate's window (20-80 % of the discharged mass)
    s = reduced_case(30);
    s.stop_fraction = 10.0 / (0.6 * double(s.particles)) * 0.99;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("stop_fraction = ") &&
                                       Catch::Matchers::Contains("at least 10 are needed"));
    s.stop_fraction = 10.0 / (0.6 * double(s.particles)) * 1.01;
    CHECK_NOTHROW(validate(s));
}

TEST_CASE("silo case: a bed that cannot fit the silo is refused, a full silo is not", "[silo]") {
    SiloCaseSettings s;  // the seed's 105 mm silo, 0.4 m body
    s.geometry = SiloGeometry::conical(30);
    s.particles = 5'000'000;  // 36 times the silo's volume of grains: it passed the check
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("particles = 5e+06") &&
                                       Catch::Matchers::Contains("the bed does not fit the silo"));
    // the silo filled to its top at the solid fraction of a random bed (0.6): accepted
    const double grain_volume = wheat_grain_volume();
    s.particles = static_cast<long>(0.6 * s.geometry.volume() / grain_volume);
    CHECK_NOTHROW(validate(s));
    // by mass: the same rule, the field named as given
    s.particles = 50000;
    s.fill_mass = 0.8 * s.geometry.volume() * s.materials.wheat.density;
    CHECK_THROWS_WITH(validate(s), Catch::Matchers::Contains("fill_mass = ") &&
                                       Catch::Matchers::Contains("does not fit"));
    // a taller body takes it
    s.geometry.body_height = 0.6;
    CHECK_NOTHROW(validate(s));
}

TEST_CASE("silo case: a small rectangular hopper fills without losing grains and discharges", "[silo]") {
    SiloCaseSettings s = small_rectangular_case();
    std::vector<SiloProgress> reports;
    const auto r = run_silo_case(s, [&](const SiloProgress& p) { reports.push_back(p); });
    CHECK(r.grains == 600);
    // the progress reports measure the cost of the steps since the previous one, and estimate the time left
    int costed = 0, estimated = 0;
    for (const auto& p : reports) {
        costed += p.step_ms > 0 && p.cores_busy > 0;
        estimated += p.remaining_wall_s > 0;
        if (p.phase != "discharge") CHECK(p.remaining_wall_s == 0);
    }
    CHECK(costed >= 2);
    CHECK(estimated >= 1);
    CHECK(r.cpu_s > 0);
    CHECK(r.cpu_sessions == 1);
    CHECK(r.fill_at_rest);
    CHECK(r.grains_in_silo + r.grains_discharged == 600);
    CHECK(r.grains_discharged > 100);
    // every grain stayed inside the box during the filling: the bed is below the body's top and inside its walls
    CHECK(r.fill_height < s.geometry.top());
}

TEST_CASE("silo case: the same seed and thread count give the same discharge", "[silo]") {
    SiloCaseSettings s = reduced_case(45);
    s.particles = 300;
    s.fill_time_max = 0.3;
    s.max_time = 0.1;
    const auto a = run_silo_case(s), b = run_silo_case(s);
    REQUIRE(a.discharge.size() == b.discharge.size());
    for (size_t i = 0; i < a.discharge.size(); ++i) CHECK(a.discharge[i].mass == b.discharge[i].mass);
    CHECK(a.fill_kinetic_energy == b.fill_kinetic_energy);
}

// Regression reference: the numbers below are what commit 177686b computed for this case (built for x86-64 without
// AVX2, GCC 12, Debian 12); the rate since 2026-12-04 (a removal takes its bodies' contacts out of their neighbours'
// loads instead of evaluating every force again: remove_bodies_if), 0x1.204c198b545f8p-2 before. The kernel's results must not depend on the instruction set the build chose (CMakeLists.txt
// enables AVX2 without FMA where the building machine has it) nor change silently: when a change alters the
// arithmetic on purpose, run this case, put the new numbers here and say so in the commit message.
TEST_CASE("silo case: the small rectangular case computes the committed reference bits", "[silo]") {
    const SiloCaseSettings s = small_rectangular_case();
    const auto r = run_silo_case(s);
    INFO(std::hexfloat << "fill kinetic energy " << r.fill_kinetic_energy << ", rate " << r.fit.rate
                       << ", discharged " << std::defaultfloat << r.grains_discharged << " grains");
    CHECK(r.grains_discharged == 600);
    CHECK(r.fill_kinetic_energy == 0x1.dfb1a8b3d2fb8p-30);
    CHECK(r.fit.rate == 0x1.236006fe329e4p-2);
}

namespace {
struct SimulatedCrash {};
}  // namespace

TEST_CASE("silo case: a run killed at a checkpoint and resumed gives the uninterrupted result bit for bit",
          "[silo][checkpoint]") {
    SiloCaseSettings s = small_rectangular_case();
    const SiloCaseResult whole = run_silo_case(s);
    REQUIRE(whole.flow.frames > 0);

    const auto dir = std::filesystem::temp_directory_path() / ("demcal-test-checkpoint-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    s.checkpoint_file = (dir / "checkpoint.bin").string();
    s.checkpoint_interval = 0;  // after every record interval
    // first session: dies at the 5th checkpoint, still filling
    long seen = 0;
    CHECK_THROWS_AS(run_silo_case(s,
                                  [&](const SiloProgress& p) {
                                      if (p.phase == "checkpoint" && ++seen == 5) throw SimulatedCrash{};
                                  }),
                    SimulatedCrash);
    CHECK(read_checkpoint_settings(s.checkpoint_file).particles == 600);
    // second session, two threads: dies at the first checkpoint 0.1 s after the opening
    CHECK_THROWS_AS(resume_silo_case(s.checkpoint_file, {.threads = 2, .checkpoint_interval = 0, .wall_limit = 0, .stop_request = {}},
                                     [&](const SiloProgress& p) {
                                         if (p.phase == "checkpoint" && p.discharge_time > 0.1) throw SimulatedCrash{};
                                     }),
                    SimulatedCrash);
    // third session: stops itself at its wall limit (reached within the first record interval), checkpoint written
    long steps_reported = 0;
    const SiloCaseResult suspended =
        resume_silo_case(s.checkpoint_file, {.threads = 1, .checkpoint_interval = 1e6, .wall_limit = 1e-6, .stop_request = {}},
                         [&](const SiloProgress& p) { steps_reported = p.step; });
    CHECK(suspended.suspended());
    CHECK(suspended.steps == steps_reported);
    CHECK(suspended.steps < whole.steps);
    CHECK_THAT(suspended.stop_reason, Catch::Matchers::Contains("wall limit"));
    CHECK(std::filesystem::exists(s.checkpoint_file));
    {  // the same checkpoint with bytes appended (not covered by its checksums) is refused before any step
        const auto appended = dir / "appended.bin";
        std::filesystem::copy_file(s.checkpoint_file, appended);
        std::ofstream(appended, std::ios::app | std::ios::binary) << "garbage";
        CHECK_THROWS_WITH(resume_silo_case(appended.string(), {.threads = 1, .checkpoint_interval = 900, .wall_limit = 0, .stop_request = {}}),
                          Catch::Matchers::Contains("appended.bin") && Catch::Matchers::Contains("bytes after its end"));
    }
    // fourth session: to the end
    const SiloCaseResult resumed = resume_silo_case(s.checkpoint_file, {.threads = 1, .checkpoint_interval = 0, .wall_limit = 0, .stop_request = {}});
    CHECK_FALSE(resumed.suspended());
    CHECK(resumed.sessions == 4);
    CHECK(resumed.cpu_sessions == 4);
    CHECK(resumed.cpu_s > 0);
    CHECK(resumed.checkpoints > 10);
    REQUIRE(resumed.discharge.size() == whole.discharge.size());
    bool same_record = true;
    for (size_t i = 0; i < whole.discharge.size(); ++i)
        same_record = same_record && resumed.discharge[i].time == whole.discharge[i].time &&
                      resumed.discharge[i].mass == whole.discharge[i].mass &&
                      resumed.discharge[i].grains == whole.discharge[i].grains;
    CHECK(same_record);
    CHECK(resumed.steps == whole.steps);
    CHECK(resumed.fill_steps == whole.fill_steps);
    CHECK(resumed.fill_kinetic_energy == whole.fill_kinetic_energy);
    CHECK(resumed.fit.rate == whole.fit.rate);
    CHECK(resumed.flow.ratio == whole.flow.ratio);
    CHECK(resumed.flow.frames == whole.flow.frames);
    REQUIRE(resumed.section->frames() == whole.section->frames());
    bool same_section = true;
    for (int i = 0; i < whole.section->nx(); ++i)
        for (int k = 0; k < whole.section->nz(); ++k) {
            const double a = whole.section->vz(i, k), b = resumed.section->vz(i, k);
            same_section = same_section && (a == b || (std::isnan(a) && std::isnan(b)));
        }
    CHECK(same_section);

    SECTION("a file that is not a checkpoint is refused, naming it") {
        const auto bad = dir / "not-a-checkpoint.bin";
        std::ofstream(bad) << "hello";
        CHECK_THROWS_WITH(resume_silo_case(bad.string(), {}), Catch::Matchers::Contains("not-a-checkpoint.bin"));
        CHECK_THROWS_WITH(read_checkpoint_settings((dir / "missing.bin").string()),
                          Catch::Matchers::Contains("missing.bin"));
    }
    std::filesystem::remove_all(dir);
}

TEST_CASE("silo case: a stop within a record interval ends the session after its step, and the run resumes bit for bit",
          "[silo][checkpoint]") {
    // A stop (SIGTERM, Ctrl-C, the wall limit) used to wait for the end of the 2 ms record interval: millions of steps
    // for a large bed. Now it comes after the step it is asked at; the checkpoint keeps the steps left of the interval
    // and a kernel state that owes the next step's half kick.
    SiloCaseSettings s = small_rectangular_case();
    const SiloCaseResult whole = run_silo_case(s);
    const long interval_steps = std::lround(s.record_interval / whole.time_step);
    REQUIRE(interval_steps > 20);
    const auto dir = std::filesystem::temp_directory_path() / ("demcal-test-midstop-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    s.checkpoint_file = (dir / "checkpoint.bin").string();
    s.checkpoint_interval = 1e6;  // only the stops write checkpoints
    // first session: asked to stop at its 1000th question, while filling
    long asked = 0;
    s.stop_request = [&asked] { return ++asked == 1000 ? std::string("test stop") : std::string(); };
    const SiloCaseResult first = run_silo_case(s);
    CHECK(first.suspended());
    CHECK(first.stop_reason == "test stop");
    CHECK(first.steps % interval_steps != 0);  // within an interval
    CHECK(first.steps < whole.fill_steps);
    // second session: asked to stop a few steps after the discharge began (progress reports mark it)
    bool discharging = false;
    long asked_in_discharge = 0;
    const SiloCaseResult second = resume_silo_case(
        s.checkpoint_file,
        {.threads = 2, .checkpoint_interval = 1e6, .wall_limit = 0,
         .stop_request = [&] { return discharging && ++asked_in_discharge == 7 ? std::string("stop 2") : std::string(); }},
        [&](const SiloProgress& p) { discharging = discharging || p.phase == "filled"; });
    CHECK(second.suspended());
    CHECK(second.stop_reason == "stop 2");
    CHECK(second.steps > whole.fill_steps);
    CHECK(second.steps % interval_steps != 0);
    // third session: to the end, the uninterrupted run's result to the last bit
    const SiloCaseResult resumed =
        resume_silo_case(s.checkpoint_file, {.threads = 1, .checkpoint_interval = 1e6, .wall_limit = 0, .stop_request = {}});
    CHECK_FALSE(resumed.suspended());
    CHECK(resumed.sessions == 3);
    CHECK(resumed.steps == whole.steps);
    CHECK(resumed.fill_steps == whole.fill_steps);
    CHECK(resumed.fill_kinetic_energy == whole.fill_kinetic_energy);
    CHECK(demcal::test::same_discharge(resumed, whole));
    CHECK(resumed.fit.rate == whole.fit.rate);
    CHECK(resumed.flow.ratio == whole.flow.ratio);
    std::filesystem::remove_all(dir);
}

TEST_CASE("silo case: a checkpoint that cannot be written is reported and the run goes on", "[silo][checkpoint]") {
    SiloCaseSettings s = reduced_case(45);
    s.particles = 300;
    s.fill_time_max = 0.3;
    s.max_time = 0.1;
    s.checkpoint_file = "/nonexistent-demcal-dir/checkpoint.bin";
    s.checkpoint_interval = 0;
    long failures = 0;
    const SiloCaseResult r = run_silo_case(s, [&](const SiloProgress& p) {
        if (p.phase == "checkpoint" && p.note.find("NOT written") != std::string::npos &&
            p.note.find("/nonexistent-demcal-dir/checkpoint.bin") != std::string::npos)
            ++failures;
    });
    CHECK(failures > 10);
    CHECK(r.checkpoints == 0);
    CHECK(r.grains_discharged > 0);
}
