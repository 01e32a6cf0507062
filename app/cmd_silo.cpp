// demcal silo: the seed's silo case (filling, opening, discharge) on the native DEM kernel.
#include "analytics/discharge_models.hpp"
#include "analytics/number_text.hpp"  // shortened_text
#include "analytics/user_input.hpp"  // json_value_text
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/gnuplot.hpp"
#include "app/result_files.hpp"
#include "app/silo_bed_export.hpp"
#include "app/silo_campaign.hpp"  // silo_number
#include "app/silo_flow_pattern.hpp"
#include "app/silo_material.hpp"
#include "app/silo_settings.hpp"
#include "kernel/silo/input_error.hpp"  // setting_text
#include "kernel/silo/silo_case.hpp"
#include "orchestrator/folder_lock.hpp"
#include "orchestrator/run_identity.hpp"  // write_text_file_atomically
#include "orchestrator/stop_signals.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

namespace demcal {

namespace fs = std::filesystem;
namespace ks = kernel::silo;

namespace {

// a [m], the slot width of a rectangular hopper when none is given (the seed's section 2.1.2 model).
constexpr double kDefaultSlotWidth = 0.03;

struct SiloCli {
    std::string geometry_file;
    std::string material_file;
    // Geometry: a value counts only where its option was given (sub.count); otherwise the --geometry file's, then
    // the default (SiloGeometry's: the seed's silo).
    double theta = 0;
    double outlet = ks::SiloGeometry{}.outlet;
    double diameter = ks::SiloGeometry{}.diameter;
    double body_height = ks::SiloGeometry{}.body_height;
    bool rect = false;
    double a = kDefaultSlotWidth, b = ks::SiloGeometry{}.depth, c = ks::SiloGeometry{}.width;
    long particles = 50000;
    double fill_mass = 0;
    int threads = 0;
    long long seed = 1;  // signed, so that a negative seed is refused rather than wrapped
    std::string out;
    std::string vtk;
    double vtk_every = 0.05;
    double max_time = 20;
    double fill_time = 2.1;
    double dt = 0;
    double dt_fraction = 0.25;
    double stiffness_scale = 1;
    double stop_fraction = 1;
    double skin = 0;
    double vibration_frequency = 0;
    double vibration_amplitude = 0;
    std::string vibration_direction = "x";
    std::string vibration_part = "bin";
    double vibration_start = 0;
    bool no_plots = false;
    double checkpoint_every = 900;
    bool no_checkpoint = false;
    bool check_only = false;  // validate the settings, write nothing (demcal vibration checks its runs this way)
    double wall_limit = 0;
    std::string resume;
    std::string export_bed;  // the filled bed at the opening, for yade_scripts/silo.py
    std::string export_final_bed;  // the grains left when the discharge ends
    std::string export_cloud;  // the generated cloud before filling, for yade_scripts/silo.py to fill on its own
    bool forget_contact_history = false;  // at the opening, as a bed imported into YADE starts
    bool start_as_yade_import = false;    // that, and the discharge starts as YADE's run of the exported bed
    std::string contact_law = "edem";     // edem | yade (checked by the option)
    std::string discharge_rotation = "richardson";  // richardson | yade (checked by the option)
    int discharge_wall_facets = 0;                  // 0: exact walls (validate() checks the rest)
};

// Exit status of a run stopped at --wall-limit (EX_TEMPFAIL): not finished, resume it. A job script can loop on it.
constexpr int kExitSuspended = 75;

constexpr const char* kCheckpointName = "checkpoint.bin";
// Every file a run writes into its --out folder (write_outputs, the checkpoint): an exported bed must not take one.
// The session options a run was started with (--threads, --checkpoint-every, --no-plots), for its resumes: a run
// started on one thread without plots resumed on every core and drew plots (needing gnuplot) unless they were given
// again (probe 60). Options given to --resume override them.
constexpr const char* kSessionFileName = "session.json";

// The most OpenMP threads a run takes (--threads; a stored session's value is held to it too).
constexpr int kMaxThreads = 256;

constexpr const char* kRunFiles[] = {kCheckpointName,       "summary.json",         "discharge.csv",
                                     "section.png",         "discharge.png",        "section.dat",
                                     "section_outline.dat", "section.png.gp",       "section.png.gp.log",
                                     "discharge.png.gp",    "discharge.png.gp.log", kSessionFileName};

// A stop signal (orchestrator/stop_signals.hpp: SIGTERM from kill, scancel or a batch system's time limit, SIGINT from
// Ctrl-C, SIGHUP from a closed terminal or ssh session) during a checkpointed run: the run ends the step it is in,
// writes its checkpoint and exits 75, as at --wall-limit. The handler only records the signal (async-signal-safe);
// the run asks for it after every step. SA_RESETHAND: a second signal takes the default action and ends the process
// at once. A signal ignored at the start (SIGINT of a job started with `&` by a script, SIGHUP under nohup) stays
// ignored.
volatile std::sig_atomic_t g_stop_signal = 0;

void record_stop_signal(int sig) { g_stop_signal = sig; }

class StopOnSignal {
public:
    StopOnSignal() : handlers_(record_stop_signal, SA_RESETHAND) {}

    // For SiloCaseSettings::stop_request: empty until a signal came.
    static std::string reason() {
        const int sig = g_stop_signal;
        if (sig == 0) return {};
        return orchestrator::stop_signal_name(sig) + " received";
    }

private:
    orchestrator::StopSignalHandlers handlers_;
};

std::string fixed(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

// One geometry quantity as given, and where: "--theta" or "FILE: theta_deg" (for the error messages).
struct GivenValue {
    double value;
    std::string source;
    bool named_slot_width = false;  // given as a_m or --a, which only a rectangular hopper has
};

// The geometry keys of a --geometry file, the options that set the same quantity and where the option's value is;
// a_m and --a are the rectangular slot width, which outlet_m / --outlet also set.
struct GeometryKey {
    const char* file_key;
    const char* option;
    double SiloCli::*value;
};
constexpr GeometryKey kGeometryKeys[] = {
    {"theta_deg", "--theta", &SiloCli::theta},       {"outlet_m", "--outlet", &SiloCli::outlet},
    {"D_m", "--diameter", &SiloCli::diameter},       {"body_height_m", "--body-height", &SiloCli::body_height},
    {"a_m", "--a", &SiloCli::a},                     {"b_m", "--b", &SiloCli::b},
    {"c_m", "--c", &SiloCli::c}};

// The geometry given at one level (the file, or the command line), by file key; the slot width under "outlet_m".
struct GeometryGiven {
    std::optional<bool> rect;
    std::string rect_source;
    std::map<std::string, GivenValue> values;

    // outlet_m and a_m name one quantity: both at one level is a contradiction, not a precedence.
    void merge_slot_width() {
        const auto a = values.find("a_m");
        if (a == values.end()) return;
        if (const auto d = values.find("outlet_m"); d != values.end())
            throw UserError(d->second.source + " and " + a->second.source +
                            " both set the outlet (slot) width; give one");
        GivenValue slot = a->second;
        slot.named_slot_width = true;
        values.emplace("outlet_m", slot);
        values.erase("a_m");
    }
};

GeometryGiven read_geometry_file(const std::string& file) {
    const nlohmann::json j = read_json_file(file, "geometry");
    if (!j.is_object()) throw UserError("--geometry = '" + file + "': must be a JSON object");
    GeometryGiven g;
    for (const auto& [key, value] : j.items()) {
        if (key.rfind("_", 0) == 0) continue;  // keys starting with '_' are comments
        if (key == "shape") {
            if (!value.is_string() || (value != "conical" && value != "rectangular"))
                throw UserError(file + ": shape = " + analytics::json_value_text(value) + ": must be \"conical\" or \"rectangular\"");
            g.rect = value == "rectangular";
            g.rect_source = file + ": shape";
            continue;
        }
        const bool known = std::any_of(std::begin(kGeometryKeys), std::end(kGeometryKeys),
                                       [&](const GeometryKey& k) { return key == k.file_key; });
        if (!known)
            throw UserError("--geometry = '" + analytics::shortened_text(file, 200) + "': unknown key '" +
                            analytics::shortened_text(key) +
                            "' (known: shape, theta_deg, outlet_m, D_m, body_height_m, a_m, b_m, c_m)");
        if (!value.is_number()) throw UserError(file + ": " + key + " = " + analytics::json_value_text(value) + ": must be a number");
        g.values[key] = {value.get<double>(), file + ": " + key};
    }
    return g;
}

GeometryGiven geometry_options(const SiloCli& o, CLI::App& sub) {
    GeometryGiven g;
    if (sub.count("--rect")) {
        g.rect = true;
        g.rect_source = "--rect";
    }
    for (const GeometryKey& k : kGeometryKeys)
        if (sub.count(k.option)) g.values[k.file_key] = {o.*k.value, k.option};
    return g;
}

// The kernel's name of each geometry quantity (in its refusals, ks::SettingRejected::field) and the file key that
// gives it: a refusal then names the quantity as the user gave it ("geo.json: D_m = -1", "--diameter = -1").
constexpr std::pair<const char*, const char*> kGeometryFieldKeys[] = {
    {"theta", "theta_deg"},     {"outlet", "outlet_m"}, {"a (outlet width)", "outlet_m"}, {"diameter", "D_m"},
    {"body_height", "body_height_m"}, {"b (depth)", "b_m"}, {"c (width)", "c_m"}};

// The kernel's name of each setting an option sets (ks::SettingRejected::field): a refusal of a setting given on the
// command line names the option typed ("--max-time = -1: must be > 0 s"), one of a setting not given keeps the
// kernel's name (a default, or a resumed run's stored value).
constexpr std::pair<const char*, const char*> kSettingOptions[] = {
    {"particles", "--particles"},
    {"fill_mass", "--fill-mass"},
    {"threads", "--threads"},
    {"max_time", "--max-time"},
    {"fill_time", "--fill-time"},
    {"dt", "--dt"},
    {"dt_fraction", "--dt-fraction"},
    {"stiffness_scale", "--stiffness-scale"},
    {"stop_fraction", "--stop-fraction"},
    {"skin", "--skin"},
    {"vtk_every", "--vtk-every"},
    {"vibration_frequency", "--vibration-frequency"},
    {"vibration_amplitude", "--vibration-amplitude"},
    {"vibration_direction", "--vibration-direction"},
    {"vibration_part", "--vibration-part"},
    {"vibration_start", "--vibration-start"},
    {"discharge_wall_facets", "--discharge-wall-facets"},
    {"checkpoint_interval", "--checkpoint-every"},
    {"wall_limit", "--wall-limit"}};

// The command line over the --geometry file over the defaults; a quantity that does not belong to the shape is
// refused wherever it was given. `sources`: where each quantity given came from, by the kernel's field name.
ks::SiloGeometry geometry_from(const SiloCli& o, CLI::App& sub, std::map<std::string, std::string>& sources) {
    GeometryGiven given = o.geometry_file.empty() ? GeometryGiven{} : read_geometry_file(o.geometry_file);
    GeometryGiven cli = geometry_options(o, sub);
    given.merge_slot_width();
    cli.merge_slot_width();
    if (cli.rect) {
        // a file of a conical silo under --rect: its diameter was dropped and its circular outlet taken for a slot
        if (given.rect.has_value() && !*given.rect)
            throw UserError("--rect: the --geometry file is a conical silo (" + given.rect_source +
                            " = \"conical\"); give a rectangular geometry file, or leave --rect out");
        if (const auto d = given.values.find("D_m"); d != given.values.end())
            throw UserError("--rect: the --geometry file gives the diameter of a conical silo (" + d->second.source +
                            "); give a rectangular geometry file, or leave --rect out");
        given.rect = cli.rect;
        given.rect_source = cli.rect_source;
    }
    for (auto& [key, v] : cli.values) given.values.insert_or_assign(key, v);
    for (const auto& [field, key] : kGeometryFieldKeys)
        if (const auto it = given.values.find(key); it != given.values.end()) sources[field] = it->second.source;
    const bool rect = given.rect.value_or(false);
    const auto value = [&](const char* key) -> std::optional<double> {
        const auto it = given.values.find(key);
        return it == given.values.end() ? std::nullopt : std::optional<double>(it->second.value);
    };
    const auto refuse_if_given = [&](const char* key, const std::string& why) {
        if (const auto it = given.values.find(key); it != given.values.end())
            throw UserError(it->second.source + " = " + ks::setting_text(it->second.value) + ": " + why);
    };
    const auto theta = value("theta_deg");
    if (!theta) throw UserError("--theta: missing; give --theta DEG (or theta_deg in --geometry)");
    const ks::SiloGeometry seed_silo;
    if (rect) {
        refuse_if_given("D_m", "the diameter applies to the conical silo, not to a rectangular one (" +
                                   given.rect_source + ")");
        return ks::SiloGeometry::rectangular(*theta, value("outlet_m").value_or(kDefaultSlotWidth),
                                             value("b_m").value_or(seed_silo.depth),
                                             value("c_m").value_or(seed_silo.width),
                                             value("body_height_m").value_or(seed_silo.body_height));
    }
    const std::string add_rect = "applies to a rectangular hopper (add --rect, or \"shape\": \"rectangular\")";
    refuse_if_given("b_m", add_rect);
    refuse_if_given("c_m", add_rect);
    if (const auto it = given.values.find("outlet_m"); it != given.values.end() && it->second.named_slot_width)
        refuse_if_given("outlet_m", add_rect);
    return ks::SiloGeometry::conical(*theta, value("outlet_m").value_or(seed_silo.outlet),
                                     value("D_m").value_or(seed_silo.diameter),
                                     value("body_height_m").value_or(seed_silo.body_height));
}

// --threads, or every core when not given.
int thread_count(const SiloCli& o) {
    return o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));
}

// The options that shape a session rather than the run (also with --resume): checked before anything is written.
void check_session_options(const SiloCli& o, CLI::App& sub) {
    if (sub.count("--threads") && o.threads < 1)
        throw UserError("--threads = " + std::to_string(o.threads) + ": must be at least 1");
    if (!(o.checkpoint_every > 0) || !std::isfinite(o.checkpoint_every))
        throw UserError("checkpoint-every = " + ks::setting_text(o.checkpoint_every) +
                        ": must be a positive number of seconds");
    if (!(o.wall_limit >= 0) || !std::isfinite(o.wall_limit))
        throw UserError("wall-limit = " + ks::setting_text(o.wall_limit) +
                        ": must be a number of seconds >= 0 (0: none)");
}

// --vibration-frequency and --vibration-amplitude go together; --vibration-direction, --vibration-part and
// --vibration-start only with them. The ranges are checked with the other settings (ks::validate).
ks::BinVibration vibration_from(const SiloCli& o, CLI::App& sub) {
    const bool frequency = sub.count("--vibration-frequency") > 0, amplitude = sub.count("--vibration-amplitude") > 0;
    if (frequency != amplitude)
        throw UserError(frequency ? "--vibration-frequency " + ks::setting_text(o.vibration_frequency) +
                                        " needs --vibration-amplitude M (the bin's displacement amplitude)"
                                  : "--vibration-amplitude " + ks::setting_text(o.vibration_amplitude) +
                                        " needs --vibration-frequency HZ");
    if (!frequency) {
        for (const char* option : {"--vibration-direction", "--vibration-part", "--vibration-start"})
            if (sub.count(option))
                throw UserError(std::string(option) +
                                " applies to a vibrating bin: add --vibration-frequency and --vibration-amplitude");
        return {};
    }
    if (o.vibration_frequency == 0)  // a still bin: the amplitude was recorded in the summary and did nothing
        throw UserError("--vibration-frequency 0 is a still bin: --vibration-amplitude and the other --vibration "
                        "options do nothing; leave them out, or give a frequency above 0");
    if (o.vibration_amplitude == 0)  // the same still bin, reported as vibrating with its part and start
        throw UserError("--vibration-amplitude 0 is a still bin: --vibration-frequency and the other --vibration "
                        "options do nothing; leave them out, or give an amplitude above 0");
    ks::BinVibration v;
    v.frequency = o.vibration_frequency;
    v.amplitude = o.vibration_amplitude;
    v.start_after_opening = o.vibration_start;
    if (o.vibration_direction == "x") v.direction = ks::VibrationDirection::x;
    else if (o.vibration_direction == "z") v.direction = ks::VibrationDirection::z;
    else
        throw UserError("vibration-direction = '" + o.vibration_direction +
                        "': must be x (perpendicular to the silo axis) or z (along it)");
    const auto part = ks::vibrating_part_named(o.vibration_part);
    if (!part)
        throw UserError("vibration-part = '" + o.vibration_part.substr(0, 40) +
                        "': must be bin (every wall) or hopper (the hopper and the outlet plate; the body still)");
    v.part = *part;
    return v;
}

// "100 Hz, 0.11 mm along x (perpendicular to the axis), ...: peak acceleration 4.4 g"; empty when still.
std::string vibration_text(const ks::SiloCaseSettings& s) {
    const ks::BinVibration& v = s.vibration;
    if (!v.vibrates()) return {};
    return ks::setting_text(v.frequency) + " Hz, " + ks::setting_text(v.amplitude * 1e3) + " mm along " +
           ks::to_string(v.direction) +
           (v.direction == ks::VibrationDirection::x ? " (perpendicular to the axis)" : " (along the axis)") +
           (v.part == ks::VibratingPart::bin ? ", the whole bin from " : ", the hopper alone from ") +
           ks::setting_text(v.start_after_opening) +
           " s after the opening (still while filling): peak acceleration " +
           ks::setting_text(v.peak_acceleration() / s.gravity) + " g";
}

// Most time steps and VTK snapshots one run may take: 1e9 steps is about 300 times the seed's full 20 s discharge
// (3.5e6 steps) and days of CPU even for a few hundred grains; 1e5 snapshots fill a disk. A smaller --dt or
// --dt-fraction (1e-300 passed every range and the clock never visibly advanced) or --vtk-every is refused here, with
// the count it would give, before anything is written.
constexpr double kMaxSiloSteps = 1e9;
constexpr double kMaxVtkSnapshots = 1e5;

void check_run_size(const ks::SiloCaseSettings& s) {
    const double dt = ks::planned_time_step(s);
    const double simulated = s.fill_time_max + s.max_time;
    const double steps = simulated / dt;
    // (1e-9 s ran no step of the discharge and ended "not determined" with exit 0)
    for (const auto& [option, t] : {std::pair<const char*, double>{"--max-time", s.max_time},
                                    std::pair<const char*, double>{"--fill-time", s.fill_time_max}})
        if (t < dt)
            throw UserError(std::string(option) + " " + ks::setting_text(t) + " s is shorter than one time step (" +
                            ks::setting_text(dt) + " s): nothing of it would be simulated");
    if (!(steps <= kMaxSiloSteps)) {
        const std::string given = s.time_step > 0 ? "--dt " + ks::setting_text(s.time_step) + " s"
                                                  : "--dt-fraction " + ks::setting_text(s.time_step_fraction) +
                                                        " (a time step of " + ks::setting_text(dt) + " s)";
        throw UserError(given + " over --fill-time " + ks::setting_text(s.fill_time_max) + " s + --max-time " +
                        ks::setting_text(s.max_time) + " s: " + ks::setting_text(steps) + " time steps, more than " +
                        ks::setting_text(kMaxSiloSteps) + "; the run would not end");
    }
    if (!s.vtk_dir.empty() && !(simulated / s.vtk_interval <= kMaxVtkSnapshots))
        throw UserError("--vtk-every " + ks::setting_text(s.vtk_interval) + " s: " +
                        ks::setting_text(simulated / s.vtk_interval) + " snapshots, more than " +
                        ks::setting_text(kMaxVtkSnapshots));
}

ks::SiloCaseSettings settings_from(const SiloCli& o, CLI::App& sub) {
    check_session_options(o, sub);
    ks::SiloCaseSettings s;
    std::map<std::string, std::string> sources;  // where each setting given came from, by the kernel's field name
    s.geometry = geometry_from(o, sub, sources);
    if (sub.count("--particles") && sub.count("--fill-mass"))
        throw UserError("--particles and --fill-mass both set the amount of grain; give one");
    // 0 is the setting's "not given": given on the command line it must be a real amount, not the default's signal
    if (sub.count("--fill-mass") && !(o.fill_mass > 0))
        throw UserError("--fill-mass = " + ks::setting_text(o.fill_mass) + ": must be > 0 kg (or give --particles)");
    if (sub.count("--vtk-every") && o.vtk.empty())
        throw UserError("--vtk-every applies to the VTK snapshots: add --vtk DIR");
    if (o.seed < 0) throw UserError("--seed = " + std::to_string(o.seed) + ": must be >= 0");
    s.particles = o.particles;
    s.fill_mass = o.fill_mass;
    s.threads = thread_count(o);
    s.seed = static_cast<unsigned long>(o.seed);
    s.max_time = o.max_time;
    s.fill_time_max = o.fill_time;
    s.fill_time_min = std::min(s.fill_time_min, o.fill_time);
    s.time_step = o.dt;
    s.time_step_fraction = o.dt_fraction;
    if (!o.material_file.empty()) s.materials = read_silo_material(o.material_file);
    s.materials.stiffness_scale = o.stiffness_scale;
    s.stop_fraction = o.stop_fraction;
    s.skin = o.skin;
    s.vibration = vibration_from(o, sub);
    s.contacts_at_opening = o.start_as_yade_import     ? ks::ContactsAtOpening::yade_import
                            : o.forget_contact_history ? ks::ContactsAtOpening::forget_history
                                                       : ks::ContactsAtOpening::keep_history;
    s.contact_law = ks::silo_contact_laws().at(o.contact_law);  // a name the option checked
    s.discharge_clump_rotation = ks::silo_clump_rotations().at(o.discharge_rotation);
    s.discharge_wall_facets = o.discharge_wall_facets;
    s.vtk_dir = o.vtk;
    s.vtk_interval = o.vtk_every;
    for (const auto& [field, option] : kSettingOptions)
        if (sub.count(option)) sources[field] = option;
    try {
        ks::validate(s);
    } catch (const ks::SettingRejected& e) {
        throw UserError(e.message([&](const std::string& field) {
            const auto source = sources.find(field);
            return source == sources.end() ? field : source->second;
        }));
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    check_run_size(s);
    return s;
}

// The settings as given (a still bin too: a sweep reads every run the same way) and the peak acceleration.
// How long the walls shook while the bed discharged: 0 when the discharge ended before the start (a run "vibrating"
// at 4 g gave the still run's rate bit for bit).
double vibrated_time(const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r) {
    return s.vibration.vibrates() ? std::max(0.0, r.discharge_time - s.vibration.start_after_opening) : 0.0;
}

nlohmann::json vibration_json(const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r) {
    const ks::BinVibration& v = s.vibration;
    // "vibrates": the walls shook during the discharge; "vibration_requested": the settings ask for shaking (a
    // --vibration-start after the discharge's end recorded "vibrates": true for a still run: held-back suite)
    return {{"vibrates", vibrated_time(s, r) > 0},
            {"vibration_requested", v.vibrates()},
            {"frequency_hz", v.frequency},
            {"amplitude_m", v.amplitude},
            {"direction", ks::to_string(v.direction)},
            {"part", ks::to_string(v.part)},
            {"start_after_opening_s", v.start_after_opening},
            {"start_time_s", r.fill_time + v.start_after_opening},
            {"vibrated_s", vibrated_time(s, r)},
            {"peak_acceleration_m_s2", v.peak_acceleration()},
            {"peak_acceleration_g", v.peak_acceleration() / s.gravity},
            {"note", "displacement A sin(2 pi f (t - start_time_s)) of the walls of the part (bin: every wall, "
                     "hopper, body and outlet plate; hopper: the hopper and the outlet plate, the body still), still "
                     "while filling; x: horizontal, perpendicular to the silo axis (the seed's "
                     "vibrator), z: along the axis; peak acceleration A (2 pi f)^2, in g of the run's gravity"}};
}

// The outlet zone's density and speed over the steady window (kernel/silo/outlet_flow.hpp).
nlohmann::json outlet_flow_json(const ks::OutletFlowResult& o) {
    return {{"frames", o.frames},
            {"zone_height_m", o.zone_height},
            {"zone_volume_m3", o.zone_volume},
            {"mean_grains", o.mean_grains},
            {"solid_density_kg_m3", o.solid_density},
            {"downward_speed_m_s", o.downward_speed},
            {"flux_rate_kg_s", o.flux_rate},
            {"note", "grains whose centre lies above the opening, below half the outlet size, over the rate's "
                     "window: grain mass per zone volume, their mean downward velocity, and the product with the "
                     "outlet area (a flux estimate, not the rate: compare it between runs of one geometry, where a "
                     "change of the rate splits into the changes of density and speed)"}};
}

// Beverloo (with the Rose-Tanaka hopper factor) for the measured bulk density: the sanity check of the rate.
nlohmann::json beverloo_check(const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r) {
    const double dp = ks::wheat_equivalent_diameter();
    const double k = 1.5, c = 0.58;
    double w;
    if (s.geometry.shape == ks::SiloShape::conical)
        w = analytics::beverloo_rate(s.geometry.outlet, dp, r.bulk_density, c, k);
    else
        w = analytics::beverloo_slot_rate(s.geometry.depth, s.geometry.outlet, dp, r.bulk_density, 1.03, k);
    const double f = analytics::rose_tanaka_factor(s.geometry.half_angle_deg, 45);
    nlohmann::json j{{"model", s.geometry.shape == ks::SiloShape::conical ? "beverloo" : "beverloo_slot"},
                     {"d_p_m", dp},
                     {"k", k},
                     {"C", s.geometry.shape == ks::SiloShape::conical ? c : 1.03},
                     {"rho_b_kg_m3", r.bulk_density},
                     {"rate_kg_s", w},
                     {"rose_tanaka_factor", f},
                     {"rate_with_hopper_factor_kg_s", w * f}};
    if (r.fit.ok && w > 0) j["simulated_over_predicted"] = r.fit.rate / (w * f);
    return j;
}

void write_plots(const fs::path& dir, const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r) {
    // mid-plane section: one filled square per cell, coloured by the mean vertical velocity
    if (r.section && r.section->frames() > 0) {
        const auto& sec = *r.section;
        {
            std::ostringstream f;
            f << "# x_m z_m vz_m_s: mean vertical velocity in the mid-plane slab over " << sec.frames()
              << " frames of the steady discharge\n";
            for (int i = 0; i < sec.nx(); ++i)
                for (int k = 0; k < sec.nz(); ++k) {
                    const double v = sec.vz(i, k);
                    if (!std::isnan(v)) f << sec.x_centre(i) << " " << sec.z_centre(k) << " " << v << "\n";
                }
            write_result_file(dir / "section.dat", f.str());
        }
        sec.write_outline(dir / "section_outline.dat");
        double zmax = r.fill_height + 0.01;
        const double half = 0.5 * sec.cell() * 1e3;
        std::ostringstream g;
        g << "set title 'Mid-plane section, vertical velocity (theta = " << s.geometry.half_angle_deg
          << " deg, " << ks::to_string(r.flow.pattern) << " flow, ratio " << fixed(r.flow.ratio, 2) << ")'\n"
          << "set xlabel 'x [mm]'\nset ylabel 'z [mm]'\nset size ratio -1\nset cblabel 'v_z [m/s]'\n"
          << "set palette defined (0 'red', 0.5 'yellow', 0.8 'cyan', 1 'blue')\n"
          << "set xrange [" << -s.geometry.top_half() * 1e3 - 5 << ":" << s.geometry.top_half() * 1e3 + 5 << "]\n"
          << "set yrange [-15:" << zmax * 1e3 << "]\nunset key\n"
          << "plot " << gnuplot_quote(dir / "section.dat") << " using ($1*1000):($2*1000):(" << half << "):(" << half
          << "):3 with boxxyerror fs solid noborder palette, " << gnuplot_quote(dir / "section_outline.dat")
          << " using ($1*1000):($2*1000) with lines lw 2 lc rgb 'black'\n";
        render_gnuplot(dir / "section.png", g.str(), 700, 900);
    }
    if (!r.discharge.empty()) {
        std::ostringstream g;
        g << "set datafile separator ','\nset title 'Discharged mass (theta = " << s.geometry.half_angle_deg
          << " deg)";
        if (r.fit.ok) g << ": W = " << fixed(r.fit.rate * 1e3, 1) << " g/s, R^2 = " << fixed(r.fit.r_squared, 4);
        g << "'\nset xlabel 'time since opening [s]'\nset ylabel 'discharged mass [g]'\nset key top left\n"
          << "plot " << gnuplot_quote(dir / "discharge.csv") << " using 1:($2*1000) with lines lw 2 title 'kernel'";
        if (r.fit.ok)
            g << ", [" << r.fit.t_begin << ":" << r.fit.t_end << "] (" << r.fit.intercept << " + " << r.fit.rate
              << " * x) * 1000 with lines dt 2 lw 2 title 'linear fit (steady part)'";
        g << "\n";
        render_gnuplot(dir / "discharge.png", g.str());
    }
}

void print_progress(const ks::SiloProgress& p) {
    std::cout << "[" << std::setw(7) << duration_text(p.wall_s) << "] " << std::left << std::setw(10) << p.phase
              << std::right << " t = " << fixed(p.time, 3) << " s";
    if (p.phase == "discharge" || p.phase == "done" || (p.phase == "suspended" && p.discharge_time > 0))
        std::cout << " (" << fixed(p.discharge_time, 3) << " s open)  discharged " << p.grains_discharged
                  << " grains, " << fixed(p.discharged_mass * 1e3, 1) << " g; " << p.grains_in_silo
                  << " in the silo";
    else if (p.phase != "checkpoint")
    {
        std::ostringstream ke;  // own stream: cout keeps its default precision
        ke << std::setprecision(3) << p.kinetic_energy_per_grain;
        std::cout << "  " << p.grains_in_silo << " grains, kinetic energy " << ke.str() << " J/grain";
    }
    if (p.step_ms > 0) {
        std::cout << "  [" << fixed(p.step_ms, 1) << " ms/step, " << fixed(p.cores_busy, 2) << " cores";
        if (p.remaining_wall_s > 0) std::cout << "; ~" << duration_text(p.remaining_wall_s) << " left at this rate and cost";
        std::cout << "]";
    }
    if (!p.note.empty()) std::cout << "  " << p.note;
    std::cout << std::endl;
}

void write_outputs(const fs::path& dir, const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r, bool no_plots);

// The output folder's lock, for the whole run (or resume); a folder another demcal holds is refused.
std::unique_ptr<orchestrator::FolderLock> lock_output_folder(const fs::path& dir) {
    try {
        return std::make_unique<orchestrator::FolderLock>(dir, "silo output folder");
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
}

// Refuses an output folder that holds an unfinished run's checkpoint, a finished run's results, or (in a folder no
// silo run has held) a file of the user's that a run would replace.
void check_out_folder_free(const fs::path& dir) {
    // a run going on there first: its checkpoint is its own, not one to resume or remove (probe 60)
    if (orchestrator::FolderLock::held(dir))
        throw UserError("--out = '" + dir.string() + "': the silo output folder is in use by another demcal process "
                        "(a silo run going on there): give another --out, or wait for that run to end");
    if (fs::exists(dir / kCheckpointName))
        throw UserError("--out = '" + dir.string() + "' holds the checkpoint of an unfinished run: continue it with "
                        "`demcal silo --resume " + shell_word(dir.string()) + "`, or remove " + (dir / kCheckpointName).string() +
                        " to start over");
    // a campaign's own folder (a shear store, a silo sweep's campaign.json): the run's files would mix with its runs
    for (const char* marker : {"campaign.sqlite", "campaign.json"})
        if (fs::exists(fs::symlink_status(dir / marker)))
            throw UserError("--out = '" + dir.string() + "' holds a campaign (" + marker + "): a silo run's files "
                            "would mix with it; give another --out (a new or empty folder)");
    if (fs::is_regular_file(dir / "summary.json"))  // a new run would leave the old results beside its own until its end
        throw UserError("--out = '" + dir.string() + "' holds the results of a finished run (summary.json): give "
                        "another --out, or remove them to run again there");
    // any other file a run writes, already there in a folder no silo run has held (no .lock of one): a user's file
    // (a measured discharge.csv in a data folder was replaced by the run's own). In a folder a run held, they are an
    // earlier attempt's (a campaign's retry in its run folder), replaced.
    // (files only: a folder in a file's place cannot be replaced, the write fails and says so)
    for (const char* name : kRunFiles)
        if (!fs::exists(fs::symlink_status(dir / ".lock")) &&
            (fs::is_regular_file(fs::symlink_status(dir / name)) || fs::is_symlink(fs::symlink_status(dir / name))))
            throw UserError("--out = '" + dir.string() + "' already holds " + name + ", a file a silo run writes: give "
                            "another --out (a new or empty folder), or remove it");
}

// Refuses an exported bed in the --out folder under a name the run keeps for itself: one of kRunFiles with any ending
// (the atomic writers' temporaries, checkpoint.bin.tmp) or a hidden name (.lock): the run removed or replaced such a
// file, and the exported bed was gone at the end with exit 0.
void refuse_export_among_run_files(const std::string& file, const char* option, const fs::path& out) {
    if (file.empty()) return;
    std::error_code ec;
    const fs::path parent = fs::weakly_canonical(fs::absolute(fs::path(file)).parent_path(), ec);
    if (ec || parent != fs::weakly_canonical(fs::absolute(out), ec) || ec) return;
    const std::string name = fs::path(file).filename().string();
    bool taken = !name.empty() && name.front() == '.';
    for (const char* own : kRunFiles) taken = taken || name.rfind(own, 0) == 0;
    if (taken)
        throw UserError(std::string(option) + " = '" + analytics::shortened_text(file, 200) + "': the name " + name +
                        " in the --out folder is the run's own (its results, their temporary files, its lock): "
                        "give the bed another name or folder");
}

// Refuses a --vtk folder that already holds snapshots (silo_*.vtk) for a new run: it replaced a user's file of that
// name, and a second run there overwrote the first run's first frames and left its later ones, one mixed series.
void check_vtk_folder_free(const std::string& vtk_dir) {
    std::error_code ec;
    for (fs::directory_iterator it(vtk_dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.rfind("silo_", 0) == 0 && it->path().extension() == ".vtk")
            throw UserError("--vtk = '" + vtk_dir + "' already holds snapshots (" + name + "): give a new or empty "
                            "folder, or remove them");
    }
}

// The VTK folder's lock, for the whole run (two runs wrote one series), unless it is the output folder (locked as
// such). Made again on a resume where it was removed.
std::unique_ptr<orchestrator::FolderLock> lock_vtk_folder(const std::string& vtk_dir, const fs::path& out_dir) {
    if (vtk_dir.empty()) return nullptr;
    std::error_code ec;
    fs::create_directories(vtk_dir, ec);
    if (ec) throw UserError("--vtk = '" + vtk_dir + "': cannot create the directory: " + ec.message());
    if (fs::equivalent(vtk_dir, out_dir, ec)) return nullptr;
    try {
        return std::make_unique<orchestrator::FolderLock>(vtk_dir, "silo VTK folder");
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
}

void check_checkpoint_options(const SiloCli& o, const CLI::App& sub) {
    if (o.no_checkpoint && o.wall_limit > 0)
        throw UserError("--wall-limit " + ks::setting_text(o.wall_limit) +
                        " needs the checkpoint that --no-checkpoint turns off");
    if (o.no_checkpoint && sub.count("--checkpoint-every"))
        throw UserError("--checkpoint-every " + ks::setting_text(o.checkpoint_every) +
                        ": --no-checkpoint turns the checkpoint off; give one of the two");
}

// Every output place before the run (a run of hours into an unwritable folder failed at its end, and told the user
// to resume from a checkpoint it could never write): the VTK folder, the run's files apart from its inputs, and the
// exported beds, whose writers are attached to the run here.
void prepare_outputs(const SiloCli& o, const fs::path& dir, ks::SiloCaseSettings& s) {
    // the bed files are for yade_scripts/silo.py, whose silo is conical (geometry.shape): a rectangular silo's bed was
    // written, and refused by YADE only when the cross-check was run
    if (s.geometry.shape == ks::SiloShape::rectangular)
        for (const auto& [file, option] : {std::pair{o.export_bed, "--export-bed"},
                                           std::pair{o.export_final_bed, "--export-final-bed"},
                                           std::pair{o.export_cloud, "--export-cloud"}})
            if (!file.empty())
                throw UserError(std::string(option) + " = '" + analytics::shortened_text(file, 200) +
                                "': the bed files are for YADE's silo (yade_scripts/silo.py), which is conical; "
                                "this silo is rectangular (--rect or the --geometry file's shape)");
    if (!s.vtk_dir.empty()) {
        check_output_folder(s.vtk_dir, "--vtk");
        check_vtk_folder_free(s.vtk_dir);
    }
    for (const auto& [file, option] : {std::pair{o.export_bed, "--export-bed"},
                                       std::pair{o.export_final_bed, "--export-final-bed"},
                                       std::pair{o.export_cloud, "--export-cloud"}})
        refuse_export_among_run_files(file, option, dir);
    std::vector<NamedPath> outputs{{dir.string(), "--out"}};
    for (const char* name : kRunFiles) outputs.push_back({(dir / name).string(), std::string("--out's ") + name});
    outputs.insert(outputs.end(), {{o.export_bed, "--export-bed"}, {o.export_final_bed, "--export-final-bed"},
                                   {o.export_cloud, "--export-cloud"}});
    check_paths_apart({{o.material_file, "--material"}, {o.geometry_file, "--geometry"}}, outputs);
    // a bed exported into the --out folder, which the run makes before it writes anything, is not refused for that
    // folder's absence (it was: "the folder s20 does not exist")
    const auto check_export = [&dir](const std::string& file, const char* option) {
        const fs::path parent = without_trailing_separator(fs::absolute(fs::path(file)).lexically_normal().parent_path());
        if (parent == without_trailing_separator(fs::absolute(dir).lexically_normal()) && !fs::exists(dir))
            check_output_file_in_new_folders(file, option);
        else
            check_output_file(file, option);
    };
    if (!o.export_bed.empty()) {
        check_export(o.export_bed, "--export-bed");
        s.at_opening = [file = o.export_bed, settings = s](const ks::BedSnapshot& bed) {
            write_silo_bed(file, bed, settings, BedMoment::opening, "export-bed");
        };
    }
    if (!o.export_final_bed.empty()) {
        check_export(o.export_final_bed, "--export-final-bed");
        s.at_end = [file = o.export_final_bed, settings = s](const ks::BedSnapshot& bed) {
            write_silo_bed(file, bed, settings, BedMoment::end, "export-final-bed");
        };
    }
    if (!o.export_cloud.empty()) {
        check_export(o.export_cloud, "--export-cloud");
        s.at_generation = [file = o.export_cloud, settings = s](const ks::BedSnapshot& bed) {
            write_silo_bed(file, bed, settings, BedMoment::generation, "export-cloud");
        };
    }
}

// The output folder and the VTK folder; on a failure nothing half-made is left behind.
void create_output_folders(const fs::path& dir, const std::string& vtk_dir) {
    std::error_code ec;
    const bool created_out = fs::create_directories(dir, ec);
    if (ec) throw UserError("--out = '" + dir.string() + "': cannot create the directory: " + ec.message());
    if (vtk_dir.empty()) return;
    fs::create_directories(vtk_dir, ec);
    if (ec) {
        std::error_code ignored;
        if (created_out) fs::remove(dir, ignored);  // it is empty
        throw UserError("--vtk = '" + vtk_dir + "': cannot create the directory: " + ec.message());
    }
}

void print_run_header(const ks::SiloCaseSettings& s, const fs::path& dir) {
    std::cout << "demcal silo: " << s.geometry.describe() << "\n  " << s.threads << " thread(s), seed " << s.seed
              << ", stiffness scale " << s.materials.stiffness_scale << ", output " << dir.string() << "\n  contact law: "
              << ks::contact_law_name(s);
    if (s.vibration.vibrates()) std::cout << "\n  vibration: " << vibration_text(s);
    if (s.discharge_clump_rotation != kernel::ClumpRotation::richardson)
        std::cout << "\n  clump rotation in the discharge: YADE's aspherical leapfrog (the filling: the kernel's own)";
    if (s.discharge_wall_facets > 0)
        std::cout << "\n  walls in the discharge: cone and cylinder of " << s.discharge_wall_facets
                  << " facets around, as YADE's silo.py (the filling: exact walls)";
    if (!s.checkpoint_file.empty())
        std::cout << "\n  checkpoint every " << duration_text(s.checkpoint_interval) << " to " << s.checkpoint_file
                  << " (continue an interrupted run with `demcal silo --resume " << shell_word(dir.string()) << "`)";
    std::cout << std::endl;
}

// A new run into `dir` (refused when dir holds the checkpoint of an unfinished run: it would be overwritten).
void run_silo(const SiloCli& o, CLI::App& sub) {
    ks::SiloCaseSettings s = settings_from(o, sub);
    const fs::path dir =
        o.out.empty() ? fs::path("silo_theta" + fixed(s.geometry.half_angle_deg, 0)) : fs::path(o.out);
    check_output_folder(dir.string(), "--out");  // first: a path the file system refuses fails every look into it
    check_out_folder_free(dir);
    if (!o.no_plots) require_gnuplot("--no-plots");
    check_checkpoint_options(o, sub);
    prepare_outputs(o, dir, s);
    if (o.check_only) {
        std::cout << "silo: the settings are valid (--check: nothing run, nothing written)\n";
        return;
    }
    create_output_folders(dir, s.vtk_dir);
    // one demcal per output folder: a second one (a repeated command, a sweep started twice) stops here
    const auto lock = lock_output_folder(dir);
    if (fs::exists(dir / kCheckpointName) || fs::is_regular_file(dir / "summary.json"))
        throw UserError("--out = '" + dir.string() + "': another demcal has just run into this folder");
    const auto vtk_lock = lock_vtk_folder(s.vtk_dir, dir);
    if (!s.vtk_dir.empty()) check_vtk_folder_free(s.vtk_dir);  // a run started beside this one
    if (!o.no_checkpoint) {
        s.checkpoint_file = (dir / kCheckpointName).string();
        s.checkpoint_interval = o.checkpoint_every;
    }
    s.wall_limit = o.wall_limit;
    if (!o.no_checkpoint)
        orchestrator::write_text_file_atomically(
            dir / kSessionFileName, nlohmann::json{{"threads", o.threads},
                                                   {"checkpoint_every", o.checkpoint_every},
                                                   {"no_plots", o.no_plots}}.dump(1) + "\n");
    print_run_header(s, dir);
    std::optional<StopOnSignal> stop_on_signal;  // without a checkpoint there is nothing to stop to
    if (!s.checkpoint_file.empty()) {
        stop_on_signal.emplace();
        s.stop_request = StopOnSignal::reason;
    }
    write_outputs(dir, s, ks::run_silo_case(s, print_progress), o.no_plots);
}

// The session options of the run in `dir` (session.json) where --resume was not given them; the options as given
// where the file is missing (a run of a demcal before it). The file is read only for an option not given, and a
// value it holds that the option itself would refuse (threads 100000 crashed the resume), or a file that is not the
// run's session options, is said and left aside for the default: a side file never stops a resumable run.
SiloCli with_stored_session(const SiloCli& given, CLI::App& sub, const fs::path& dir) {
    SiloCli o = given;
    const bool all_given = sub.count("--threads") && sub.count("--checkpoint-every") && sub.count("--no-plots");
    if (given.resume.empty() || all_given || !fs::is_regular_file(dir / kSessionFileName)) return o;
    const fs::path file = dir / kSessionFileName;
    try {
        const nlohmann::json stored = read_json_file(file.string(), "the run's session options");
        if (!sub.count("--threads")) {
            const int threads = stored.at("threads").get<int>();
            if (threads < 0 || threads > kMaxThreads)
                throw std::out_of_range("threads = " + std::to_string(threads) + " is not 0 (every core) to " +
                                        std::to_string(kMaxThreads));
            o.threads = threads;
        }
        if (!sub.count("--checkpoint-every")) {
            const double every = stored.at("checkpoint_every").get<double>();
            if (!(every > 0) || !std::isfinite(every))
                throw std::out_of_range("checkpoint_every = " + ks::setting_text(every) + " is not a positive time");
            o.checkpoint_every = every;
        }
        if (!sub.count("--no-plots")) o.no_plots = stored.at("no_plots").get<bool>();
    } catch (const std::exception& e) {
        std::cerr << "demcal: warning: " << file.string() << " is not the run's session options ("
                  << analytics::shortened_text(e.what(), 300) << "); the resume uses --threads, --checkpoint-every "
                  << "and --no-plots as given, or their defaults" << std::endl;
        return given;
    }
    return o;
}

// Continues the run whose checkpoint lies in o.resume, with the settings stored in it.
void resume_silo(const SiloCli& given, CLI::App& sub) {
    const SiloCli o = with_stored_session(given, sub, fs::path(given.resume));
    for (const auto* opt : sub.get_options()) {
        const std::string name = opt->get_name();
        if (opt->count() > 0 && name != "--resume" && name != "--threads" && name != "--checkpoint-every" &&
            name != "--wall-limit" && name != "--no-plots")
            throw UserError(name + " cannot be combined with --resume: a resumed run keeps the settings stored in "
                                   "its checkpoint (only --threads, --checkpoint-every, --wall-limit and --no-plots "
                                   "apply)");
    }
    check_session_options(o, sub);
    if (o.resume.empty()) throw UserError("resume = '': give the output directory of the run to continue");
    const fs::path dir(o.resume);
    const fs::path file = dir / kCheckpointName;
    if (fs::exists(file) && !fs::is_regular_file(file))
        throw UserError("resume = '" + dir.string() + "': " + file.string() + " is not a regular file");
    if (!fs::exists(file)) {
        std::string why = fs::exists(dir / "summary.json") ? " (summary.json is there: that run has finished)"
                                                              : fs::exists(dir) ? "" : " (no such directory)";
        throw UserError("resume = '" + dir.string() + "' holds no " + kCheckpointName + why);
    }
    const int threads = thread_count(o);
    ks::SiloCaseSettings s;
    try {
        s = ks::read_checkpoint_settings(file.string());
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
    // the results, the next checkpoints and the snapshots go where the run wrote before: still writable?
    check_output_folder(dir.string(), "--resume");
    if (!s.vtk_dir.empty()) check_output_folder(s.vtk_dir, "--vtk (the run's snapshot folder, in its checkpoint)");
    if (!o.no_plots) require_gnuplot("--no-plots");
    const auto lock = lock_output_folder(dir);  // two resumes of one run read and wrote one checkpoint at once
    const auto vtk_lock = lock_vtk_folder(s.vtk_dir, dir);
    // a refusal after the locks leaves the folders as found: no .lock file that this command made (probe 64)
    const auto forget_locks = [&] {
        if (vtk_lock) vtk_lock->release_and_forget();
        lock->release_and_forget();
    };
    if (!fs::exists(file)) {
        forget_locks();
        throw UserError("resume = '" + dir.string() + "': another demcal has just finished it");
    }
    s.threads = threads;
    s.checkpoint_file = file.string();  // removed once the outputs are written
    s.wall_limit = o.wall_limit;
    std::cout << "demcal silo --resume: " << s.geometry.describe() << "\n  " << threads << " thread(s), seed "
              << s.seed << ", stiffness scale " << s.materials.stiffness_scale << ", checkpoint " << file.string();
    if (s.vibration.vibrates()) std::cout << "\n  vibration: " << vibration_text(s);
    std::cout << std::endl;
    const StopOnSignal stop_on_signal;
    ks::SiloCaseResult result;
    try {
        result = ks::resume_silo_case(file.string(), {threads, o.checkpoint_every, o.wall_limit, StopOnSignal::reason},
                                      print_progress);
    } catch (const std::invalid_argument&) {  // a damaged checkpoint, refused as it loads (bad input, exit 2)
        forget_locks();
        throw;
    }
    write_outputs(dir, s, result, o.no_plots);
}

// CPU time with the sessions it covers, e.g. "21.3 h CPU" or "12.0 h CPU (the last 3 of 5 sessions)".
std::string cpu_text(const ks::SiloCaseResult& r) {
    std::string t = duration_text(r.cpu_s) + " CPU";
    if (r.cpu_sessions < r.sessions)
        t += " (the last " + std::to_string(r.cpu_sessions) + " of " + std::to_string(r.sessions) + " sessions)";
    if (!r.suspended() && std::isfinite(r.fill_cpu_s)) t += ", of which the discharge " + duration_text(r.cpu_s - r.fill_cpu_s);
    return t;
}

// A time that may be unknown (NaN) as JSON: the number or null.
nlohmann::json seconds_or_null(double seconds) { return std::isfinite(seconds) ? nlohmann::json(seconds) : nullptr; }

// A run stopped before its end (a time budget, a signal): where it stands and how to go on; exits kExitSuspended.
[[noreturn]] void report_suspension(const fs::path& dir, const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r) {
    std::cout << "\nsuspended: " << r.stop_reason << ", "
              << (r.discharge_time > 0 ? fixed(r.discharge_time, 3) + " s after the opening" : "while filling")
              << " (" << r.steps << " steps, " << r.grains_discharged << " grains discharged); checkpoint "
              << r.checkpoints << " written to " << s.checkpoint_file << "\nwall time so far "
              << duration_text(r.wall_s) << ", " << cpu_text(r) << "; continue with `demcal silo --resume "
              << shell_word(dir.string()) << "`" << std::endl;
    throw CLI::RuntimeError(kExitSuspended);
}

// The run's summary.json (before its seal).
nlohmann::json summary_json(const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r) {
    nlohmann::json j;
    j["schema"] = orchestrator::kSiloSummarySchema;
    j["geometry"] = silo_geometry_json(s.geometry);
    j["grains"] = r.grains;
    j["grain_mass_kg"] = r.grain_mass;
    j["filled_mass_kg"] = r.filled_mass;
    j["bulk_density_kg_m3"] = r.bulk_density;
    j["fill"] = {{"time_s", r.fill_time},
                 {"at_rest", r.fill_at_rest},
                 {"kinetic_energy_per_grain_J", r.fill_kinetic_energy},
                 {"rest_criterion_J", s.rest_energy_factor * r.grain_mass * s.gravity * ks::wheat_length},
                 {"height_m", r.fill_height},
                 {"steps", r.fill_steps},
                 {"wall_s", r.fill_wall_s},
                 {"cpu_s", seconds_or_null(r.fill_cpu_s)}};
    j["discharge"] = {{"time_s", r.discharge_time},
                      {"cpu_s", seconds_or_null(r.cpu_s - r.fill_cpu_s)},
                      {"discharged_mass_kg", r.discharge.empty() ? 0.0 : r.discharge.back().mass},
                      {"grains_discharged", r.grains_discharged},
                      {"grains_left", r.grains_in_silo},
                      {"emptied", r.emptied()},
                      {"end", ks::discharge_end_name(r.end)},
                      {"stop_reason", r.stop_reason}};
    nlohmann::json fit{{"ok", r.fit.ok},
                       {"window", "discharged mass between " + fixed(100 * r.fit.lower_fraction, 0) + " % and " +
                                      fixed(100 * r.fit.upper_fraction, 0) + " % of the mass discharged at the end"},
                       {"t_begin_s", r.fit.t_begin},
                       {"t_end_s", r.fit.t_end},
                       {"samples", r.fit.n}};
    if (r.fit.ok) {
        fit["rate_kg_s"] = r.fit.rate;
        fit["rate_se_kg_s"] = r.fit.rate_se;
        fit["rate_batch_se_kg_s"] = r.fit.rate_batch_se;
        fit["batches"] = r.fit.batches;
        fit["r_squared"] = r.fit.r_squared;
        fit["uncertainty_note"] =
            "rate_se_kg_s: standard error of the least-squares slope; the samples of a cumulative mass are correlated, "
            "so it understates the uncertainty. rate_batch_se_kg_s: slopes fitted over four equal time spans of the "
            "window, the standard error of their mean (the flow's own fluctuation). Neither is the run-to-run spread: "
            "repeat with other --seed values for that";
    } else {
        fit["message"] = r.fit.message;
    }
    j["rate"] = fit;
    j["flow_pattern"] = flow_pattern_json(r.flow);
    j["outlet_flow"] = outlet_flow_json(r.outlet);
    j["vibration"] = vibration_json(s, r);
    if (r.bulk_density > 0) j["beverloo_check"] = beverloo_check(s, r);
    j["steps"] = r.steps;
    j["time_step_s"] = r.time_step;
    j["wall_s"] = r.wall_s;
    j["sessions"] = r.sessions;
    j["cpu_s"] = r.cpu_s;
    j["cpu_sessions"] = r.cpu_sessions;
    j["time_note"] = "wall_s: every session's wall-clock time, pauses and waits for busy cores included; cpu_s: the "
                     "process's CPU time over all its threads, in the last cpu_sessions sessions (checkpoints before "
                     "format 2 did not record it); fill.cpu_s and discharge.cpu_s split it at the opening (null: "
                     "unknown, a run resumed past its filling from a checkpoint before format 12)";
    j["checkpoints"] = r.checkpoints;
    j["settings"] = {{"threads", s.threads},
                     {"seed", s.seed},
                     {"particles_requested", s.particles},
                     {"fill_mass_requested_kg", s.fill_mass},
                     {"stiffness_scale", s.materials.stiffness_scale},
                     {"time_step_fraction_of_rayleigh", s.time_step_fraction},
                     {"fill_time_max_s", s.fill_time_max},
                     {"max_time_s", s.max_time},
                     {"stop_fraction", s.stop_fraction},
                     {"skin_m", s.skin},
                     {"removal_depth_m", s.removal_depth},
                     {"contacts_at_opening", s.contacts_at_opening == ks::ContactsAtOpening::yade_import ? "yade_import"
                                             : s.contacts_at_opening == ks::ContactsAtOpening::forget_history
                                                 ? "forget_history"
                                                 : "keep_history"},
                     {"contact_law_family", ks::silo_contact_law_text(s.contact_law)},
                     {"discharge_clump_rotation", ks::silo_clump_rotation_text(s.discharge_clump_rotation)},
                     {"discharge_wall_facets", s.discharge_wall_facets},
                     // as a --material file gives it (silo_material.cpp), unscaled: demcal silo --material reads it back
                     {"material", silo_material_json(s.materials)},
                     {"contact_law", r.contact_law}};
    if (!s.vtk_dir.empty()) j["vtk"] = {{"dir", s.vtk_dir}, {"files", r.vtk_files}};
    return j;
}

// discharge.csv, then the sealed summary.json that marks the run finished; either both or neither (exit 74: the
// campaigns run it again). The results written, the checkpoint has served its purpose and is removed.
void write_results(const fs::path& dir, const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r,
                   const nlohmann::json& j) {
    try {
        // (the table first, then the summary that marks the run finished; a failure removes the table again below)
        orchestrator::write_text_file_atomically(dir / "discharge.csv", ks::discharge_csv_text(r.discharge));
        // sealed: the campaigns that read it back (vibration, cutoff, crosscheck, diagnose silo-dem) find a damaged one
        orchestrator::write_text_file_atomically(dir / "summary.json",
                                                 orchestrator::sealed_result_text(j.dump(2) + "\n"));
    } catch (const std::exception& e) {
        std::error_code ec;
        fs::remove(dir / "discharge.csv", ec);  // no table without its summary: a reader takes the pair for a result
        // a checkpoint on disk stays: resuming from it computes the end again and writes the results
        const bool resumable = !s.checkpoint_file.empty() && fs::exists(s.checkpoint_file, ec);
        std::cerr << "demcal: failed: "
                  << analytics::shortened_text(
                         std::string(e.what()) + "; the results are not written" +
                             (resumable ? "; the checkpoint is kept: make room, then `demcal silo --resume " +
                                              shell_word(dir.string()) + "` finishes the run again"
                                        : "; no checkpoint was written (none was due: --checkpoint-every), so "
                                          "the run must be made again"),
                         4000)
                  << std::endl;
        throw CLI::RuntimeError(kExitResultsNotWritten);  // a campaign runs it again (app/silo_campaign.cpp)
    }
    // the results are written: the checkpoint has served its purpose (and would block a new run in this directory)
    if (!s.checkpoint_file.empty()) {
        std::error_code ec;
        fs::remove(s.checkpoint_file, ec);
        fs::remove(s.checkpoint_file + ".tmp", ec);
    }
}

// The run in a few lines on stdout.
void print_summary(const fs::path& dir, const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r, bool no_plots) {
    std::cout << "\n" << r.grains << " grains (" << fixed(r.filled_mass * 1e3, 1) << " g), filled in "
              << fixed(r.fill_time, 3) << " s" << (r.fill_at_rest ? " (at rest)" : " (time limit, not at rest)")
              << ", bulk density " << fixed(r.bulk_density, 0) << " kg/m^3\n";
    std::cout << "discharge: " << r.grains_discharged << " grains in " << fixed(r.discharge_time, 3) << " s ("
              << r.stop_reason << ")\n";
    if (r.fit.ok)
        std::cout << "rate W = " << fixed(r.fit.rate * 1e3, 2) << " +/- " << fixed(r.fit.rate_se * 1e3, 2)
                  << " g/s (slope SE; batch SE " << fixed(r.fit.rate_batch_se * 1e3, 2) << " g/s) (steady part "
                  << fixed(r.fit.t_begin, 3) << ".." << fixed(r.fit.t_end, 3) << " s), R^2 = "
                  << fixed(r.fit.r_squared, 5) << "\n";
    else
        std::cout << "rate: not determined (" << r.fit.message << ")\n";
    if (s.vibration.vibrates()) std::cout << "vibration: " << vibration_text(s) << "\n";
    // a run that could not give what a silo run is for says so where a user looks, not only in its summary
    if (!r.fill_at_rest)
        std::cerr << "demcal silo: warning: the filling reached its time limit (" << ks::setting_text(s.fill_time_max)
                  << " s) with the grains still moving (" << std::setprecision(3) << r.fill_kinetic_energy
                  << " J per grain): the discharge started from a bed not at rest; a longer --fill-time settles it"
                  << std::endl;
    if (!r.fit.ok)
        std::cerr << "demcal silo: warning: no discharge rate: " << r.fit.message << " (the discharge ended: "
                  << r.stop_reason << ")" << std::endl;
    if (s.vibration.vibrates() && !(vibrated_time(s, r) > 0))
        std::cerr << "demcal silo: warning: the bin never vibrated: the discharge ended " << fixed(r.discharge_time, 3)
                  << " s after the opening, before --vibration-start (" << ks::setting_text(s.vibration.start_after_opening)
                  << " s); summary.json records \"vibrates\": false, a still discharge" << std::endl;
    std::cout << "flow pattern: " << ks::to_string(r.flow.pattern) << " (wall/axis velocity ratio "
              << fixed(r.flow.ratio, 3) << ")\n";
    std::cout << r.steps << " steps of " << std::setprecision(3) << r.time_step << " s, wall time "
              << duration_text(r.wall_s);
    if (r.sessions > 1) std::cout << " over " << r.sessions << " sessions (resumed from checkpoints)";
    std::cout << ", " << cpu_text(r);
    std::cout << "\nwrote " << (dir / "summary.json").string() << ", "
              << (dir / "discharge.csv").string() << (no_plots ? "" : ", section.png, discharge.png") << "\n";
}

void write_outputs(const fs::path& dir, const ks::SiloCaseSettings& s, const ks::SiloCaseResult& r, bool no_plots) {
    if (r.suspended()) report_suspension(dir, s, r);  // nothing final to write: the checkpoint holds the run
    write_results(dir, s, r, summary_json(s, r));
    if (!no_plots) write_plots(dir, s, r);  // after the results: a plot that fails loses no data
    print_summary(dir, s, r, no_plots);
}

// The silo's shape and its grain: the geometry file or its options one by one, the material.
void add_geometry_options(CLI::App* sub, SiloCli& o) {
    sub->add_option("--theta", o.theta, "hopper half angle from the vertical [deg], 0 < theta < 90 (required unless "
                                         "--geometry gives theta_deg)");
    sub->add_option("--material", o.material_file,
                    "material file (grain, wall, grain-grain and grain-wall pairs; default: the seed's Table 2.1, "
                    "examples/materials/silo_wheat_table21.json)");
    sub->add_option("--geometry", o.geometry_file,
                    "geometry JSON (shape, theta_deg, outlet_m, D_m, body_height_m, a_m, b_m, c_m; see "
                    "examples/silo/); options given on the command line win");
    sub->add_option("--outlet", o.outlet, "outlet diameter d [m] (conical, default 0.035) or slot width a (--rect)");
    sub->add_option("--diameter", o.diameter, "silo diameter D [m]")->capture_default_str();
    sub->add_option("--body-height", o.body_height, "height of the vertical body above the hopper [m]")
        ->capture_default_str();
    sub->add_flag("--rect", o.rect, "rectangular silo with a wedge hopper and a slot outlet spanning the depth");
    sub->add_option("--a", o.a, "rectangular: outlet (slot) width a [m], default 0.03");
    sub->add_option("--b", o.b, "rectangular: silo depth b [m] (the slot's length)")->capture_default_str();
    sub->add_option("--c", o.c, "rectangular: silo width c [m]")->capture_default_str();
}

// How many grains, how the run fills and discharges them, and the numerics (time step, skin, threads).
void add_run_options(CLI::App* sub, SiloCli& o) {
    sub->add_option("--particles", o.particles, "number of grains")->capture_default_str();
    sub->add_option("--fill-mass", o.fill_mass, "mass of grain [kg] (instead of --particles)");
    sub->add_option("--threads", o.threads, "OpenMP threads (default: every core)")->check(integer_in(1, kMaxThreads));
    sub->add_option("--seed", o.seed, "random seed of the generation")->capture_default_str();
    sub->add_option("--out", o.out, "output directory (default silo_theta<DEG>)");
    sub->add_option("--vtk", o.vtk, "write VTK snapshots of the spheres into this directory");
    sub->add_option("--vtk-every", o.vtk_every, "simulated seconds between VTK snapshots")->capture_default_str();
    sub->add_option("--max-time", o.max_time, "discharge time limit after the opening [s]")->capture_default_str();
    sub->add_option("--fill-time", o.fill_time, "filling time limit [s] (ends earlier once the grains are at rest)")
        ->capture_default_str();
    sub->add_option("--dt", o.dt, "time step [s] (default: --dt-fraction x the Rayleigh time step)")
        ->check(positive_number());  // 0 stands for "not given" inside: `--dt 0` ran the default time step
    sub->add_option("--dt-fraction", o.dt_fraction, "time step as a fraction of the Rayleigh time step")
        ->capture_default_str();
    sub->add_option("--stiffness-scale", o.stiffness_scale,
                    "scales the shear moduli of Table 2.1, in (0, 1] (softer contacts allow a larger time step)")
        ->capture_default_str();
    sub->add_option("--stop-fraction", o.stop_fraction,
                    "stop once this fraction of the filled mass has left (1: until empty)")
        ->capture_default_str();
    sub->add_option("--skin", o.skin, "Verlet skin of the neighbour list [m] (0: 40 dt x 1 m/s within 0.2-1 mm)")
        ->capture_default_str();
}

// The seed's vibrated bin: frequency, amplitude, direction, which walls, from when.
void add_vibration_options(CLI::App* sub, SiloCli& o) {
    sub->add_option("--vibration-frequency", o.vibration_frequency,
                    "the bin (--vibration-part) vibrates at this frequency [Hz], 0-1000, from the opening (the "
                    "seed's eccentric vibrator; needs --vibration-amplitude)");
    sub->add_option("--vibration-amplitude", o.vibration_amplitude,
                    "displacement amplitude A of the bin's vibration [m], 0-0.01 (the seed: up to 1.1e-4); "
                    "d(t) = A sin(2 pi f t)");
    sub->add_option("--vibration-direction", o.vibration_direction,
                    "x: horizontal, perpendicular to the silo axis (as the seed's vibrator); z: along the axis")
        ->capture_default_str();
    sub->add_option("--vibration-part", o.vibration_part,
                    "the walls that vibrate: bin (hopper, body and outlet plate as one rigid body) or hopper (the "
                    "hopper and the outlet plate; the body still: the seed's vibrator sits on the cone)")
        ->capture_default_str();
    sub->add_option("--vibration-start", o.vibration_start,
                    "the vibration starts this many simulated seconds after the outlet opens; the bin is still "
                    "while it fills")
        ->capture_default_str();
}

// What a cross-check with yade_scripts/silo.py needs: the beds exported, and YADE's law, integrator and walls.
void add_yade_crosscheck_options(CLI::App* sub, SiloCli& o) {
    sub->add_option("--export-bed", o.export_bed,
                    "write the filled bed at the opening (every grain's centre, orientation, velocities; the clump, "
                    "materials, geometry) to this JSON file, for yade_scripts/silo.py");
    sub->add_option("--export-final-bed", o.export_final_bed,
                    "write the grains left when the discharge ends (the same format as --export-bed, moment \"end\"), "
                    "e.g. to compare them with YADE's after the same steps from the same bed (silo.py's "
                    "run.final_bed_file)");
    sub->add_option("--export-cloud", o.export_cloud,
                    "write the generated grains before the filling (the same format as --export-bed), for "
                    "yade_scripts/silo.py to fill the silo on its own from the same cloud");
    sub->add_flag("--forget-contact-history", o.forget_contact_history,
                  "at the opening every contact forgets its past (tangential springs at zero), as the bed does when "
                  "YADE's silo.py imports it: measures that one difference of a cross-check");
    sub->add_flag("--start-as-yade-import", o.start_as_yade_import,
                  "at the opening every contact forgets its past and the discharge starts as YADE's silo.py starts from "
                  "the exported bed (leapfrog: the first kick a whole step, the fresh contacts' springs advanced in the "
                  "first force evaluation): with --contact-law yade --discharge-rotation yade --discharge-wall-facets "
                  "72 the kernel then follows YADE's own run of the bed step for step until chaos parts them")
        ->excludes("--forget-contact-history");
    sub->add_option("--contact-law", o.contact_law,
                    "edem: the kernel's Hertz-Mindlin (JKR when cohesive) with EDEM's rolling friction; yade: YADE "
                    "2023.02a's Hertz-Mindlin as yade_scripts/silo.py runs it (incremental tangential force, no "
                    "rolling resistance: the material's rolling friction must be 0), for a cross-check on one law")
        ->check(CLI::IsMember(ks::silo_contact_laws()))
        ->capture_default_str();
    sub->add_option("--discharge-rotation", o.discharge_rotation,
                    "how the grains turn from the opening on: richardson (the kernel's quaternion update) or yade "
                    "(YADE 2023.02a's aspherical leapfrog); the filling always runs the kernel's own, so the bed is the "
                    "same either way: for a cross-check that removes the integrators' difference")
        ->check(CLI::IsMember(ks::silo_clump_rotations()))
        ->capture_default_str();
    sub->add_option("--discharge-wall-facets", o.discharge_wall_facets,
                    "0: exact cone and cylinder; N (12 to 2000): from the opening on, the conical silo's cone and "
                    "cylinder as N-sided polygons of triangular facets with YADE's facet contact, built as "
                    "yade_scripts/silo.py builds its walls; the filling runs on the exact walls, so the bed is the same "
                    "either way: for a cross-check that removes the walls' difference")
        ->capture_default_str();
}

// The session: plots, checkpoints, a check-only pass, a wall-clock limit and the resume of an interrupted run.
void add_session_options(CLI::App* sub, SiloCli& o) {
    sub->add_flag("--no-plots", o.no_plots, "do not render section.png and discharge.png (no gnuplot needed)");
    sub->add_option("--checkpoint-every", o.checkpoint_every,
                    "wall-clock seconds between checkpoints of the whole run to OUT/checkpoint.bin (removed once "
                    "the outputs are written)")
        ->capture_default_str();
    sub->add_flag("--no-checkpoint", o.no_checkpoint, "write no checkpoint");
    sub->add_flag("--check", o.check_only, "check the settings and exit (0: valid, 2: refused); nothing is written");
    sub->add_option("--wall-limit", o.wall_limit,
                    "stop after this many wall-clock seconds of this session (0: none), after the step it is in, "
                    "with a checkpoint written; exit status 75: not finished, continue with --resume "
                    "(a batch system's time limit); SIGTERM or Ctrl-C does the same at any time")
        ->capture_default_str();
    sub->add_option("--resume", o.resume,
                    "continue the interrupted run whose output directory (and checkpoint.bin) is DIR, bit for bit, "
                    "with the settings stored in its checkpoint");
}

// Every option of `demcal silo`, into `o`, in the order --help lists them.
void add_silo_options(CLI::App* sub, SiloCli& o) {
    add_geometry_options(sub, o);
    add_run_options(sub, o);
    add_vibration_options(sub, o);
    add_yade_crosscheck_options(sub, o);
    add_session_options(sub, o);
}

}  // namespace

namespace {

// demcal silo's options on a parser of their own, read by the rules of demcal silo's command line (no empty value,
// the number and integer rules, one value per occurrence): for the options a campaign passes on after --
std::unique_ptr<CLI::App> silo_options_parser(SiloCli& o, const std::string& title) {
    auto parser = std::make_unique<CLI::App>(title, "silo");
    add_silo_options(parser.get(), o);
    refuse_empty_values(*parser);
    read_values_strictly(*parser);
    return parser;
}

// An option given twice after --, by demcal's one rule (refuse_repeated_option): CLI11 said only "At Most 1 required
// but received 2" (probe 60b). A flag given twice is harmless: it says one thing, and has no value to name.
void refuse_repeated_silo_options(const CLI::App& parser, const std::vector<std::string>& options,
                                  const std::string& owner) {
    std::map<const CLI::Option*, std::vector<std::string>> given;
    for (std::size_t i = 0; i < options.size(); ++i) {
        const std::string& arg = options[i];
        if (arg.size() < 3 || arg.rfind("--", 0) != 0) continue;
        const std::string name = arg.substr(0, arg.find('='));
        const CLI::Option* opt = parser.get_option_no_throw(name);
        if (!opt || opt->get_expected_max() == 0 || opt->get_type_size_max() == 0) continue;
        const std::string value = name.size() < arg.size() ? arg.substr(name.size() + 1)
                                  : i + 1 < options.size() ? options[i + 1]
                                                           : "";
        try {
            refuse_repeated_option(*opt, value, given[opt]);
        } catch (const UserError& e) {
            throw UserError("silo options of " + owner + ": " + e.what());
        }
    }
}

}  // namespace

ks::SiloCaseSettings silo_case_settings(const std::vector<std::string>& options, const std::string& owner) {
    SiloCli o;
    const auto parser_owned = silo_options_parser(o, "the silo options of " + owner);
    CLI::App& parser = *parser_owned;
    refuse_repeated_silo_options(parser, options, owner);
    std::vector<std::string> reversed(options.rbegin(), options.rend());  // CLI11 takes them last first
    try {
        parser.parse(reversed);
    } catch (const CLI::Success&) {  // -h after --: CLI11's own text said "This should be caught in your main function"
        throw UserError("silo options of " + owner + ": -h/--help after --: `demcal silo --help` lists the silo "
                        "options, `demcal " + owner.substr(owner.rfind(' ') + 1) + " --help` this command's");
    } catch (const CLI::ParseError& e) {
        throw UserError("silo options of " + owner + ": " + e.what());
    }
    // what only a `demcal silo` run of its own has: its outputs, its sessions
    for (const char* own : {"--out", "--vtk", "--vtk-every", "--export-bed", "--export-final-bed", "--export-cloud", "--no-plots", "--checkpoint-every",
                            "--no-checkpoint", "--check", "--wall-limit", "--resume"})
        if (parser.count(own))
            throw UserError(std::string("silo option ") + own + " does not apply to " + owner +
                            " (it runs the silo case itself and writes its own outputs)");
    return settings_from(o, parser);
}

nlohmann::json canonical_silo_options(const std::vector<std::string>& options) {
    SiloCli o;  // (demcal silo's rules: a value they refuse, an octal-looking "0400", gets no canonical form that
    const auto parser = silo_options_parser(o, "silo options");  // could equal another's)
    std::vector<std::string> reversed(options.rbegin(), options.rend());  // CLI11 takes them last first
    try {
        parser->parse(reversed);
    } catch (const std::exception&) {  // (CLI11's errors, a rule's UserError)
        return options;  // (refused elsewhere with its message): the text as given
    }
    // one spelling per value: a number by its value (1e-3 and 0.001); a file not by its path (relative, absolute or
    // through a link): the campaigns compare its contents' digest (silo_input_file_digests)
    const auto value_key = [](const std::string& option, const std::string& value) -> std::string {
        if (std::count(kSiloFileOptions.begin(), kSiloFileOptions.end(), option))
            return "(a file: its contents are compared by digest)";
        char* end = nullptr;
        const double number = std::strtod(value.c_str(), &end);
        if (!value.empty() && end && *end == '\0') return silo_number(number);
        return value;
    };
    nlohmann::json canonical = nlohmann::json::object();  // (sorted by option name)
    for (const CLI::Option* opt : parser->get_options()) {
        if (opt->count() == 0 || opt->get_name().empty()) continue;
        const std::string name = opt->get_name(false, true);  // the long name, whichever spelling was typed
        nlohmann::json values = nlohmann::json::array();
        for (const std::string& v : opt->results()) values.push_back(value_key(name, v));
        canonical[name] = values;
    }
    return canonical;
}

void add_silo_command(CLI::App& app) {
    auto o = std::make_shared<SiloCli>();
    CLI::App* sub = app.add_subcommand(
        "silo",
        "The seed's silo case on the native DEM kernel: wheat grains generated in the silo, filled against a closed "
        "outlet, then discharged; writes discharge.csv, summary.json (rate, flow pattern), section.png");
    add_silo_options(sub, *o);
    sub->callback([o, sub] {
        if (sub->count("--resume")) resume_silo(*o, *sub);
        else run_silo(*o, *sub);
    });
}

}  // namespace demcal
