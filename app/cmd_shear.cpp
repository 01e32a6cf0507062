// demcal shear / status / resume: YADE direct-shear campaigns and their failure lines.
#include "analytics/number_text.hpp"
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/execution_options.hpp"
#include "app/gnuplot.hpp"
#include "app/result_files.hpp"
#include "app/shear_report.hpp"
#include "app/silo_campaign.hpp"
#include "analytics/failure_line.hpp"
#include "analytics/user_input.hpp"
#include "calibration/campaign_evaluator.hpp"  // replaces_failed_runs
#include "calibration/failure_line_evaluation.hpp"
#include "orchestrator/campaign_suspended.hpp"
#include "orchestrator/executor.hpp"  // InterruptGuard
#include "orchestrator/folder_lock.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"
#include "orchestrator/shear_params.hpp"

#include <map>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

namespace demcal {

namespace fs = std::filesystem;
using namespace orchestrator;

namespace {

struct ShearCliOptions {
    std::string material_file;
    std::vector<double> normal_stresses;
    int replicates = 1;
    long seed = 1;
    std::string campaign_dir;
    std::string template_path;
    std::string plot_format = "png";
    std::string engine = "yade";
    ExecutionOptions exec;
    bool yade_given = false;  // resume: --yade typed (it applies to campaigns of the YADE engine)
    bool max_runs_given = false;  // resume: --max-runs typed (it bounds the runs left; it was ignored)
};

// Failure line with its points and 95 % band, and the shear curves, for one campaign.
void write_plots(const fs::path& dir, const std::string& stem, const calibration::FailureLineEvaluation& ev,
                 const std::string& format) {
    const fs::path points = dir / (stem + "_points.dat"), band = dir / (stem + "_band.dat");
    {
        std::ostringstream p;
        p << "# sigma_Pa peak_tau_Pa residual_tau_Pa\n";
        for (const auto& r : ev.outcome.runs)
            if (r.state == RunState::done)
                p << r.label["normal_stress"].get<double>() << " " << r.result["peak_shear_stress"].get<double>() << " "
                  << r.result.value("residual_shear_stress", 0.0) << "\n";
        write_result_file(points, p.str());
        std::ostringstream b;
        b << "# sigma_Pa peak_fit peak_low peak_high residual_fit\n";
        double smax = 0;
        for (const auto& r : ev.outcome.runs) smax = std::max(smax, r.label["normal_stress"].get<double>());
        for (int i = 0; i <= 50; ++i) {
            const double s = 1.1 * smax * i / 50;
            const double w = ev.peak->band_half_width(s);
            b << s << " " << ev.peak->shear_stress(s) << " " << ev.peak->shear_stress(s) - w << " "
              << ev.peak->shear_stress(s) + w << " " << ev.residual->shear_stress(s) << "\n";
        }
        write_result_file(band, b.str());
    }
    std::ostringstream g;
    g << "set title 'Failure line: mu_b = " << std::setprecision(3) << ev.peak->mu_b << " (phi_b = "
      << std::setprecision(3) << ev.peak->phi_b_deg << " deg), tau_c = " << std::setprecision(3) << ev.peak->tau_c
      << " Pa'\nset xlabel 'normal stress sigma [kPa]'\nset ylabel 'shear stress tau [kPa]'\nset key top left\n"
      << "set grid\nset xrange [0:*]\nset yrange [0:*]\n"
      << "plot " << gnuplot_quote(band) << " using ($1/1e3):($3/1e3):($4/1e3) with filledcurves lc rgb '#c6dbef' "
      << "title '95% confidence band (peak)', \\\n  '' using ($1/1e3):($2/1e3) with lines lw 2 lc rgb '#08519c' "
      << "title 'peak failure line', \\\n  '' using ($1/1e3):($5/1e3) with lines lw 2 dt 2 lc rgb '#a50f15' "
      << "title 'residual failure line', \\\n  " << gnuplot_quote(points)
      << " using ($1/1e3):($2/1e3) with points pt 7 ps 1.2 lc rgb '#08519c' title 'peak', \\\n  '' using "
         "($1/1e3):($3/1e3) with points pt 5 ps 1 lc rgb '#a50f15' title 'residual'\n";
    render_gnuplot(dir / (stem + "." + format), g.str());

    std::ostringstream c;
    c << "set title 'Shear stress against shear displacement'\nset xlabel 'shear displacement [mm]'\n"
      << "set ylabel 'shear stress [kPa]'\nset key outside right\nset grid\nplot ";
    bool first = true;
    for (const auto& r : ev.outcome.runs) {
        if (r.state != RunState::done || !r.result.contains("curve")) continue;
        const fs::path curve = r.run_dir / "curve.dat";
        std::ostringstream f;
        const auto& cv = r.result["curve"];
        for (std::size_t i = 0; i < cv["displacement"].size(); ++i)
            f << cv["displacement"][i].get<double>() << " " << cv["shear_stress"][i].get<double>() << "\n";
        write_result_file(curve, f.str());
        c << (first ? "" : ", \\\n  ") << gnuplot_quote(curve) << " using ($1*1e3):($2/1e3) with lines title '"
          << r.label["normal_stress"].get<double>() / 1e3 << " kPa #" << r.label["replicate"].get<int>() << "'";
        first = false;
    }
    if (!first) render_gnuplot(dir / ("shear_curves_" + ev.outcome.campaign.name + "." + format), c.str(), 1000, 600);
}

// Prints, saves and plots one campaign's failure lines; returns the process exit code.
int report_campaign(const fs::path& dir, const ShearCampaignOutcome& outcome, const std::string& plot_format,
                    bool stopped_before_reports) {
    const auto ev = calibration::failure_lines_of(outcome);
    std::cout << "\ncampaign " << outcome.campaign.name << " (" << dir.string() << "): " << outcome.runs.size()
              << " runs, " << ev.simulations_run << " computed now, " << ev.simulations_reused << " reused, "
              << ev.simulations_failed << " failed; CPU " << duration_text(ev.cpu_s) << "\n";
    for (const auto& r : outcome.runs)
        if (r.state == RunState::failed)
            std::cout << "  FAILED sigma=" << r.label["normal_stress"] << " Pa rep " << r.label["replicate"] << ": "
                      << r.cause << ": " << r.message << "  (" << r.run_dir.string() << "/stderr.log)\n";
    nlohmann::json j = {{"campaign", outcome.campaign.name},
                        {"spec", outcome.campaign.spec},
                        {"runs", nlohmann::json::array()},
                        {"simulations_run", ev.simulations_run},
                        {"simulations_reused", ev.simulations_reused},
                        {"simulations_failed", ev.simulations_failed},
                        {"cpu_s", ev.cpu_s}};
    for (const auto& r : outcome.runs) {
        nlohmann::json rj = {{"hash", r.hash}, {"label", r.label}, {"state", to_string(r.state)},
                             {"run_dir", r.run_dir.string()}, {"wall_s", r.wall_s}, {"cpu_s", r.cpu_s}};
        if (r.state == RunState::done) {
            for (const char* k : {"peak_shear_stress", "residual_shear_stress", "normal_stress_held", "porosity",
                                  "particle_count"})
                if (r.result.contains(k)) rj[k] = r.result[k];
        } else if (r.state == RunState::failed) {
            rj["cause"] = r.cause;
            rj["message"] = r.message;
        }
        j["runs"].push_back(rj);
    }
    j["peak_failure_line"] = ev.peak ? ev.peak->to_json() : nlohmann::json(nullptr);
    j["residual_failure_line"] = ev.residual ? ev.residual->to_json() : nlohmann::json(nullptr);
    const std::string stem = "failure_line_" + outcome.campaign.name;
    write_result_file(dir / (stem + ".json"), j.dump(2) + "\n");
    if (ev.peak && ev.residual) {
        std::cout << "\n";
        print_line("Peak failure line", *ev.peak);
        print_line("Residual failure line", *ev.residual);
        try {
            write_plots(dir, stem, ev, plot_format);
            std::cout << "\nresults: " << (dir / (stem + ".json")).string() << "\nplots:   "
                      << (dir / (stem + "." + plot_format)).string() << ", "
                      << (dir / ("shear_curves_" + outcome.campaign.name + "." + plot_format)).string() << "\n";
        } catch (const std::exception& e) {
            std::cerr << "demcal: warning: plot not written: " << e.what() << "\n";
        }
    } else {
        // what the campaign has, not a fixed text ("fewer than 3 finished runs on 2 normal stresses" of 0 runs on 3)
        std::set<double> stresses;
        std::size_t done = 0;
        for (const auto& r : outcome.runs)
            if (r.state == orchestrator::RunState::done) {
                ++done;
                if (r.label.contains("normal_stress")) stresses.insert(r.label["normal_stress"].get<double>());
            }
        std::cout << "no failure line: " << done << " finished run" << (done == 1 ? "" : "s") << " on "
                  << stresses.size() << " normal stress" << (stresses.size() == 1 ? "" : "es")
                  << " (a line needs 3 runs on at least 2)\n";
    }
    // A stop signal after the runs (caught by the guard the command holds from its runs on) stops the command as one during
    // the runs does (exit 75, resume it), once the report step it came in is done, with the report's files removed.
    // It ended demcal silently by the signal (held-back probe 65).
    if (orchestrator::interrupted() && !stopped_before_reports && !outcome.interrupted)
        throw orchestrator::CampaignSuspended("stopped by a stop signal while it wrote the report of campaign " +
                                              outcome.campaign.name + ": its finished runs are stored; `demcal resume " +
                                              shell_word(dir.string()) + "` writes the report again");
    keep_results();  // this campaign's report is whole: a later campaign's failure (resume) does not take it
    if (outcome.interrupted) return kExitResumeLater;
    if (!outcome.infrastructure_failure.empty()) {
        std::cout << "the simulator could not be started (" << outcome.infrastructure_failure
                  << "); the runs it hit stay pending: fix what stops it (its message; --yade for another YADE; the "
                     "kernel engine: the demcal program), then `demcal resume "
                  << shell_word(dir.string()) << "`\n";
        return kExitResumeLater;
    }
    // a campaign is run for its failure line: finished without one, it has not done its job
    return outcome.failed > 0 || !(ev.peak && ev.residual) ? 1 : 0;
}

// A shear campaign: every input checked before anything is written, the runs, the failure line.
void run_shear(const ShearCliOptions& opt) {
    ShearCampaignSpec spec;
    spec.material = read_json_file(opt.material_file, "material");
    validate_material(spec.material, opt.material_file);
    check_run_count(static_cast<double>(opt.normal_stresses.size()) * opt.replicates, opt.exec.max_runs,
                    "shear: " + std::to_string(opt.normal_stresses.size()) + " normal stresses x " +
                        std::to_string(opt.replicates) + " replicates");
    spec.normal_stresses = opt.normal_stresses;
    spec.replicates = opt.replicates;
    spec.base_seed = opt.seed;
    spec.template_path = opt.template_path;
    spec.engine = parse_shear_engine(opt.engine);
    if (spec.engine == ShearEngine::kernel && !opt.template_path.empty())
        throw UserError("--template = '" + opt.template_path + "' is a YADE script: it applies to --engine yade only");
    validate_shear_spec(spec);
    if (spec.engine == ShearEngine::yade) find_yade(opt.exec.yade);
    analytics::check_failure_line_design(spec.normal_stresses, spec.replicates);
    const fs::path dir = opt.campaign_dir.empty() ? fs::path("campaigns") / fs::path(opt.material_file).stem()
                                                  : fs::path(opt.campaign_dir);
    ShearCampaignRunner runner(dir, opt.exec);
    std::cout << "campaign directory " << runner.dir().string() << ": " << spec.normal_stresses.size()
              << " normal stresses x " << spec.replicates << " replicates, " << to_string(spec.engine) << " engine, "
              << opt.exec.executor << " executor\n";
    const orchestrator::InterruptGuard stop_guard;  // from the runs to the end of the report (report_campaign)
    const auto outcome = runner.run(spec, print_progress);
    const int code = report_campaign(runner.dir(), outcome, opt.plot_format, orchestrator::interrupted());
    if (outcome.interrupted) std::cout << "interrupted: continue with `demcal resume " << shell_word(runner.dir().string()) << "`\n";
    if (code != 0) throw CLI::RuntimeError(code);
}

// A material field's value as text that compares numbers by value (2650 and 2650.0 are one density).
std::string field_value_key(const nlohmann::json& v) {
    return v.is_number() ? analytics::number_text(v.get<double>(), 15) : v.dump();
}

// Each material field's value held by every one of a store's shear campaigns: `demcal status` shows, for each
// campaign, the fields in which the campaigns differ (campaign names are digests: a study's levels, a calibration's
// steps). (The most common value, ties to the smallest text, read a study's lowest level as the base (probe 62); a
// calibration added to a one-parameter study's folder broke the tie and hid a level again (probe 62b); a majority
// hid the base level of a study once the base material was run beside it (review of stop 63).)
std::map<std::string, std::string> common_material_values(const std::vector<ShearCampaignOutcome>& outs) {
    std::map<std::string, std::map<std::string, int>> counts;
    int campaigns = 0;
    for (const auto& o : outs) {
        if (o.campaign.kind != CampaignKind::shear) continue;
        ++campaigns;
        const nlohmann::json material = o.campaign.spec.value("material", nlohmann::json::object());
        for (const auto& [k, v] : material.items()) ++counts[k][field_value_key(v)];
    }
    std::map<std::string, std::string> common;
    for (const auto& [k, by_value] : counts)
        for (const auto& [value, n] : by_value)
            if (n == campaigns) common[k] = value;
    return common;
}

// What a shear campaign ran: the engine, its material (its name, and the fields whose values differ from the store's
// most common ones), the stresses and packings, and its label.
std::string campaign_description(const ShearCampaignOutcome& o, const std::map<std::string, std::string>& common) {
    const auto spec = ShearCampaignSpec::from_json(o.campaign.spec);
    std::ostringstream d;
    d << "  " << to_string(spec.engine) << " engine";
    if (!spec.material_name.empty())
        d << ", material '" << analytics::shortened_text(spec.material_name, 60) << "'";
    for (const auto& [k, v] : spec.material.items()) {
        if (k == "name" || k == "description") continue;
        const auto c = common.find(k);
        if (c == common.end() || c->second != field_value_key(v))
            d << ", " << k << " " << analytics::json_value_text(v);
    }
    const auto [lo, hi] = std::minmax_element(spec.normal_stresses.begin(), spec.normal_stresses.end());
    d << "; " << spec.normal_stresses.size() << " normal stresses " << analytics::number_text(*lo) << " to "
      << analytics::number_text(*hi) << " Pa x " << spec.replicates << " packings from seed " << spec.base_seed;
    if (!spec.label.empty()) d << "; " << analytics::shortened_text(spec.label, 80);
    return d.str();
}

// One campaign's line of `demcal status`: its runs by state, their time, its failures and its failure line.
void print_campaign_status(const ShearCampaignOutcome& o, bool folder_held,
                           const std::map<std::string, std::string>& common_material) {
    std::map<std::string, int> by_state;
    double wall = 0;
    for (const auto& r : o.runs) {
        ++by_state[to_string(r.state)];
        wall += r.wall_s;
    }
    std::cout << o.campaign.name << " [" << to_string(o.campaign.status) << "] " << to_string(o.campaign.kind) << ": "
              << o.runs.size() << " runs";
    // runs marked running while no demcal holds the folder belong to one that died: the next resume reruns them
    for (const auto& [s, n] : by_state)
        std::cout << ", " << n << " "
                  << (s == "running" && !folder_held ? "interrupted (no demcal holds the campaign: `demcal resume` "
                                                       "reruns them)"
                                                     : s);
    std::cout << "; run time " << duration_text(wall) << ", CPU " << duration_text(o.cpu_s) << "\n";
    const bool shear = o.campaign.kind == CampaignKind::shear;
    if (shear) std::cout << campaign_description(o, common_material) << "\n";
    for (const auto& r : o.runs)
        if (r.state == RunState::failed)
            std::cout << "  failed: "
                      << (shear ? "sigma=" + r.label["normal_stress"].dump() + " rep " + r.label["replicate"].dump()
                                : r.label.dump())
                      << " after " << r.attempts << " attempt(s): " << r.cause << ": " << r.message << "\n";
    if (!shear) return;  // other campaigns (a silo cross-check) report themselves
    const auto ev = calibration::failure_lines_of(o);
    if (ev.peak) print_line("  peak failure line", *ev.peak);
}

// status and resume take the campaign's folder: given its campaign.sqlite (or any file), they said "'.../campaign.sqlite'
// holds no campaign.sqlite"
void check_campaign_folder_argument(const std::string& dir, const std::string& command) {
    std::error_code ec;
    const std::string named = command + ": DIR = '" + analytics::shortened_text(dir, 200) + "'";
    if (fs::is_regular_file(dir, ec))
        throw UserError(named + " is a file, not a campaign folder: give the folder that holds it (" +
                        analytics::shortened_text(
                            fs::path(dir).has_parent_path() ? fs::path(dir).parent_path().string() : ".", 200) +
                        ")");
    const bool there = fs::exists(dir, ec);
    if (ec) return;  // a path the file system will not take (a link loop): named with its reason further on
    if (!there) throw UserError(named + " does not exist");
    if (!fs::is_directory(dir, ec))  // (a FIFO or a device was told it "holds no campaign.sqlite", probe 63)
        throw UserError(named + " is not a folder (a device, FIFO or socket): give a campaign folder");
    const fs::path d(dir);
    if (fs::exists(d / "campaign.sqlite", ec) || fs::exists(d / "campaign.json", ec)) return;
    if (fs::exists(d / "checkpoint.bin", ec) || fs::exists(d / "summary.json", ec))
        throw UserError(named + " is a demcal silo run's folder, not a campaign: `demcal silo --resume " +
                        shell_word(analytics::shortened_text(dir, 200)) + "` continues a suspended run");
    // a store a command began and was stopped (kill -9) before it was renamed into place (held-back probe 65)
    for (fs::directory_iterator it(d, ec), end; !ec && it != end; it.increment(ec))
        if (const std::string n = it->path().filename().string(); n.rfind("campaign.sqlite.new-", 0) == 0)
            throw UserError(named + " holds only " + analytics::shortened_text(n) + ", the store of a command stopped "
                            "before it had stored its campaign: run that command again (it starts the campaign whole)");
    // a folder of campaigns (campaigns/, where cutoff puts its silo searches): name them
    std::vector<std::string> inside;
    for (fs::directory_iterator it(d, ec), end; !ec && it != end && inside.size() < 6; it.increment(ec))
        if (fs::exists(it->path() / "campaign.sqlite") || fs::exists(it->path() / "campaign.json"))
            inside.push_back(it->path().filename().string());
    if (!inside.empty()) {
        std::sort(inside.begin(), inside.end());
        std::string list;
        for (const auto& n : inside) list += (list.empty() ? "" : ", ") + n;
        throw UserError(named + " holds no campaign itself; its folders " + list + " do: give one of them");
    }
    if (command == "status")  // (resume says so itself, naming a silo sweep's folder)
        throw UserError(named + " holds no campaign.sqlite nor a silo sweep's campaign.json: no campaign");
}

void print_status(const std::string& dir) {
    check_campaign_folder_argument(dir, "status");
    if (!fs::exists(fs::path(dir) / "campaign.sqlite") && fs::exists(fs::path(dir) / "campaign.json"))
        return print_silo_sweep_status(dir);  // a vibration, cutoff or diagnose silo-dem sweep
    const std::vector<ShearCampaignOutcome> outs = inspect_campaigns(dir);
    const auto common = common_material_values(outs);
    for (const auto& o : outs) print_campaign_status(o, orchestrator::FolderLock::held(dir), common);
    if (outs.empty())
        std::cout << "no campaigns in " << dir << " (the command that made its store stopped before it recorded one: "
                  << "run that command again)\n";
}

// The commands whose shear campaigns a folder holds beside plain ones (the first word of a campaign's label:
// sensitivity, calibrate, scale): resume runs their pending runs, not the study, the loop or the fits around them,
// which exited 0 as if the interrupted calibration were done (probe 62). Said on stderr.
void warn_of_study_commands(const std::string& dir) {
    std::set<std::string> commands;
    for (const auto& o : inspect_campaigns(dir)) {
        if (o.campaign.kind != orchestrator::CampaignKind::shear) continue;
        const std::string label = ShearCampaignSpec::from_json(o.campaign.spec).label;
        const std::string first = label.substr(0, label.find(' '));
        if (first == "sensitivity" || first == "calibrate" || first == "scale") commands.insert(first);
    }
    for (const auto& command : commands)
        std::cerr << "demcal resume: warning: " << dir << " holds the runs of a `demcal " << command
                  << "`: resume ran its pending shear runs only; the " << command
                  << " itself (its study, search, fits and reports) continues when the same `demcal " << command
                  << "` command is run again, which reuses every finished run" << std::endl;
}

std::size_t runs_in_state(const ShearCampaignOutcome& o, orchestrator::RunState state) {
    return std::size_t(std::count_if(o.runs.begin(), o.runs.end(),
                                     [state](const orchestrator::RunRecord& r) { return r.state == state; }));
}

std::size_t failed_runs(const ShearCampaignOutcome& o) {
    return runs_in_state(o, orchestrator::RunState::failed);
}

// The stored campaign whose fresh packings replaced the failed runs of `o` (calibration::replaces_failed_runs), if
// every run of `o` has ended (nothing of it is left to run) and one has failed.
const ShearCampaignOutcome* replacing_campaign(const ShearCampaignOutcome& o,
                                               const std::vector<ShearCampaignOutcome>& stored) {
    const auto ended = [](const orchestrator::RunRecord& r) {
        return r.state == orchestrator::RunState::done || r.state == orchestrator::RunState::failed;
    };
    if (o.campaign.kind != CampaignKind::shear || failed_runs(o) == 0 ||
        !std::all_of(o.runs.begin(), o.runs.end(), ended))
        return nullptr;
    const auto spec = ShearCampaignSpec::from_json(o.campaign.spec);
    for (const auto& later : stored)
        if (later.campaign.kind == CampaignKind::shear &&
            calibration::replaces_failed_runs(ShearCampaignSpec::from_json(later.campaign.spec), spec))
            return &later;
    return nullptr;
}

// A campaign counts as complete once its last run is stored, before its report is written: a stop in between (kill
// -9, a full disk) left the report cut short or missing, and resume said only "nothing to resume" (probe 64). So
// resume writes again, from the store (a fit and two plots, no simulation), the report of a complete campaign it did
// not just run that `demcal shear` made (no label: studies and crosschecks write reports of their own) or whose
// report was begun (a file of it in the folder).
// `files`: the names in the campaign folder (listed once per resume).
bool report_written_again(const std::vector<std::string>& files, const ShearCampaignOutcome& o,
                          const std::vector<ShearCampaignOutcome>& resumed) {
    if (o.campaign.kind != CampaignKind::shear || o.campaign.status != CampaignStatus::complete) return false;
    for (const auto& r : resumed)
        if (r.campaign.name == o.campaign.name) return false;
    if (ShearCampaignSpec::from_json(o.campaign.spec).label.empty()) return true;
    for (const std::string& name : files)
        for (const std::string& stem : {"failure_line_" + o.campaign.name, "shear_curves_" + o.campaign.name})
            if (name.rfind(stem, 0) == 0) return true;
    return false;
}

std::vector<std::string> file_names_in(const fs::path& dir) {
    std::vector<std::string> names;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        names.push_back(it->path().filename().string());
    return names;
}

void run_resume(const ShearCliOptions& opt) {
    check_campaign_folder_argument(opt.campaign_dir, "resume");
    if (!fs::exists(fs::path(opt.campaign_dir) / "campaign.sqlite")) {
        // a silo sweep's folder (vibration, cutoff, diagnose silo-dem) is continued by its own command, run again
        const std::string what = fs::exists(fs::path(opt.campaign_dir) / "campaign.json")
                                     ? ": it holds a silo sweep (campaign.json of demcal vibration, cutoff or diagnose "
                                       "silo-dem), which the same command, run again, continues"
                                     : "";
        throw UserError("resume: DIR = '" + opt.campaign_dir + "' holds no campaign.sqlite" + what);
    }
    orchestrator::check_stored_shear_specs(opt.campaign_dir);
    if (opt.yade_given) {  // void where every unfinished campaign runs on the kernel (it was silently ignored)
        bool unfinished = false, on_yade = false;
        for (const auto& o : inspect_campaigns(opt.campaign_dir)) {
            if (runs_in_state(o, orchestrator::RunState::done) == o.runs.size()) continue;
            unfinished = true;
            on_yade = on_yade || o.campaign.kind != orchestrator::CampaignKind::shear ||
                      ShearCampaignSpec::from_json(o.campaign.spec).engine == ShearEngine::yade;
        }
        if (unfinished && !on_yade)
            throw UserError("--yade = '" + analytics::shortened_text(opt.exec.yade) + "' is YADE's launcher: the "
                            "unfinished campaigns of " + opt.campaign_dir + " run on the kernel engine; omit it");
    }
    if (opt.max_runs_given) {  // the runs left, bounded as a new campaign's planned runs are
        std::size_t left = 0;
        for (const auto& o : inspect_campaigns(opt.campaign_dir))
            left += std::size_t(std::count_if(o.runs.begin(), o.runs.end(), [](const orchestrator::RunRecord& r) {
                return r.state != orchestrator::RunState::done;
            }));
        if (left > std::size_t(opt.exec.max_runs))
            throw UserError("--max-runs = " + std::to_string(opt.exec.max_runs) + ": the campaigns of " +
                            opt.campaign_dir + " have " + std::to_string(left) +
                            " runs not done; resume them with a --max-runs of at least that, or without it");
    }
    if (inspect_campaigns(opt.campaign_dir).empty())  // (a command killed between making the store and its campaign)
        throw UserError("resume: DIR = '" + analytics::shortened_text(opt.campaign_dir, 200) + "' holds a store with no "
                        "campaign recorded in it (the command that made it stopped first): run that command again");
    find_yade(opt.exec.yade);  // before the store is opened: a bad --yade costs nothing
    ShearCampaignRunner runner(opt.campaign_dir, opt.exec);
    const orchestrator::InterruptGuard stop_guard;  // from the runs to the end of the reports (report_campaign)
    auto outs = runner.resume(print_progress);
    const bool stopped_before_reports = orchestrator::interrupted();  // (a stop in the runs is the runs' to report)
    const auto stored = inspect_campaigns(opt.campaign_dir);
    const std::size_t resumed = outs.size();
    std::size_t rewritten = 0;
    const std::vector<std::string> files = file_names_in(runner.dir());
    for (auto o : stored)
        if (report_written_again(files, o, outs)) {
            o.reused = int(runs_in_state(o, RunState::done));
            outs.push_back(std::move(o));
            ++rewritten;
        }
    if (resumed == 0)
        std::cout << "nothing to resume: every campaign in " << runner.dir().string() << " is complete"
                  << (rewritten > 0 ? "; the report of each `demcal shear` campaign is written again from the store"
                                    : "")
                  << "\n";
    int code = 0;
    for (const auto& o : outs) {
        // a study's line whose failed runs fresh packings replaced was fitted over both campaigns: reported as a
        // failure of its own on every resume (exit 1), it was retried never (probe 62)
        if (const auto* by = replacing_campaign(o, stored)) {
            std::cout << "campaign " << o.campaign.name << ": its " << failed_runs(o)
                      << " failed run(s) were replaced by the fresh packings of campaign " << by->campaign.name
                      << " (the study fits its line over every round's runs); nothing to resume\n";
            continue;
        }
        code = std::max(code, report_campaign(runner.dir(), o, opt.plot_format, stopped_before_reports));
    }
    warn_of_study_commands(opt.campaign_dir);
    if (code != 0) throw CLI::RuntimeError(code);
}

}  // namespace

void add_shear_commands(CLI::App& app) {
    auto opt = std::make_shared<ShearCliOptions>();
    auto* shear = app.add_subcommand("shear", "run a direct-shear campaign in YADE and fit the failure line");
    shear->add_option("material", opt->material_file, "material JSON (micromechanical parameters)")->required();
    shear->add_option("--normal-stress,-s", opt->normal_stresses, "normal stresses [Pa], e.g. 5e3,10e3,15e3")
        ->required()
        ->delimiter(',')
        ->check(positive_number());
    shear->add_option("--replicates,-r", opt->replicates, "packings per normal stress (seeds seed, seed+1, ...)")
        ->check(integer_in(1, orchestrator::kMaxReplicates))
        ->capture_default_str();
    shear->add_option("--seed", opt->seed, "first packing seed")
        ->check(integer_in(0, static_cast<long long>(find_shear_param("seed")->max)))
        ->capture_default_str();
    shear->add_option("--campaign,-c", opt->campaign_dir, "campaign directory (default campaigns/<the material file's name without .json>)");
    shear->add_option("--template", opt->template_path, "YADE template (default: yade_scripts/shear_box.py)");
    shear->add_option("--engine", opt->engine,
                      "yade (yade_scripts/shear_box.py) or kernel (the same box on demcal's kernel with YADE's laws)")
        ->check(CLI::IsMember({"yade", "kernel"}))
        ->capture_default_str();
    shear->add_option("--plot", opt->plot_format, "plot format")->check(CLI::IsMember({"png", "svg"}))->capture_default_str();
    shear->add_flag("--force", opt->exec.force, "recompute runs already in the store");
    add_execution_options(shear, opt->exec);
    shear->callback([opt] { run_shear(*opt); });

    auto status_dir = std::make_shared<std::string>();
    auto* status = app.add_subcommand("status", "summarise the campaigns of a directory");
    status->add_option("dir", *status_dir, "campaign directory")->required();
    status->callback([status_dir] { print_status(*status_dir); });

    auto resume_opt = std::make_shared<ShearCliOptions>();
    auto* resume = app.add_subcommand("resume", "continue the unfinished campaigns of a directory");
    resume->add_option("dir", resume_opt->campaign_dir, "campaign directory")->required();
    resume->add_option("--plot", resume_opt->plot_format, "plot format")->check(CLI::IsMember({"png", "svg"}));
    add_execution_options(resume, resume_opt->exec);
    resume->callback([resume_opt, resume] {
        resume_opt->yade_given = resume->count("--yade") > 0;
        resume_opt->max_runs_given = resume->count("--max-runs") > 0;
        run_resume(*resume_opt);
    });
}

}  // namespace demcal
