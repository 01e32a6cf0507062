// demcal crosscheck silo: for each cone angle the kernel fills the silo and discharges it (`demcal silo`), writing its
// bed at the opening (--export-bed); YADE (yade_scripts/silo.py) discharges that very bed. The two discharges side
// by side: rate with its uncertainty, time to empty, mass-time curves on one plot per angle and their largest gap,
// wall and CPU time of each code and their ratio, and the differences YADE cannot remove with their expected effect.
// --fill own / both: YADE fills the silo itself from the kernel's generated cloud (--export-cloud) instead / as well,
// so the filling's share of the difference is measured. Runs are subprocesses of the orchestrator's local pool
// (timeouts, kill on Ctrl-C) or SLURM array tasks, kept in the campaign store DIR/campaign.sqlite (state, result,
// timings, every attempt; `demcal status DIR` lists them): a run whose inputs did not change is reused, so the same
// command continues an interrupted check.
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/silo_material.hpp"
#include "app/silo_flow_pattern.hpp"
#include "app/silo_settings.hpp"
#include "app/gnuplot.hpp"
#include "analytics/user_input.hpp"
#include "orchestrator/campaign_directory.hpp"
#include "orchestrator/executor.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"
#include "orchestrator/slurm_executor.hpp"
#include "orchestrator/stored_jobs.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <thread>

namespace demcal {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Which beds YADE discharges: the kernel's filled bed (the discharges compared alone), a bed YADE fills itself from the
// kernel's generated cloud (filling and discharge compared), or both (the filling's share of the difference).
enum class FillMode { same_bed, own, both };
const std::map<std::string, FillMode> kFillModes = {
    {"same-bed", FillMode::same_bed}, {"own", FillMode::own}, {"both", FillMode::both}};

struct SiloCrosscheckOptions {
    std::vector<double> thetas{10, 30, 50, 70};
    int particles = 4000;
    double stiffness_scale = 1e-3;
    std::string material, geometry;
    std::string yade_material;  // a different material for YADE on purpose (a mismatch the report must flag)
    double tolerance = 0.05;    // rates agree when YADE / kernel lies within 1 +/- this
    long seed = 1;
    double max_time = 10;
    std::string dir = "campaigns/crosscheck-silo";
    int jobs = 0;
    std::string executor = "local", partition;  // local | slurm (array tasks), SLURM partition
    double timeout_s = 7200;
    std::string yade = "yade";
    std::string plot_format = "png";
    long max_runs = 10000;
    std::string fill_text = "same-bed";  // same-bed | own | both (checked by the option)
    FillMode fill() const { return kFillModes.at(fill_text); }
};

// A YADE run of one angle: its folder, the bed file it starts from, and whether it fills first.
struct YadeRunKind {
    const char* folder;
    const char* bed_file;
    bool fills;
    const char* label;
};
constexpr YadeRunKind kYadeSameBed{"yade", "bed.json", false, "YADE from the kernel's filled bed"};
constexpr YadeRunKind kYadeOwnFill{"yade-own-fill", "cloud.json", true,
                                   "YADE filling on its own from the kernel's generated cloud"};

std::vector<YadeRunKind> yade_runs(FillMode mode) {
    switch (mode) {
        case FillMode::same_bed: return {kYadeSameBed};
        case FillMode::own: return {kYadeOwnFill};
        case FillMode::both: return {kYadeSameBed, kYadeOwnFill};
    }
    return {};
}

constexpr const char* kYadeFramesFile = "frames.bin";

// The differences between the two codes' set-ups that YADE cannot remove (yade_scripts/README.md measures them).
const char* const kKnownDifferences[] = {
    "rolling friction: YADE has no EDEM-type constant directional torque; its elastic-plastic rolling moment "
    "(run.rolling_moment) is a different law (measured on a 30 deg bed: +2.6 % on the rate against none). YADE runs "
    "without rolling resistance by default: at 10 deg (4000 grains) YADE / kernel was 1.064 and 1.087 on two beds, "
    "1.032 with rolling friction 0 in both codes (examples/crosscheck/README.md)",
    "tangential spring: YADE's Mindlin law is incremental, the kernel's a rotated history spring (same stiffness)",
    "YADE clips the normal force at zero in a separating contact; the kernel does not (a very small effect at "
    "restitution 0.5-0.6)",
    "integrators: YADE's leapfrog with its aspherical rotation for clumps, the kernel's velocity Verlet with a "
    "Richardson quaternion update",
    "walls: YADE's cone and cylinder are facet polygons (72 sides), the kernel's are exact surfaces of revolution",
};

std::string g(double v, int digits = 4) {
    std::ostringstream o;
    o << std::setprecision(digits) << v;
    return o.str();
}

std::string theta_name(double theta) {
    std::ostringstream o;
    o << "theta_" << theta;
    return o.str();
}

std::vector<std::string> kernel_argv(const SiloCrosscheckOptions& o, double theta, const fs::path& out,
                                     const fs::path& bed, const std::string& self) {
    std::vector<std::string> a = {self,        "silo",          "--theta",         g(theta, 10),
                                  "--particles", std::to_string(o.particles), "--stiffness-scale", g(o.stiffness_scale, 17),
                                  "--seed",    std::to_string(o.seed),         "--max-time",      g(o.max_time, 17),
                                  "--threads", "1",              "--no-plots",      "--no-checkpoint",
                                  "--out",     out.string(),     "--export-bed",    bed.string(),
                                  "--export-cloud", (bed.parent_path() / "cloud.json").string()};
    if (!o.material.empty()) a.insert(a.end(), {"--material", fs::absolute(o.material).string()});
    if (!o.geometry.empty()) a.insert(a.end(), {"--geometry", fs::absolute(o.geometry).string()});
    return a;
}

// yade_scripts/silo.py's params for the bed the kernel wrote: its geometry and material, the kernel's run settings.
json yade_params(const json& bed, const SiloCrosscheckOptions& o, const json& yade_material, const YadeRunKind& kind) {
    json geometry = json::object();
    for (const char* k : {"shape", "theta_deg", "outlet_m", "D_m", "body_height_m"}) geometry[k] = bed.at("geometry").at(k);
    json params = {{"bed_file", std::string("../") + kind.bed_file},
                   {"geometry", geometry},
                   {"material", yade_material.is_null() ? bed.at("material") : yade_material},
                   {"run",
                    {{"stiffness_scale", bed.at("stiffness_scale")},
                     {"time_step_fraction", bed.at("time_step_fraction")},
                     {"discharge_time_s", o.max_time},
                     {"sample_interval_s", bed.at("record_interval_s")},
                     {"removal_depth_m", bed.at("removal_depth_m")},
                     // YADE's flow-pattern frames at the kernel's interval, classified here by the kernel's classifier
                     {"frame_interval_s", bed.at("flow_pattern_sampling").at("frame_interval_s")},
                     {"frames_file", kYadeFramesFile}}}};
    if (kind.fills) params["run"]["fill"] = 1;  // silo.py's default is 0: a same-bed run's params stay as they were
    return params;
}

// YADE's flow pattern: its frames through the kernel's classifier with the kernel's sampling (from the bed).
json yade_flow_pattern(const fs::path& dir, const json& bed, const json& yade_result) {  // dir: the YADE run's
    try {
        const FlowPatternSampling sampling =
            flow_pattern_sampling_from_json(bed.at("flow_pattern_sampling"), "bed of " + dir.string());
        const json& geometry = bed.at("geometry");
        const auto silo = kernel::silo::SiloGeometry::conical(
            geometry.at("theta_deg").get<double>(), geometry.at("outlet_m").get<double>(),
            geometry.at("D_m").get<double>(), geometry.at("body_height_m").get<double>());
        return flow_pattern_json(flow_pattern_of_frames(dir / kYadeFramesFile, silo, sampling,
                                                        yade_result.at("initial_mass_kg").get<double>(),
                                                        yade_result.at("discharged_mass_kg").get<double>()));
    } catch (const std::exception& e) {
        return {{"pattern", "undetermined"}, {"wall_to_axis_velocity_ratio", 0.0}, {"message", e.what()}};
    }
}

struct CurvePoint {
    double t, mass;
};
std::vector<CurvePoint> kernel_curve(const fs::path& csv) {
    std::vector<CurvePoint> c;
    std::ifstream f(csv);
    std::string line;
    std::getline(f, line);  // header
    while (std::getline(f, line)) {
        std::istringstream s(line);
        double t = 0, m = 0;
        char comma = 0;
        if (s >> t >> comma >> m) c.push_back({t, m});
    }
    return c;
}
std::vector<CurvePoint> yade_curve(const json& result) {
    std::vector<CurvePoint> c;
    const auto& t = result.at("curve").at("time_s");
    const auto& m = result.at("curve").at("discharged_mass_kg");
    for (std::size_t i = 0; i < t.size(); ++i) c.push_back({t[i].get<double>(), m[i].get<double>()});
    return c;
}
double mass_at(const std::vector<CurvePoint>& c, double t) {
    if (c.empty()) return 0;
    if (t <= c.front().t) return c.front().mass;
    if (t >= c.back().t) return c.back().mass;
    const auto it = std::lower_bound(c.begin(), c.end(), t, [](const CurvePoint& p, double x) { return p.t < x; });
    const CurvePoint& b = *it;
    const CurvePoint& a = *(it - 1);
    return a.mass + (b.mass - a.mass) * (t - a.t) / (b.t - a.t);
}
// The largest gap between the curves at the kernel's recorded times, as a fraction of the filled mass.
double largest_gap(const std::vector<CurvePoint>& k, const std::vector<CurvePoint>& y, double filled) {
    double gap = 0;
    const double t_end = std::min(k.empty() ? 0 : k.back().t, y.empty() ? 0 : y.back().t);
    for (const auto& p : k)
        if (p.t <= t_end) gap = std::max(gap, std::abs(p.mass - mass_at(y, p.t)));
    return filled > 0 ? gap / filled : 0;
}

// `own`: YADE's discharge of the bed it filled itself (--fill both), drawn when not empty.
void write_curve_plot(const fs::path& dir, double theta, const std::vector<CurvePoint>& k,
                      const std::vector<CurvePoint>& y, const std::vector<CurvePoint>& own, const std::string& format) {
    const fs::path data_k = dir / "curve_kernel.dat", data_y = dir / "curve_yade.dat",
                   data_own = dir / "curve_yade_own_fill.dat";
    std::ofstream fk(data_k), fy(data_y);
    for (const auto& p : k) fk << p.t << " " << p.mass * 1e3 << "\n";
    for (const auto& p : y) fy << p.t << " " << p.mass * 1e3 << "\n";
    fk.close();
    fy.close();
    if (!own.empty()) {
        std::ofstream fo(data_own);
        for (const auto& p : own) fo << p.t << " " << p.mass * 1e3 << "\n";
    }
    std::ostringstream s;
    s << "set title 'Discharged mass, cone half angle " << theta << " deg'\n"
      << "set xlabel 'time since opening [s]'\nset ylabel 'discharged mass [g]'\nset key top left\nset grid\n"
      << "plot " << gnuplot_quote(data_k) << " using 1:2 with lines lw 2 title 'demcal kernel', "
      << gnuplot_quote(data_y) << " using 1:2 with lines lw 2 dt 2 title 'YADE 2023.02a'";
    if (!own.empty()) s << ", " << gnuplot_quote(data_own) << " using 1:2 with lines lw 2 dt 3 title 'YADE, its own filling'";
    s << "\n";
    render_gnuplot(dir / ("mass_time." + format), s.str());
}

// The kernel run of one angle checked by demcal silo's own parser and checks (silo_case_settings), before the
// campaign folder exists: a setting the silo refuses (a material, a time limit, a particle count) was found only once
// the runs had started. The run's outputs and sessions (--out, --export-bed, --no-plots, --no-checkpoint) are this
// command's (--export-cloud too): the settings alone are checked.
void check_kernel_run(const SiloCrosscheckOptions& o, double theta) {
    const std::vector<std::string> argv = kernel_argv(o, theta, "out", "bed.json", "demcal");
    std::vector<std::string> settings;
    for (std::size_t i = 2; i < argv.size(); ++i) {  // after the program and "silo"
        if (argv[i] == "--out" || argv[i] == "--export-bed" || argv[i] == "--export-cloud") ++i;
        else if (argv[i] != "--no-plots" && argv[i] != "--no-checkpoint") settings.push_back(argv[i]);
    }
    try {
        silo_case_settings(settings, "demcal crosscheck silo");
    } catch (const std::exception& e) {
        throw UserError("theta = " + g(theta) + ": the kernel run refuses its settings: " + e.what());
    }
}

int run_silo_crosscheck(const SiloCrosscheckOptions& o) {
    if (o.thetas.empty()) throw UserError("theta: give at least one cone half angle");
    for (std::size_t i = 0; i < o.thetas.size(); ++i) {
        const double t = o.thetas[i];
        if (!(t > 0 && t < 90)) throw UserError("theta = " + g(t) + " deg must lie in (0, 90)");
        // one folder per angle: a repeated angle would run twice into it
        if (std::find(o.thetas.begin(), o.thetas.begin() + i, t) != o.thetas.begin() + i)
            throw UserError("theta = " + g(t) + " deg is given twice");
    }
    const double runs_per_angle = 1.0 + static_cast<double>(yade_runs(o.fill()).size());
    orchestrator::check_run_count(runs_per_angle * static_cast<double>(o.thetas.size()), o.max_runs,
                                  "crosscheck silo: " + std::to_string(o.thetas.size()) + " angles x " +
                                      g(runs_per_angle) + " runs");
    if (!(o.tolerance > 0 && o.tolerance < 1)) throw UserError("tolerance = " + g(o.tolerance) + " must lie in (0, 1)");
    check_output_folder(o.dir, "--campaign");
    const fs::path script = orchestrator::default_shear_template().parent_path() / "silo.py";
    const fs::path wrapper = orchestrator::default_shear_template().parent_path() / "run_clean.py";
    if (!fs::is_regular_file(script)) throw UserError("yade_scripts/silo.py not found at " + script.string());
    const std::string yade = orchestrator::find_yade(o.yade).string();
    std::error_code ec;
    const std::string self = fs::read_symlink("/proc/self/exe", ec).string();
    if (ec) throw std::runtime_error("cannot find this program's own path (/proc/self/exe)");
    // refused early, named; YADE's Hertz-Mindlin has no JKR cohesion, so a cohesive material has no YADE twin
    for (const auto& [option, file] : {std::pair<std::string, std::string>{"--material", o.material},
                                       {"--yade-material", o.yade_material}})
        if (!file.empty() && read_silo_material(file).cohesive())
            throw UserError(option + " = " + file + ": a cohesive material (surface_energy_J_m2 > 0): yade_scripts/silo.py "
                            "has no JKR cohesion to match the kernel's; cross-check cohesionless materials");
    if (!o.geometry.empty()) analytics::read_json_input(o.geometry, "geometry");
    const json yade_material = o.yade_material.empty() ? json() : analytics::read_json_input(o.yade_material, "yade-material");
    for (double theta : o.thetas) check_kernel_run(o, theta);
    // the campaign directory: its lock and its store (runs, states, results, attempts), stale runs recovered
    orchestrator::CampaignDirectory campaign(o.dir, orchestrator::stored_job_result);
    const fs::path root = campaign.dir();
    orchestrator::CampaignStore& store = campaign.store();
    const json spec = {{"thetas", o.thetas},
                       {"particles", o.particles},
                       {"stiffness_scale", o.stiffness_scale},
                       {"seed", o.seed},
                       {"max_time_s", o.max_time},
                       {"material", o.material},
                       {"geometry", o.geometry},
                       {"yade_material", o.yade_material},
                       {"fill", o.fill_text}};
    const std::int64_t campaign_id =
        store.ensure_campaign("crosscheck-silo-" + orchestrator::sha256_hex(spec.dump()).substr(0, 12),
                              "crosscheck_silo", spec)
            .id;
    // the kernel runs start a copy of this program kept in the campaign: a rebuild while they run (or wait in a SLURM
    // queue) neither fails them nor mixes two builds
    const std::string program = orchestrator::pinned_program(self, root / ".program");
    const std::string script_text = orchestrator::read_text_file(script);
    const int slots = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
    const auto executor = orchestrator::make_executor(o.executor, slots, root / "slurm", o.partition);
    auto run_stage = [&](const std::vector<orchestrator::StoredJob>& jobs) {
        const auto out = orchestrator::run_stored_jobs(
            store, campaign_id, jobs, *executor,
            [](const std::string& event, const orchestrator::StoredJob& job, const std::string& detail) {
                std::cout << std::left << std::setw(9) << event << job.name
                          << (detail.empty() ? "" : " (" + detail + ")") << std::endl;
            });
        return !out.interrupted;
    };
    auto file_hash = [](const std::string& file) {
        return file.empty() ? std::string() : orchestrator::sha256_hex(orchestrator::read_text_file(file));
    };

    // 1. the kernel fills and discharges at every angle, writing its generated cloud and its bed at the opening
    std::vector<orchestrator::StoredJob> jobs;
    for (double theta : o.thetas) {
        const fs::path d = root / theta_name(theta);
        fs::create_directories(d / "kernel");
        // the identity: what the run computes, without paths (a campaign moved elsewhere keeps its runs)
        const json params = {{"code", "kernel"},
                             {"what", "demcal silo, its bed at the opening and its generated cloud exported"},
                             {"theta_deg", theta},
                             {"particles", o.particles},
                             {"stiffness_scale", o.stiffness_scale},
                             {"seed", o.seed},
                             {"max_time_s", o.max_time},
                             {"material_sha256", file_hash(o.material)},
                             {"geometry_sha256", file_hash(o.geometry)}};
        auto job = orchestrator::stored_job(theta_name(theta) + " kernel", params,
                                            {{"theta_deg", theta}, {"code", "kernel"}}, d / "kernel",
                                            kernel_argv(o, theta, d / "kernel", d / "bed.json", program),
                                            "summary.json", o.timeout_s);
        job.outputs = {d / "bed.json", d / "cloud.json"};
        jobs.push_back(std::move(job));
    }
    if (!run_stage(jobs)) {
        std::cout << "interrupted: run the same command again to continue\n";
        return 130;
    }

    // 2. YADE discharges each bed (and, with --fill own/both, fills the silo from the kernel's cloud first)
    jobs.clear();
    for (double theta : o.thetas)
        for (const YadeRunKind& kind : yade_runs(o.fill())) {
            const fs::path d = root / theta_name(theta), run = d / kind.folder;
            if (!fs::exists(d / kind.bed_file) || !fs::exists(d / "kernel" / "summary.json")) continue;
            const json bed = analytics::read_json_input(d / kind.bed_file, "bed");
            const json params = yade_params(bed, o, yade_material, kind);
            fs::create_directories(run);
            orchestrator::write_text_file_atomically(run / "params.json", params.dump(1) + "\n");
            orchestrator::write_text_file_atomically(run / "silo.py", script_text);
            orchestrator::write_text_file_atomically(run / "run_clean.py", orchestrator::read_text_file(wrapper));
            const json identity = {{"code", "yade"},
                                   {"run", kind.folder},
                                   {"script_sha256", orchestrator::sha256_hex(script_text)},
                                   {"params", params},
                                   {"bed_sha256", file_hash((d / kind.bed_file).string())}};
            jobs.push_back(orchestrator::stored_job(
                theta_name(theta) + " " + kind.folder, identity, {{"theta_deg", theta}, {"code", kind.folder}}, run,
                {yade, "-n", "-j1", "-x", "run_clean.py", "silo.py", "params.json", "result.json"}, "result.json",
                o.timeout_s));
        }
    if (!run_stage(jobs)) {
        std::cout << "interrupted: run the same command again to continue\n";
        return 130;
    }

    {
        const auto runs = store.campaign_runs(campaign_id);
        const bool all_done = std::all_of(runs.begin(), runs.end(), [](const orchestrator::RunRecord& r) {
            return r.state == orchestrator::RunState::done;
        });
        const bool any_failed = std::any_of(runs.begin(), runs.end(), [](const orchestrator::RunRecord& r) {
            return r.state == orchestrator::RunState::failed;
        });
        store.set_campaign_status(campaign_id, all_done ? "complete" : any_failed ? "failed" : "open");
    }

    // 3. side by side
    json report = {{"thetas", o.thetas},
                   {"particles", o.particles},
                   {"stiffness_scale", o.stiffness_scale},
                   {"seed", o.seed},
                   {"angles", json::array()},
                   {"known_differences", json::array()}};
    for (const char* d : kKnownDifferences) report["known_differences"].push_back(d);
    report["tolerance"] = o.tolerance;
    if (!yade_material.is_null()) report["yade_material"] = yade_material;
    std::ostringstream md;
    md << "| theta [deg] | kernel rate [g/s] (batch SE) | YADE rate [g/s] (slope SE) | YADE / kernel | rates | kernel empty [s] | "
          "YADE empty [s] | kernel pattern (wall/axis) | YADE pattern (wall/axis) | largest curve gap [% of fill] | "
          "kernel CPU [s] | YADE CPU [s] | YADE / kernel CPU |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    bool complete = true, all_agree = true, all_patterns_agree = true, all_patterns_determined = true;
    const YadeRunKind primary = yade_runs(o.fill()).front();
    std::ostringstream own_fill_md;  // --fill both: the filling's share, a table of its own
    for (double theta : o.thetas) {
        const fs::path d = root / theta_name(theta);
        if (!fs::exists(d / "kernel" / "summary.json") || !fs::exists(d / primary.folder / "result.json")) {
            md << "| " << theta << " | (a run failed: see " << d.string() << ") ||||||||||\n";
            complete = false;
            continue;
        }
        const json k = analytics::read_json_input(d / "kernel" / "summary.json", "kernel summary");
        const json y = analytics::read_json_input(d / primary.folder / "result.json", "yade result");
        const double kr = k.at("rate").at("rate_kg_s").get<double>(), yr = y.at("rate").at("rate_kg_s").get<double>();
        const auto kc = kernel_curve(d / "kernel" / "discharge.csv");
        const auto yc = yade_curve(y);
        const double filled = k.at("filled_mass_kg").get<double>();
        const double gap = largest_gap(kc, yc, filled);
        const double kcpu = k.at("cpu_s").get<double>(), ycpu = y.at("cpu_time_s").get<double>();
        const json& pattern = k.at("flow_pattern");
        const json yade_pattern =
            yade_flow_pattern(d / primary.folder, analytics::read_json_input(d / primary.bed_file, "bed"), y);
        const bool agree = std::abs(yr / kr - 1) <= o.tolerance;
        // compared only where both codes determined a pattern (too few grains leave a hopper height without samples)
        const bool patterns_determined =
            pattern.value("pattern", "undetermined") != "undetermined" &&
            yade_pattern.value("pattern", "undetermined") != "undetermined";
        const bool patterns_agree =
            patterns_determined && pattern.value("pattern", "") == yade_pattern.value("pattern", "");
        all_agree = all_agree && agree;
        all_patterns_agree = all_patterns_agree && (patterns_agree || !patterns_determined);
        all_patterns_determined = all_patterns_determined && patterns_determined;
        md << "| " << theta << " | " << g(kr * 1e3) << " (" << g(k["rate"].value("rate_batch_se_kg_s", 0.0) * 1e3, 2)
           << ") | " << g(yr * 1e3) << " (" << g(y["rate"].value("rate_se_kg_s", 0.0) * 1e3, 2) << ") | "
           << g(yr / kr, 4) << " | " << (agree ? "agree" : "**DIFFER**") << " | "
           << g(k.at("discharge").at("time_s").get<double>(), 3) << " | "
           << g(y.at("discharge_time_s").get<double>(), 3) << " | " << pattern.value("pattern", "?") << " ("
           << g(pattern.value("wall_to_axis_velocity_ratio", 0.0), 2) << ") | "
           << (patterns_determined && !patterns_agree ? "**" : "") << yade_pattern.value("pattern", "?") << " ("
           << g(yade_pattern.value("wall_to_axis_velocity_ratio", 0.0), 2) << ")"
           << (patterns_determined && !patterns_agree ? "**" : "")
           << " | " << g(100 * gap, 2) << " | "
           << g(kcpu, 3) << " | " << g(ycpu, 3) << " | " << g(ycpu / kcpu, 3) << " |\n";
        report["angles"].push_back({{"theta_deg", theta},
                                    {"kernel", {{"rate_kg_s", kr},
                                                {"rate_batch_se_kg_s", k["rate"].value("rate_batch_se_kg_s", 0.0)},
                                                {"time_to_empty_s", k.at("discharge").at("time_s")},
                                                {"flow_pattern", pattern},
                                                {"cpu_s", kcpu},
                                                {"wall_s", k.at("wall_s")}}},
                                    {"yade", {{"rate_kg_s", yr},
                                              {"rate_se_kg_s", y["rate"].value("rate_se_kg_s", 0.0)},
                                              {"time_to_empty_s", y.at("discharge_time_s")},
                                              {"stop_reason", y.at("stop_reason")},
                                              {"flow_pattern", yade_pattern},
                                              {"cpu_s", ycpu},
                                              {"wall_s", y.at("wall_time_s")},
                                              {"started_from", primary.label}}},
                                    {"rate_ratio_yade_over_kernel", yr / kr},
                                    {"rates_agree", agree},
                                    {"patterns_agree", patterns_determined ? json(patterns_agree) : json(nullptr)},
                                    {"yade_material_as_bed", y.value("material_as_bed", true)},
                                    {"largest_curve_gap_of_filled_mass", gap},
                                    {"cpu_ratio_yade_over_kernel", ycpu / kcpu}});
        std::vector<CurvePoint> own_curve;
        if (o.fill() == FillMode::both) {
            const fs::path own = d / kYadeOwnFill.folder / "result.json";
            if (!fs::exists(own)) {
                own_fill_md << "| " << theta << " | (YADE's own filling failed: see " << own.parent_path().string()
                            << ") ||||||||\n";
                complete = false;
            } else {
                const json yo = analytics::read_json_input(own, "yade own-fill result");
                const double yor = yo.at("rate").at("rate_kg_s").get<double>();
                own_curve = yade_curve(yo);
                const json& yf = yo.at("fill");
                const json& kf = k.at("fill");
                // the filling's share of the rate difference: what YADE's own bed adds to the ratio of the same bed
                const double share = yor / kr - yr / kr;
                const json own_pattern = yade_flow_pattern(
                    d / kYadeOwnFill.folder, analytics::read_json_input(d / kYadeOwnFill.bed_file, "cloud"), yo);
                own_fill_md << "| " << theta << " | " << g(kr * 1e3) << " | " << g(yor * 1e3) << " | "
                            << g(yor / kr, 4) << " | " << g(yr / kr, 4) << " | " << std::showpos << g(100 * share, 2)
                            << std::noshowpos << " | " << g(kf.at("time_s").get<double>(), 3) << " / "
                            << g(yf.at("time_s").get<double>(), 3) << " | "
                            << g(kf.at("height_m").get<double>() * 1e3, 4) << " / "
                            << g(yf.at("bed_height_m").get<double>() * 1e3, 4) << " | "
                            << own_pattern.value("pattern", "?") << " ("
                            << g(own_pattern.value("wall_to_axis_velocity_ratio", 0.0), 2) << ") | "
                            << g(yo.at("cpu_time_s").get<double>(), 3) << " |\n";
                report["angles"].back()["yade_own_fill"] = {
                    {"rate_kg_s", yor},
                    {"rate_ratio_yade_over_kernel", yor / kr},
                    {"filling_share_of_rate_ratio", share},
                    {"fill", yf},
                    {"kernel_fill", kf},
                    {"time_to_empty_s", yo.at("discharge_time_s")},
                    {"flow_pattern", own_pattern},
                    {"cpu_s", yo.at("cpu_time_s")},
                    {"largest_curve_gap_of_filled_mass", largest_gap(kc, own_curve, filled)}};
            }
        }
        try {
            write_curve_plot(d, theta, kc, yc, own_curve, o.plot_format);
        } catch (const std::exception& e) {
            std::cerr << "demcal: warning: plot not written: " << e.what() << "\n";
        }
    }
    md << "\nRates agree when YADE / kernel lies within 1 +/- " << g(o.tolerance)
       << (all_agree ? ": they do at every angle." : ": **they do not at every angle**.");
    if (!yade_material.is_null())
        md << " YADE ran a different material on purpose (--yade-material " << o.yade_material << ").";
    md << " Flow patterns: YADE's frames (at the kernel's frame interval) classified by the kernel's own "
          "classifier with the kernel's settings; "
       << (!all_patterns_agree            ? "**not the same at every angle** (marked)."
           : all_patterns_determined      ? "the same at every angle."
                                          : "the same wherever both were determined (see each report's message for "
                                            "the others).")
       << "\n\nDifferences YADE cannot remove (yade_scripts/README.md):\n";
    for (const char* d : kKnownDifferences) md << "- " << d << "\n";
    if (o.fill() == FillMode::both)
        md << "\n## Each code fills on its own\n\nYADE fills the silo itself from the kernel's generated cloud (the same "
              "grains, positions and orientations before the first filling step; the kernel's rest rule), then "
              "discharges. The filling's share of the difference is YADE's own-fill rate over the kernel's minus the "
              "same-bed ratio.\n\n| theta [deg] | kernel rate [g/s] | YADE own fill [g/s] | YADE own fill / kernel | "
              "YADE same bed / kernel | filling's share [% of the kernel's rate] | fill time kernel / YADE [s] | "
              "bed height kernel / YADE [mm] | YADE own fill pattern (wall/axis) | YADE own fill CPU [s] |\n"
              "|---|---|---|---|---|---|---|---|---|---|\n"
           << own_fill_md.str();
    report["fill_mode"] = o.fill_text;
    report["rates_agree"] = all_agree;
    report["patterns_agree"] = all_patterns_agree;  // at every angle where both codes determined one
    report["patterns_determined"] = all_patterns_determined;
    orchestrator::write_text_file_atomically(root / "crosscheck_silo.json", report.dump(2) + "\n");
    orchestrator::write_text_file_atomically(root / "crosscheck_silo.md", md.str());
    std::cout << "\n" << md.str() << "\nresults: " << (root / "crosscheck_silo.json").string() << ", "
              << (root / "crosscheck_silo.md").string() << ", <theta>/mass_time." << o.plot_format << "\n";
    return complete ? 0 : 1;
}

}  // namespace

void add_crosscheck_silo_subcommand(CLI::App& crosscheck) {
    auto o = std::make_shared<SiloCrosscheckOptions>();
    auto* silo = crosscheck.add_subcommand(
        "silo", "the kernel fills and discharges the silo, YADE discharges the same bed: rates, curves, time");
    silo->add_option("--theta", o->thetas, "cone half angles [deg]")->delimiter(',')->capture_default_str();
    silo->add_option("--particles", o->particles, "grains")->check(integer_in(10, 1000000))->capture_default_str();
    silo->add_option("--stiffness-scale", o->stiffness_scale, "shear moduli x this (both codes)")
        ->check(positive_number())
        ->capture_default_str();
    silo->add_option("--material", o->material, "silo material file (default: the seed's wheat)");
    silo->add_option("--geometry", o->geometry, "silo geometry file (default: the seed's 105 mm silo)");
    silo->add_option("--yade-material", o->yade_material,
                     "a different silo material for YADE on purpose (to see a mismatch flagged); default: the bed's");
    silo->add_option("--tolerance", o->tolerance, "rates agree within YADE/kernel = 1 +/- this")->capture_default_str();
    silo->add_option("--seed", o->seed, "filling seed")->check(integer_in(0, 2147483647));
    silo->add_option("--max-time", o->max_time, "discharge time limit [s]")->check(positive_number())->capture_default_str();
    silo->add_option("--campaign,-c", o->dir, "output directory (runs reused from it)")->capture_default_str();
    silo->add_option("--jobs,-j", o->jobs, "runs in parallel (0 = one per core)")->check(non_negative_number());
    silo->add_option("--timeout", o->timeout_s, "per-run wall-clock limit [s]")->check(positive_number());
    silo->add_option("--executor", o->executor, "local (processes of this machine) or slurm (job arrays)")
        ->check(CLI::IsMember({"local", "slurm"}))
        ->capture_default_str();
    silo->add_option("--partition", o->partition, "SLURM partition (--executor slurm)");
    silo->add_option("--yade", o->yade, "YADE launcher");
    silo->add_option("--plot", o->plot_format, "plot format")->check(CLI::IsMember({"png", "svg"}));
    silo->add_option("--fill", o->fill_text,
                     "same-bed: YADE discharges the kernel's filled bed; own: YADE fills the silo itself from the "
                     "kernel's generated cloud, then discharges; both: the two, and the filling's share of the "
                     "difference")
        ->check(CLI::IsMember({"same-bed", "own", "both"}))
        ->capture_default_str();
    silo->add_option("--max-runs", o->max_runs, "most runs this command may plan, 2 per angle (3 with --fill both; a guard against typos)")
        ->check(integer_in(1, 1000000000))
        ->capture_default_str();
    silo->callback([o] {
        const int code = run_silo_crosscheck(*o);
        if (code != 0) throw CLI::RuntimeError(code);
    });
}

}  // namespace demcal
