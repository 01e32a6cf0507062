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
#include "app/crosscheck_silo_report.hpp"
#include "app/commands.hpp"
#include "app/silo_material.hpp"
#include "app/silo_settings.hpp"
#include "kernel/silo/silo_case.hpp"
#include "analytics/user_input.hpp"
#include "analytics/number_text.hpp"
#include "orchestrator/campaign_directory.hpp"
#include "orchestrator/executor.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"
#include "orchestrator/slurm_executor.hpp"
#include "orchestrator/stored_jobs.hpp"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <thread>

namespace demcal {

namespace fs = std::filesystem;
using nlohmann::json;

using crosscheck_silo::kYadeOwnFill;
using crosscheck_silo::kYadeSameBed;
using crosscheck_silo::kYadeFramesFile;
using crosscheck_silo::YadeRunKind;

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
    std::string kernel_law = "edem";     // demcal silo --contact-law (a name of silo_contact_laws: the option checks)
    std::string kernel_rotation = "richardson";  // demcal silo --discharge-rotation (silo_clump_rotations)
    int wall_facets = 0;  // demcal silo --discharge-wall-facets and silo.py's run.facet_segments (0: exact / 72)
    bool start_as_yade_import = false;  // demcal silo --start-as-yade-import
    FillMode fill() const { return kFillModes.at(fill_text); }
    // an angle's folder and its kernel run's (names the options checked)
    std::string angle(double theta) const {
        return crosscheck_silo::angle_folder(theta, kernel::silo::silo_contact_laws().at(kernel_law));
    }
    std::string kernel_run() const {
        return crosscheck_silo::kernel_folder(kernel::silo::silo_clump_rotations().at(kernel_rotation), wall_facets,
                                              start_as_yade_import);
    }
};

std::vector<YadeRunKind> yade_runs(FillMode mode) {
    switch (mode) {
        case FillMode::same_bed: return {kYadeSameBed};
        case FillMode::own: return {kYadeOwnFill};
        case FillMode::both: return {kYadeSameBed, kYadeOwnFill};
    }
    return {};
}

std::string g(double v, int digits = 4) {
    std::ostringstream o;
    o << std::setprecision(digits) << v;
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
    if (o.kernel_law != "edem") a.insert(a.end(), {"--contact-law", o.kernel_law});
    if (o.kernel_rotation != "richardson") a.insert(a.end(), {"--discharge-rotation", o.kernel_rotation});
    if (o.wall_facets > 0) a.insert(a.end(), {"--discharge-wall-facets", std::to_string(o.wall_facets)});
    if (o.start_as_yade_import) a.push_back("--start-as-yade-import");
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
    // silo.py's default is 72 sides: a run on them keeps the identity it had before the choice
    if (o.wall_facets > 0 && o.wall_facets != 72) params["run"]["facet_segments"] = o.wall_facets;
    return params;
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
        // demcal silo names a refused setting by its option; the options this command passes under another name
        // are named as the user typed them here
        constexpr std::pair<const char*, const char*> kRenamed[] = {{"--discharge-wall-facets", "--wall-facets"},
                                                                    {"--contact-law", "--kernel-law"},
                                                                    {"--discharge-rotation", "--kernel-rotation"}};
        std::string message = e.what();
        for (const auto& [silo_option, own_option] : kRenamed)
            if (message.rfind(std::string(silo_option) + " = ", 0) == 0)
                message = own_option + message.substr(std::string(silo_option).size());
        throw UserError("--theta = " + g(theta) + ": the kernel run refuses its settings: " + message);
    }
}

// What the runs need beyond the options, found and checked before the campaign folder exists.
struct CrosscheckInputs {
    fs::path script, wrapper;  // yade_scripts/silo.py and its clean-exit wrapper
    std::string yade;          // the launcher found
    std::string self;          // this program
    json yade_material;        // null: YADE runs the bed's material
};

// Every refusal the options can earn, named, before anything is written.
CrosscheckInputs checked_inputs(const SiloCrosscheckOptions& o) {
    if (o.thetas.empty()) throw UserError("--theta: give at least one cone half angle");
    for (std::size_t i = 0; i < o.thetas.size(); ++i) {
        const double t = o.thetas[i];
        if (!(t > 0 && t < 90)) throw UserError("--theta = " + g(t) + " deg must lie in (0, 90)");
        // one folder per angle: a repeated angle, or two that its folder's name cannot tell apart, would run twice into it
        for (std::size_t k = 0; k < i; ++k)
            if (o.angle(o.thetas[k]) == o.angle(t))
                throw UserError("--theta = " + g(t) + " deg " + (o.thetas[k] == t ? "is given twice" : "shares its folder '" +
                                o.angle(t) + "' with theta = " + g(o.thetas[k]) + " deg; give angles further apart"));
    }
    const double runs_per_angle = 1.0 + static_cast<double>(yade_runs(o.fill()).size());
    orchestrator::check_run_count(runs_per_angle * static_cast<double>(o.thetas.size()), o.max_runs,
                                  "crosscheck silo: " + std::to_string(o.thetas.size()) + " angles x " +
                                      g(runs_per_angle) + " runs");
    if (!(o.tolerance > 0 && o.tolerance < 1)) throw UserError("--tolerance = " + g(o.tolerance) + " must lie in (0, 1)");
    check_output_folder(o.dir, "--campaign");
    CrosscheckInputs in;
    in.script = orchestrator::yade_script("silo.py");
    in.wrapper = orchestrator::yade_script("run_clean.py");
    in.yade = orchestrator::find_yade(o.yade).string();
    std::error_code ec;
    in.self = fs::read_symlink("/proc/self/exe", ec).string();
    if (ec) throw std::runtime_error("cannot find this program's own path (/proc/self/exe)");
    // refused early, named; YADE's Hertz-Mindlin has no JKR cohesion, so a cohesive material has no YADE twin
    for (const auto& [option, file] : {std::pair<std::string, std::string>{"--material", o.material},
                                       {"--yade-material", o.yade_material}})
        if (!file.empty() && read_silo_material(file, option.substr(2)).cohesive())
            throw UserError(option + " = " + file + ": a cohesive material (surface_energy_J_m2 > 0): yade_scripts/silo.py "
                            "has no JKR cohesion to match the kernel's; cross-check cohesionless materials");
    if (!o.geometry.empty()) {
        const json geometry = analytics::read_json_input(o.geometry, "--geometry");
        // yade_scripts/silo.py builds the conical silo only (its facet walls): a hopper would fail after the kernel's run
        if (geometry.is_object() && geometry.contains("shape") && geometry["shape"] != "conical")
            throw UserError("--geometry = '" + o.geometry + "': shape = " + analytics::json_value_text(geometry["shape"]) +
                            ": yade_scripts/silo.py builds the conical silo only; cross-check a conical geometry");
    }
    if (!o.yade_material.empty()) {
        in.yade_material = analytics::read_json_input(o.yade_material, "--yade-material");
        // the report says YADE ran a different material on purpose: the same one is a void option
        if (!o.material.empty() && in.yade_material == analytics::read_json_input(o.material, "--material"))
            throw UserError("--yade-material = '" + analytics::shortened_text(o.yade_material) +
                            "': the same material as --material; omit it (YADE runs the bed's material)");
    }
    for (double theta : o.thetas) check_kernel_run(o, theta);
    return in;
}

std::int64_t ensure_campaign(orchestrator::CampaignStore& store, const SiloCrosscheckOptions& o) {
    const json spec = {{"thetas", o.thetas},
                       {"particles", o.particles},
                       {"stiffness_scale", o.stiffness_scale},
                       {"seed", o.seed},
                       {"max_time_s", o.max_time},
                       {"material", o.material},
                       {"geometry", o.geometry},
                       {"yade_material", o.yade_material},
                       {"fill", o.fill_text}};
    return store
        .ensure_campaign("crosscheck-silo-" + orchestrator::sha256_hex(spec.dump()).substr(0, 12),
                         orchestrator::CampaignKind::crosscheck_silo, spec)
        .id;
}

std::string file_hash(const std::string& file) {
    return file.empty() ? std::string() : orchestrator::sha256_hex(orchestrator::read_text_file(file));
}

// Stage 1: the kernel fills and discharges at every angle, writing its generated cloud and its bed at the opening.
std::vector<orchestrator::StoredJob> kernel_jobs(const SiloCrosscheckOptions& o, const fs::path& root,
                                                 const std::string& program) {
    std::vector<orchestrator::StoredJob> jobs;
    for (double theta : o.thetas) {
        const fs::path d = root / o.angle(theta), kd = d / o.kernel_run();
        fs::create_directories(kd);
        // the identity: what the run computes, without paths (a campaign moved elsewhere keeps its runs)
        json params = {{"code", "kernel"},
                             {"what", "demcal silo, its bed at the opening and its generated cloud exported"},
                             {"theta_deg", theta},
                             {"particles", o.particles},
                             {"stiffness_scale", o.stiffness_scale},
                             {"seed", o.seed},
                             {"max_time_s", o.max_time},
                             {"material_sha256", file_hash(o.material)},
                             {"geometry_sha256", file_hash(o.geometry)}};
        // only when not the default: the runs of campaigns made before the choice keep their identity
        if (o.kernel_law != "edem") params["contact_law"] = o.kernel_law;
        if (o.kernel_rotation != "richardson") params["discharge_rotation"] = o.kernel_rotation;
        if (o.wall_facets > 0) params["discharge_wall_facets"] = o.wall_facets;
        if (o.start_as_yade_import) params["contacts_at_opening"] = "yade_import";
        auto job = orchestrator::stored_job(o.angle(theta) + " " + o.kernel_run(), params,
                                            {{"theta_deg", theta}, {"code", "kernel"}}, kd,
                                            kernel_argv(o, theta, kd, d / "bed.json", program),
                                            "summary.json", o.timeout_s);
        job.outputs = {d / "bed.json", d / "cloud.json"};
        jobs.push_back(std::move(job));
    }
    return jobs;
}

// Stage 2: YADE discharges each bed the kernel wrote (and, with --fill own/both, fills the silo from the kernel's
// cloud first); an angle whose kernel run failed has nothing for YADE.
std::vector<orchestrator::StoredJob> yade_jobs(const SiloCrosscheckOptions& o, const CrosscheckInputs& in,
                                               const fs::path& root) {
    const std::string script_text = orchestrator::read_text_file(in.script);
    const std::string wrapper_text = orchestrator::read_text_file(in.wrapper);
    std::vector<orchestrator::StoredJob> jobs;
    for (double theta : o.thetas)
        for (const YadeRunKind& kind : yade_runs(o.fill())) {
            const fs::path d = root / o.angle(theta), run = d / kind.folder;
            if (!fs::exists(d / kind.bed_file) || !fs::exists(d / o.kernel_run() / "summary.json")) continue;
            const json bed = analytics::read_json_input(d / kind.bed_file, "bed");
            const json params = yade_params(bed, o, in.yade_material, kind);
            fs::create_directories(run);
            orchestrator::write_text_file_atomically(run / "params.json", params.dump(1) + "\n");
            orchestrator::write_text_file_atomically(run / "silo.py", script_text);
            orchestrator::write_text_file_atomically(run / "run_clean.py", wrapper_text);
            const json identity = {{"code", "yade"},
                                   {"run", kind.folder},
                                   {"script_sha256", orchestrator::sha256_hex(script_text)},
                                   {"params", params},
                                   {"bed_sha256", file_hash((d / kind.bed_file).string())}};
            jobs.push_back(orchestrator::stored_job(
                o.angle(theta) + " " + kind.folder, identity, {{"theta_deg", theta}, {"code", kind.folder}}, run,
                {in.yade, "-n", "-j1", "-x", "run_clean.py", "silo.py", "params.json", "result.json"}, "result.json",
                o.timeout_s));
        }
    return jobs;
}

void record_campaign_status(orchestrator::CampaignStore& store, std::int64_t campaign_id) {
    const auto runs = store.campaign_runs(campaign_id);
    const bool all_done = std::all_of(runs.begin(), runs.end(), [](const orchestrator::RunRecord& r) {
        return r.state == orchestrator::RunState::done;
    });
    const bool any_failed = std::any_of(runs.begin(), runs.end(), [](const orchestrator::RunRecord& r) {
        return r.state == orchestrator::RunState::failed;
    });
    store.set_campaign_status(campaign_id, all_done     ? orchestrator::CampaignStatus::complete
                                          : any_failed ? orchestrator::CampaignStatus::failed
                                                       : orchestrator::CampaignStatus::open);
}

crosscheck_silo::ReportSettings report_settings(const SiloCrosscheckOptions& o, const CrosscheckInputs& in) {
    crosscheck_silo::ReportSettings r;
    r.thetas = o.thetas;
    r.particles = o.particles;
    r.stiffness_scale = o.stiffness_scale;
    r.seed = o.seed;
    r.tolerance = o.tolerance;
    r.yade_material = in.yade_material;
    r.yade_material_file = o.yade_material;
    r.fill_text = o.fill_text;
    r.kernel_law = kernel::silo::silo_contact_laws().at(o.kernel_law);
    r.kernel_rotation = kernel::silo::silo_clump_rotations().at(o.kernel_rotation);
    r.wall_facets = o.wall_facets;
    r.start_as_yade_import = o.start_as_yade_import;
    r.yade_runs = yade_runs(o.fill());
    r.plot_format = o.plot_format;
    return r;
}

int run_silo_crosscheck(const SiloCrosscheckOptions& o) {
    const CrosscheckInputs in = checked_inputs(o);
    // the campaign directory: its lock and its store (runs, states, results, attempts), stale runs recovered
    orchestrator::CampaignDirectory campaign(o.dir, orchestrator::stored_job_result);
    const fs::path root = campaign.dir();
    orchestrator::CampaignStore& store = campaign.store();
    const std::int64_t campaign_id = ensure_campaign(store, o);
    // the kernel runs start a copy of this program kept in the campaign: a rebuild while they run (or wait in a SLURM
    // queue) neither fails them nor mixes two builds
    const std::string program = orchestrator::pinned_program(in.self, root / ".program");
    const int slots = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
    const auto executor = orchestrator::make_executor(o.executor, slots, root / "slurm", o.partition);
    auto run_stage = [&](const std::vector<orchestrator::StoredJob>& jobs) {
        const auto out = orchestrator::run_stored_jobs(
            store, campaign_id, jobs, *executor,
            [](const std::string& event, const orchestrator::StoredJob& job, const std::string& detail) {
                // a column of 9, and a space after a longer event ("retry later")
                std::cout << event << std::string(event.size() < 9 ? 9 - event.size() : 1, ' ') << job.name
                          << (detail.empty() ? "" : " (" + detail + ")") << std::endl;
            });
        return !out.interrupted;
    };
    // the YADE stage needs the beds of the kernel stage
    if (!run_stage(kernel_jobs(o, root, program)) || !run_stage(yade_jobs(o, in, root))) {
        std::cout << "interrupted: run the same command again to continue\n";
        return kExitResumeLater;
    }
    record_campaign_status(store, campaign_id);
    const auto report = crosscheck_silo::write_report(root, report_settings(o, in));
    std::cout << "\n" << report.markdown << "\nresults: " << (root / "crosscheck_silo.json").string() << ", "
              << (root / "crosscheck_silo.md").string() << ", <theta>/mass_time." << o.plot_format << "\n";
    return report.complete ? 0 : 1;
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
    silo->add_option("--timeout", o->timeout_s, "per-run wall-clock limit [s]")->check(run_timeout());
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
    silo->add_option("--kernel-law", o->kernel_law,
                     "the kernel's contact law (demcal silo --contact-law): edem, its own; yade, YADE's Hertz-Mindlin, "
                     "so that both codes run one law (the material's rolling friction must then be 0)")
        ->check(CLI::IsMember(kernel::silo::silo_contact_laws()))
        ->capture_default_str();
    silo->add_option("--kernel-rotation", o->kernel_rotation,
                     "how the kernel's grains turn in the discharge (demcal silo --discharge-rotation): richardson, "
                     "its own; yade, YADE's aspherical leapfrog, so that both codes integrate the clumps alike (the "
                     "bed is the same either way)")
        ->check(CLI::IsMember(kernel::silo::silo_clump_rotations()))
        ->capture_default_str();
    silo->add_option("--wall-facets", o->wall_facets,
                     "0: the kernel's exact cone and cylinder beside YADE's 72-sided facet polygons; N (12 to 2000): "
                     "both codes discharge between the same N-sided facet polygons (demcal silo "
                     "--discharge-wall-facets N, silo.py's run.facet_segments N), so that the walls differ no more")
        ->check(CLI::Range(0, 2000))
        ->capture_default_str();
    silo->add_flag("--kernel-start-as-yade-import", o->start_as_yade_import,
                   "the kernel starts the discharge as YADE's import of the bed does (demcal silo "
                   "--start-as-yade-import: contacts afresh, their springs advanced in the first force evaluation, a "
                   "whole first kick); with --kernel-law yade --kernel-rotation yade --wall-facets 72 both codes then "
                   "run the same dynamics from the same state");
    silo->add_option("--max-runs", o->max_runs, "most runs this command may plan, 2 per angle (3 with --fill both; a guard against typos)")
        ->check(integer_in(1, 1000000000))
        ->capture_default_str();
    silo->callback([o] {
        const int code = run_silo_crosscheck(*o);
        if (code != 0) throw CLI::RuntimeError(code);
    });
}

}  // namespace demcal
