// The seed's silo case (section 2.3.2) on demcal's DEM kernel: random generation of wheat grains in the silo, filling
// under gravity against a closed outlet plate until the grains are at rest, opening, discharge until empty; the
// discharged mass against time, the rate from its steady part, the flow pattern and the mid-plane velocity section.
#pragma once
#include "kernel/silo/discharge_fit.hpp"
#include "kernel/silo/flow_pattern.hpp"
#include "kernel/silo/section_field.hpp"
#include "kernel/silo/silo_geometry.hpp"
#include "kernel/silo/silo_output.hpp"
#include "kernel/silo/wheat.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace demcal::kernel::silo {

struct SiloCaseSettings {
    SiloGeometry geometry;
    WheatMaterials materials;
    long particles = 50000;          // number of grains (used when fill_mass is 0)
    double fill_mass = 0;            // [kg]; > 0: particles = round(fill_mass / grain mass)
    double gravity = 9.81;           // [m/s^2]
    double time_step = 0;            // [s]; 0: time_step_fraction x the Rayleigh step of the small sphere
    double time_step_fraction = 0.25;
    // Filling ends when the mean kinetic energy per grain (translation + rotation) is below
    // rest_energy_factor x m g d_p (1e-3: a grain moving at about 1 cm/s) after fill_time_min, or at fill_time_max.
    double fill_time_min = 0.05;     // [s]
    double fill_time_max = 2.1;      // [s] (the seed fills for 2.1 s)
    double rest_energy_factor = 1e-3;
    double max_time = 20;            // discharge time limit after opening [s]
    double stop_fraction = 1.0;      // stop once this fraction of the filled mass has left (1: empty)
    double removal_depth = 0.0055;   // a grain counts as discharged when its centre is this far below the outlet [m]
    double record_interval = 2e-3;   // discharged mass sampled every ... [s]
    double frame_interval = 5e-3;    // flow-pattern and section frames every ... [s] (steady part only)
    double steady_lower = 0.2, steady_upper = 0.8;  // the steady part: fractions of the filled mass discharged
    double section_cell = 0.0025;    // [m]
    double section_half_thickness = 0.011;  // slab |y| < 2 d_p [m]
    FlowPatternSettings flow;
    // Verlet skin [m]; 0: automatic, 40 dt x 1 m/s within [0.2 mm, 1 mm] (grains leave the outlet at ~1 m/s: the list
    // then lasts tens of steps; measured on the reduced 70 deg case, dt = 66 us: 1 mm ran 1.7 times faster than the
    // kernel's default 0.1 r; at the seed's dt = 2.1 us a 0.2 mm skin keeps fewer pairs in the list).
    double skin = 0;
    int threads = 1;
    unsigned long seed = 1;
    std::string vtk_dir;             // empty: no VTK
    double vtk_interval = 0.05;      // [s]
    double progress_interval = 0.05; // simulated seconds between progress reports
};

// Throws std::invalid_argument naming the field and value (geometry, counts, times, fractions).
void validate(const SiloCaseSettings& s);

struct SiloProgress {
    std::string phase;          // "generated", "filling", "filled", "discharge", "done"
    double time = 0;            // simulated time since the start [s]
    double discharge_time = 0;  // since the opening [s]
    long step = 0;
    long grains_in_silo = 0;
    long grains_discharged = 0;
    double discharged_mass = 0;
    double kinetic_energy_per_grain = 0;  // [J]
    double wall_s = 0;
    std::string note;
};

struct SiloCaseResult {
    long grains = 0;                   // generated
    double grain_mass = 0;             // [kg]
    double filled_mass = 0;            // [kg] in the silo when opened
    double fill_time = 0;              // [s] simulated
    bool fill_at_rest = false;         // ended by the rest criterion (false: by fill_time_max)
    double fill_kinetic_energy = 0;    // per grain at the opening [J]
    double fill_height = 0;            // highest grain centre at the opening [m]
    double bulk_density = 0;           // of the filled bed below 0.8 fill height [kg/m^3]
    double time_step = 0;
    long steps = 0;
    long fill_steps = 0;
    double discharge_time = 0;         // simulated time since the opening at the end [s]
    long grains_discharged = 0;
    long grains_in_silo = 0;           // at the end
    bool emptied = false;
    std::string stop_reason;
    std::vector<DischargeRow> discharge;  // time since the opening, mass, grains
    DischargeFit fit;
    FlowPatternResult flow;
    std::shared_ptr<SectionField> section;
    double wall_s = 0, fill_wall_s = 0;
    long vtk_files = 0;
};

SiloCaseResult run_silo_case(const SiloCaseSettings& s,
                             const std::function<void(const SiloProgress&)>& progress = {});

}  // namespace demcal::kernel::silo
