// Shared by the silo case's checkpoint tests: a run killed at checkpoints (first while it fills, then after the
// opening) and resumed gives the uninterrupted run's result bit for bit, whatever the settings exercise (a still or
// vibrating bin, a cohesive material).
#pragma once
#include "kernel/silo/silo_case.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace demcal::test {

inline bool same_discharge(const kernel::silo::SiloCaseResult& a, const kernel::silo::SiloCaseResult& b) {
    if (a.discharge.size() != b.discharge.size()) return false;
    for (size_t i = 0; i < a.discharge.size(); ++i)
        if (a.discharge[i].time != b.discharge[i].time || a.discharge[i].mass != b.discharge[i].mass ||
            a.discharge[i].grains != b.discharge[i].grains)
            return false;
    return true;
}

// A switch that acts at the opening (and only then): the same filling as without it, another discharge.
inline void check_same_fill_other_discharge(const kernel::silo::SiloCaseResult& switched,
                                            const kernel::silo::SiloCaseResult& plain) {
    CHECK(switched.fill_steps == plain.fill_steps);
    CHECK(switched.fill_kinetic_energy == plain.fill_kinetic_energy);
    CHECK(switched.filled_mass == plain.filled_mass);
    CHECK_FALSE(same_discharge(switched, plain));
}

// `s` runs as it is and with `discharge_switch` applied to it (a switch that acts from the opening on): the same
// filling, another discharge, both rates fitted and within `margin` of each other (a change of the discharge's
// numerics or walls, not of its physics: the tiny silo's single runs scatter by about 10 %).
template <class Switch>
void check_discharge_switch_keeps_rate(kernel::silo::SiloCaseSettings s, Switch discharge_switch, double margin) {
    const kernel::silo::SiloCaseResult plain = kernel::silo::run_silo_case(s);
    discharge_switch(s);
    const kernel::silo::SiloCaseResult switched = kernel::silo::run_silo_case(s);
    check_same_fill_other_discharge(switched, plain);
    REQUIRE(switched.fit.ok);
    REQUIRE(plain.fit.ok);
    INFO("rate switched " << switched.fit.rate << " kg/s, plain " << plain.fit.rate << " kg/s");
    CHECK(switched.fit.rate / plain.fit.rate == Approx(1.0).margin(margin));
}

// `s` runs whole, then again killed at its 5th checkpoint (while filling, with checkpoints after every record
// interval) and, resumed on another thread count, stopped within a record interval once the discharge passed
// `second_kill_after` s; the third session finishes. Returns the checkpoint's stored settings for the caller's own checks.
inline kernel::silo::SiloCaseSettings check_resumes_bit_for_bit(kernel::silo::SiloCaseSettings s, const std::string& tag,
                                                                double second_kill_after) {
    using namespace kernel::silo;
    struct SimulatedCrash {};
    const SiloCaseResult whole = run_silo_case(s);
    const auto dir = std::filesystem::temp_directory_path() / ("demcal-test-" + tag + "-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    s.checkpoint_file = (dir / "checkpoint.bin").string();
    s.checkpoint_interval = 0;  // after every record interval
    long seen = 0;
    bool opened = false;  // the first kill must come while filling: the resumed session then opens the outlet itself
    CHECK_THROWS_AS(run_silo_case(s,
                                  [&](const SiloProgress& p) {
                                      opened = opened || p.phase == "discharge";
                                      if (p.phase == "checkpoint" && ++seen == 5) throw SimulatedCrash{};
                                  }),
                    SimulatedCrash);
    CHECK_FALSE(opened);
    const SiloCaseSettings stored = read_checkpoint_settings(s.checkpoint_file);
    // the second session is stopped (as by SIGTERM) 7 steps after the discharge passed `second_kill_after`: within a
    // record interval, its kernel state between two steps
    bool past = false;
    long asked_after = 0;
    const SiloCaseResult second = resume_silo_case(
        s.checkpoint_file,
        {.threads = 2, .checkpoint_interval = 0, .wall_limit = 0,
         .stop_request = [&] { return past && ++asked_after == 7 ? std::string("test stop") : std::string(); }},
        [&](const SiloProgress& p) { past = past || p.discharge_time > second_kill_after; });
    CHECK(second.suspended());
    CHECK(second.stop_reason == "test stop");
    CHECK(second.steps % std::lround(s.record_interval / whole.time_step) != 0);
    const SiloCaseResult resumed = resume_silo_case(s.checkpoint_file, {.threads = 1, .checkpoint_interval = 0, .wall_limit = 0, .stop_request = {}});
    CHECK(resumed.sessions == 3);
    CHECK(resumed.fill_steps == whole.fill_steps);
    CHECK(resumed.fill_kinetic_energy == whole.fill_kinetic_energy);
    CHECK(same_discharge(resumed, whole));
    CHECK(resumed.steps == whole.steps);
    CHECK(resumed.fit.rate == whole.fit.rate);
    CHECK(resumed.flow.ratio == whole.flow.ratio);
    CHECK(resumed.outlet.frames == whole.outlet.frames);
    CHECK(resumed.outlet.solid_density == whole.outlet.solid_density);
    CHECK(resumed.outlet.downward_speed == whole.outlet.downward_speed);
    CHECK(resumed.contact_law == whole.contact_law);
    std::filesystem::remove_all(dir);
    return stored;
}

}  // namespace demcal::test
