// The seed's silo case (section 2.3.2) on demcal's DEM kernel: random generation of wheat grains in the silo, filling
// under gravity against a closed outlet plate until the grains are at rest, opening, discharge until empty; the
// discharged mass against time, the rate from its steady part, the flow pattern and the mid-plane velocity section.
#pragma once
#include "kernel/silo/bin_vibration.hpp"
#include "kernel/silo/discharge_end.hpp"
#include "kernel/silo/discharge_fit.hpp"
#include "kernel/silo/flow_pattern.hpp"
#include "kernel/silo/outlet_flow.hpp"
#include "kernel/silo/section_field.hpp"
#include "kernel/silo/silo_geometry.hpp"
#include "kernel/silo/silo_output.hpp"
#include "kernel/silo/wheat.hpp"
#include "kernel/clump.hpp"
#include "kernel/clump_rotation_scheme.hpp"
#include "kernel/walls.hpp"

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace demcal::kernel::silo {

// One grain of the filled bed as the kernel holds it: the clump's centre of mass and the orientation of its
// principal frame (the frame of ClumpTemplate::offsets and ::inertia), on-step velocities, world frame.
struct BedGrain {
    Eigen::Vector3d position;          // centre of mass [m]
    Eigen::Quaterniond orientation;    // principal frame -> world
    Eigen::Vector3d velocity;          // [m/s]
    Eigen::Vector3d angular_velocity;  // [rad/s]
    std::vector<Eigen::Vector3d> spheres;  // the centres of its spheres as the kernel placed them [m] (any order)
};

// The bed at a moment of the run: what another code needs to go on from there. At the opening, before the first
// discharge step, to discharge the same bed (demcal silo --export-bed); at the generation, before the first filling
// step, to fill the same cloud of grains on its own (demcal silo --export-cloud).
struct BedSnapshot {
    double time = 0;       // simulated time of the moment [s]
    double time_step = 0;  // [s]
    double wall_top = 0;   // the body wall's top [m]: above the silo's top when the generation column was taller
    double rest_energy = 0;  // the filling's rest criterion: mean kinetic energy per grain below this [J]
    ClumpTemplate grain;   // mass, principal inertia, member offsets (principal frame) and radii
    std::vector<BedGrain> grains;
};

// What the contacts keep of their past when the outlet opens. forget_history: every contact restarts as if just
// formed (its tangential spring at zero), as a bed imported into a code without the kernel's contact history does
// (YADE's silo.py creates its interactions afresh): the cross-check's switch for that one difference. yade_import:
// that, and the discharge goes on as YADE's run of the exported bed starts (BasicSimulation::
// restart_as_imported_leapfrog: the first force evaluation advances the fresh springs by a step, the first kick is a
// whole step): with YADE's law, rotation and facet walls both codes then follow one trajectory until chaos parts them.
enum class ContactsAtOpening : std::uint8_t { keep_history = 0, forget_history = 1, yade_import = 2 };

// The contact law family the grains run on. edem: the kernel's own (Hertz-Mindlin with a total-displacement
// tangential spring and EDEM's rolling friction; JKR when a pair is cohesive). yade: YADE 2023.02a's Hertz-Mindlin as
// yade_scripts/silo.py runs it (incremental tangential force, normal force clipped at zero, no rolling resistance;
// kernel/contact/yade_mindlin_*.hpp), so that a cross-check can run one law in both codes. It has no cohesion and no
// rolling friction: materials with either are refused.
enum class SiloContactLaw : std::uint8_t { edem = 0, yade = 1 };

// The laws by the names the command line, summary.json and the cross-check use ("edem", "yade"): declared once here.
const std::map<std::string, SiloContactLaw>& silo_contact_laws();

// How the clumps turn in the discharge, by name ("richardson": the kernel's own; "yade": YADE 2023.02a's aspherical
// leapfrog, kernel/clump_rotation_yade.hpp). The filling always runs the kernel's own, so that the bed at the opening
// (the one YADE imports in a cross-check) is the same whichever scheme discharges it: a paired comparison then
// measures what the integrators alone change.
const std::map<std::string, ClumpRotation>& silo_clump_rotations();
std::string silo_clump_rotation_text(ClumpRotation scheme);  // its name in silo_clump_rotations()
std::string silo_contact_law_text(SiloContactLaw law);  // its name in silo_contact_laws()

// The smallest time step a silo run takes, as a fraction of the Rayleigh step (time_step and time_step_fraction):
// smaller resolves nothing better, and the run would take up to a thousand times the steps.
inline constexpr double kMinTimeStepFraction = 1e-3;

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
    // The bin (vibration.part: every wall, or the hopper and the outlet plate) vibrates from
    // vibration.start_after_opening after the opening; still while it fills. Default: still.
    BinVibration vibration;
    ContactsAtOpening contacts_at_opening = ContactsAtOpening::keep_history;
    SiloContactLaw contact_law = SiloContactLaw::edem;
    ClumpRotation discharge_clump_rotation = ClumpRotation::richardson;  // from the opening on (see above)
    // 0: the conical silo's cone and cylinder are exact surfaces of revolution. N (12 to 2000): from the opening on
    // they are N-sided polygons of triangular facets (kernel/walls/triangle_wall.hpp, YADE's facet contact), built as
    // yade_scripts/silo.py builds its walls (silo_facet_walls); the filling always runs on the exact walls, so the
    // bed at the opening is the same either way: what a YADE run started from the kernel's bed meets.
    int discharge_wall_facets = 0;
    // Verlet skin [m]; 0: automatic, 40 dt x 1 m/s within [0.2 mm, 1 mm] (grains leave the outlet at ~1 m/s: the list
    // then lasts tens of steps; measured on the reduced 70 deg case, dt = 66 us: 1 mm ran 1.7 times faster than the
    // kernel's default 0.1 r; at the seed's dt = 2.1 us a 0.2 mm skin keeps fewer pairs in the list).
    double skin = 0;
    int threads = 1;
    unsigned long seed = 1;
    std::string vtk_dir;             // empty: no VTK
    double vtk_interval = 0.05;      // [s]
    double progress_interval = 0.05; // simulated seconds between progress reports
    // Checkpoint: every checkpoint_interval seconds of wall-clock time the whole run (the simulation, the discharge
    // record, the flow-pattern and section frames, these settings) is written to checkpoint_file (atomically: a
    // temporary file renamed over the previous one), so that resume_silo_case() continues it bit for bit after a
    // crash, a kill or the end of a session. Empty: no checkpoints. 0 s: after every record interval (tests).
    std::string checkpoint_file;
    double checkpoint_interval = 900;  // [s] wall clock
    // Wall-clock limit of this session [s] (0: none): once it is reached (asked after every step), the run
    // writes its checkpoint and returns suspended, to be resumed later (a batch system's time limit, a machine lent
    // for a few hours). Needs a checkpoint file. Not stored: each session sets its own.
    double wall_limit = 0;
    // Asked after every step, as the wall limit: a non-empty answer (why, e.g. "SIGTERM received")
    // suspends the run the same way (checkpoint written, result marked suspended). The caller's way to stop a run
    // cleanly from outside (demcal silo: SIGTERM and SIGINT). Only with a checkpoint file. Not stored.
    std::function<std::string()> stop_request;
    // Called once with the filled bed when the outlet opens (demcal silo --export-bed). Not stored: a run resumed
    // from a checkpoint written after the opening does not call it again.
    std::function<void(const BedSnapshot&)> at_opening;
    // Called once with the generated cloud before the first filling step (demcal silo --export-cloud). Not stored,
    // as at_opening.
    std::function<void(const BedSnapshot&)> at_generation;
    // Called once with the grains left when the discharge ends (emptied, stopped, time limit; not when a session is
    // suspended) (demcal silo --export-final-bed). Not stored, as at_opening.
    std::function<void(const BedSnapshot&)> at_end;
};
// A new setting that changes the run must also be listed in for_each_setting (silo_case.cpp): the checkpoint stores
// the settings through that list. threads, checkpoint_file, checkpoint_interval, wall_limit, stop_request, at_opening, at_end and
// at_generation are not stored: a resumed run takes them from its caller.

// Throws std::invalid_argument naming the field and value (geometry, counts, times, fractions, the vibration).
void validate(const SiloCaseSettings& s);
// The materials alone (part of the above), their fields named as the material file names them (grain.density_kg_m3).
void validate(const WheatMaterials& materials);

// The silo's walls of steel material `steel`, the outlet plate last; the body reaches up to `wall_top`. The walls of
// the vibrating `part` move on `bin_motion` (null: every wall still).
std::vector<Wall> silo_walls(const SiloGeometry& g, int steel, double wall_top,
                             const std::shared_ptr<const WallMotion>& bin_motion, VibratingPart part);
// The conical silo's cone and cylinder as yade_scripts/silo.py builds them from facets: `sides` facets around, each
// side of the cone (outlet to body) and of the cylinder (body to wall_top) split into two triangles, the polygons'
// vertices at the radius that puts the facets' mean distance from the axis at the wall's radius; moving as the exact
// walls they stand for (bin_motion, part).
std::vector<Wall> silo_facet_walls(const SiloGeometry& g, int steel, double wall_top, int sides,
                                   const std::shared_ptr<const WallMotion>& bin_motion, VibratingPart part);

// The Rayleigh time step of the grain's smallest sphere at the materials' (scaled) stiffness [s], and the time step a
// run of these settings plans from it (time_step, or time_step_fraction of it): what the checks of a run's settings
// and size are made against. (The run itself takes the kernel's own Rayleigh step, the same formula.)
double smallest_sphere_rayleigh_step(const WheatMaterials& m);
double planned_time_step(const SiloCaseSettings& s);

struct SiloProgress {
    std::string phase;  // "generated", "resumed", "filling", "filled", "discharge", "checkpoint", "suspended", "done"
    double time = 0;            // simulated time since the start [s]
    double discharge_time = 0;  // since the opening [s]
    long step = 0;
    long grains_in_silo = 0;
    long grains_discharged = 0;
    double discharged_mass = 0;
    double kinetic_energy_per_grain = 0;  // [J]
    double wall_s = 0;
    // Cost of the steps since the previous "filling" or "discharge" report of this session (0 when there is none):
    // wall-clock milliseconds per step, and the process's CPU time over that wall time (the cores it kept busy: below
    // the thread count when other work shared the machine or the run was paused).
    double step_ms = 0;
    double cores_busy = 0;
    // Discharge only (0 otherwise): wall-clock seconds left if the mean discharge rate so far and step_ms held to the
    // stop (empty, stop_fraction or max_time): a rough guide (the cost per step falls as the silo empties, the rate
    // falls as the last grains leave the hopper).
    double remaining_wall_s = 0;
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
    DischargeEnd end = DischargeEnd::running;  // how the discharge ended (stop_reason: the same in words)
    bool emptied() const { return end == DischargeEnd::emptied; }
    std::string stop_reason;
    std::vector<DischargeRow> discharge;  // time since the opening, mass, grains
    DischargeFit fit;
    FlowPatternResult flow;
    OutletFlowResult outlet;  // density and speed of the grains above the outlet over the steady window
    std::shared_ptr<SectionField> section;
    double wall_s = 0, fill_wall_s = 0;  // wall-clock time of the whole run (every session of it) [s]
    int sessions = 1;                    // 1 + the number of times the run was resumed from its checkpoint
    // CPU time of the process, every thread, summed over the sessions that counted it [s]: the last cpu_sessions
    // (checkpoints older than this field did not record it). Unlike wall_s it excludes the time the run was paused
    // or waited for cores other work held.
    double cpu_s = 0;
    int cpu_sessions = 0;
    // The part of cpu_s spent until the end of the filling (NaN: unknown, a run resumed in its discharge from a
    // checkpoint older than format 12): cpu_s - fill_cpu_s is the discharge's, the work a code that starts from the
    // filled bed (YADE importing it) does.
    double fill_cpu_s = 0;
    // stopped at SiloCaseSettings::wall_limit or stop_request (stop_reason says which): resume it from its checkpoint
    bool suspended() const { return end == DischargeEnd::suspended; }
    std::string contact_law;             // the law the run was on (contact_law_name)
    long checkpoints = 0;                // written over the whole run
    long vtk_files = 0;
};

// The contact law a silo runs on: with SiloContactLaw::edem Hertz-Mindlin with EDEM's rolling friction, or, when a
// pair is cohesive (WheatMaterials::cohesive), JKR with the same friction and rolling friction; with
// SiloContactLaw::yade YADE's Hertz-Mindlin (kernel/contact/contact_law.hpp).
std::string contact_law_name(const SiloCaseSettings& s);

SiloCaseResult run_silo_case(const SiloCaseSettings& s,
                             const std::function<void(const SiloProgress&)>& progress = {});

// The settings a checkpoint was written with (threads and the checkpoint options as stored defaults). Throws
// std::runtime_error naming the file when it cannot be read or is not a silo checkpoint.
SiloCaseSettings read_checkpoint_settings(const std::string& checkpoint_file);

// What a resumed session sets for itself (the rest comes from the checkpoint): see the fields of the same names in
// SiloCaseSettings.
struct SiloSession {
    int threads = 1;
    double checkpoint_interval = 900;  // [s] wall clock
    double wall_limit = 0;             // [s] wall clock of this session; 0: none
    std::function<std::string()> stop_request;  // see SiloCaseSettings::stop_request
};

// Continues the run saved in checkpoint_file (the settings stored in it), checkpointing to the same file; the result
// is the one the uninterrupted run gives, bit for bit, with the wall (and CPU) time of every session added up.
SiloCaseResult resume_silo_case(const std::string& checkpoint_file, const SiloSession& session,
                                const std::function<void(const SiloProgress&)>& progress = {});

}  // namespace demcal::kernel::silo
