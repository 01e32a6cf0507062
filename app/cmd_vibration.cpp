// demcal vibration: the seed's vibrational-discharge sweep (sections 2.1.3, 3.5; figures 3.10-3.12) as a campaign of
// `demcal silo` runs: every hopper angle x frequency x repeat (seed) is one run in DIR/runs/<name>/, a subprocess of
// this demcal (its own checkpoint, its own summary.json; a crash or Ctrl-C of one run loses nothing finished). The
// same command again continues the campaign: finished runs are read, suspended ones resumed (--resume), the rest run.
// The report: per angle and frequency the discharge rate's mean, standard deviation and count, and the flow pattern;
// DIR/vibration.json, DIR/vibration.md and DIR/vibration.png (rate against frequency, one line per angle).
#include "analytics/number_text.hpp"
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/gnuplot.hpp"
#include "app/result_files.hpp"
#include "app/silo_campaign.hpp"
#include "kernel/silo/bin_vibration.hpp"
#include "orchestrator/shear_campaign.hpp"  // check_run_count

#include <gsl/gsl_statistics_double.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace demcal {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct VibrationCli {
    std::vector<double> thetas, frequencies;
    double amplitude = 0;
    std::string direction = "x";
    std::string part = "bin";
    int repeats = 3;
    long long first_seed = 1;
    std::string campaign;
    long max_runs = 10000;
    int jobs = 1;  // runs at once: one locally (each takes the cores its --threads gives it), SLURM array slots
    std::string executor = "local", partition;
    std::vector<std::string> silo_args;  // after --: passed to every `demcal silo`
    std::vector<std::string> vibration_options_given;  // --amplitude, --direction, --part as typed (void in a still bin)
};

struct RunSpec {
    double theta, frequency;
    long long seed;
    std::string name() const {
        std::ostringstream n;
        n << "theta" << theta << "_f" << frequency << "_seed" << seed;
        return n.str();
    }
};

// Options this command sets for every run itself.
const std::vector<std::string> kOwnedSiloOptions = {"--theta", "--seed", "--out", "--resume", "--vibration-frequency",
                                                    "--vibration-amplitude", "--vibration-direction",
                                                    "--vibration-part", "--check"};

SiloRunPlan silo_plan(const VibrationCli& o, const RunSpec& r) {
    std::vector<std::string> a{"--theta", silo_number(r.theta), "--seed", std::to_string(r.seed)};
    if (r.frequency > 0)
        a.insert(a.end(), {"--vibration-frequency", silo_number(r.frequency), "--vibration-amplitude",
                           silo_number(o.amplitude), "--vibration-direction", o.direction, "--vibration-part",
                           o.part});
    // --vibration-start after -- delays the vibrating cells' shaking; the still runs have none to delay (silo refuses
    // it without a vibration: a sweep with a 0 Hz cell was refused naming a run, one without took it)
    for (std::size_t i = 0; i < o.silo_args.size(); ++i) {
        const std::string& arg = o.silo_args[i];
        if (r.frequency == 0 && arg == "--vibration-start") {
            ++i;  // and its value
            continue;
        }
        if (r.frequency == 0 && arg.rfind("--vibration-start=", 0) == 0) continue;
        a.push_back(arg);
    }
    return {r.name(), a};
}

json campaign_settings(const VibrationCli& o) {
    json s = {{"thetas_deg", o.thetas},     {"frequencies_hz", o.frequencies}, {"amplitude_m", o.amplitude},
              {"direction", o.direction},   {"repeats", o.repeats},           {"first_seed", o.first_seed},
              {"silo_args", o.silo_args},   {kInputFileDigestsKey, silo_input_file_digests(o.silo_args)}};
    // absent for the whole bin: sweeps from before --part continue
    if (kernel::silo::vibrating_part_named(o.part) != kernel::silo::VibratingPart::bin) s["part"] = o.part;
    return s;
}

void check_options(const VibrationCli& o) {
    refuse_owned_silo_options(o.silo_args, kOwnedSiloOptions, "demcal vibration");
    // it delays the vibrating cells' shaking (silo_plan): with none it does nothing
    const bool any_vibrating = std::any_of(o.frequencies.begin(), o.frequencies.end(), [](double f) { return f > 0; });
    for (const std::string& a : o.silo_args)
        if (!any_vibrating && (a == "--vibration-start" || a.rfind("--vibration-start=", 0) == 0))
            throw UserError("silo option --vibration-start after -- delays the vibrating cells' shaking, and every "
                            "--frequency is 0");
    // before each cell's settings are checked (a subprocess each): a typo's millions of cells end here
    try {
        orchestrator::check_run_count(double(o.thetas.size()) * double(o.frequencies.size()) * o.repeats, o.max_runs,
                                      "--theta x --frequency x --repeats = " + std::to_string(o.thetas.size()) +
                                          " x " + std::to_string(o.frequencies.size()) + " x " +
                                          std::to_string(o.repeats));
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    check_output_folder(o.campaign, "--campaign");
    // each cell runs in a folder of its name, and each angle's curve goes to a file of its name: two cells that these
    // names cannot tell apart (an angle or frequency given twice, or closer than the names' 6 digits) would share them
    std::map<std::string, RunSpec> cells;
    for (double theta : o.thetas)
        for (double f : o.frequencies) {
            const RunSpec cell{theta, f, o.first_seed};
            const auto [at, fresh] = cells.emplace(cell.name(), cell);
            if (!fresh)
                throw UserError("--theta " + analytics::number_text(theta, 10) + " --frequency " +
                                analytics::number_text(f, 10) + ": the same run folder '" + cell.name() +
                                "' as --theta " + analytics::number_text(at->second.theta, 10) + " --frequency " +
                                analytics::number_text(at->second.frequency, 10) +
                                " (a value given twice, or two closer than 6 digits)");
        }
    bool vibrating = false;
    for (double f : o.frequencies) vibrating = vibrating || f > 0;
    if (vibrating && !(o.amplitude > 0)) throw UserError("--amplitude: a frequency above 0 needs an amplitude > 0 m");
    if (!vibrating && !o.vibration_options_given.empty())  // every cell a still bin: they were accepted and ignored
        throw UserError(o.vibration_options_given.front() +
                        " applies to a vibrating bin, and every --frequency is 0 (a still bin): leave it out, or add "
                        "a frequency above 0");
    if (o.direction != "x" && o.direction != "z")
        throw UserError("--direction = '" + o.direction.substr(0, 20) + "': x (perpendicular to the axis) or z");
    if (!kernel::silo::vibrating_part_named(o.part))
        throw UserError("--part = '" + o.part.substr(0, 20) + "': bin (every wall) or hopper (the body still)");
}

// What one run gave (NaN where it did not: a failed run, no steady discharge, a demcal without the outlet meter).
struct RunResult {
    bool finished = false, failed = false;
    bool never_vibrated = false;   // a vibrating cell's run whose discharge ended before its vibration started
    double rate = NAN;             // g/s
    double outlet_density = NAN;   // kg/m^3
    double outlet_speed = NAN;     // m/s
    std::string pattern;
};

RunResult read_run(const fs::path& dir, const RunSpec& r) {
    RunResult out;
    if (const auto s = silo_run_summary(dir, r.name())) {
        // the run in this cell's folder is this cell's run (a summary copied from another cell was counted as this one)
        const auto same = [](double a, double b) { return std::fabs(a - b) <= 1e-12 * std::max(std::fabs(a), 1.0); };
        for (const auto& [field, want] : {std::pair{std::string("geometry/theta_deg"), r.theta},
                                          std::pair{std::string("vibration/frequency_hz"), r.frequency},
                                          std::pair{std::string("settings/seed"), double(r.seed)}})
            if (!same(s->number(field), want))
                s->fail(field, "= " + analytics::number_text(s->number(field)) + ", but the cell's run has " + analytics::number_text(want) +
                                   ": not this cell's run");
        out.finished = true;
        out.pattern = s->text("flow_pattern/pattern");
        // a still discharge in a vibrating cell (--vibration-start after its end) measures no vibration: not counted
        out.never_vibrated = r.frequency > 0 && s->optional_number("vibration/vibrated_s").value_or(1) == 0;
        if (out.never_vibrated) return out;
        // no rate where the run ended without a steady discharge
        out.rate = s->optional_number("rate/rate_kg_s").value_or(NAN) * 1e3;
        if (s->optional_number("outlet_flow/frames").value_or(0) > 0) {
            out.outlet_density = s->number("outlet_flow/solid_density_kg_m3");
            out.outlet_speed = s->number("outlet_flow/downward_speed_m_s");
        }
    } else {
        out.failed = silo_run_failed(dir, r.name());
    }
    return out;
}

// Mean and sample standard deviation of the finite values (NaN where there are too few).
std::pair<double, double> mean_sd(const std::vector<double>& all) {
    std::vector<double> v;
    for (double x : all)
        if (std::isfinite(x)) v.push_back(x);
    if (v.empty()) return {NAN, NAN};
    const double mean = gsl_stats_mean(v.data(), 1, v.size());
    return {mean, v.size() > 1 ? gsl_stats_sd_m(v.data(), 1, v.size(), mean) : NAN};
}

// A change in per cent, paired seed by seed: every frequency of a seed discharges the bed that seed filled (the bin
// is still while it fills), so the still run of the same angle and seed is the reference and the seeds' own scatter
// drops out. Mean, its standard error and the number of pairs.
struct PairedChange {
    double mean = NAN, se = NAN;
    std::size_t pairs = 0;
};

PairedChange paired_change(const std::vector<double>& values, const std::vector<double>& still) {
    std::vector<double> changes;
    for (std::size_t i = 0; i < values.size(); ++i)
        if (std::isfinite(values[i]) && std::isfinite(still[i]) && still[i] != 0)
            changes.push_back(100 * (values[i] / still[i] - 1));
    const auto [mean, sd] = mean_sd(changes);
    return {mean, std::isfinite(sd) ? sd / std::sqrt(double(changes.size())) : NAN, changes.size()};
}

struct Cell {
    std::vector<RunResult> runs;
    std::vector<RunResult> still;  // the still run of each run's seed and angle (an empty result where there is none)
};

std::string number_text(double v, int digits) {
    std::ostringstream t;
    if (std::isfinite(v)) t << std::setprecision(digits) << v; else t << "-";
    return t.str();
}

std::string change_text(const PairedChange& c) {
    if (!std::isfinite(c.mean)) return "-";
    std::ostringstream t;
    t << std::showpos << std::fixed << std::setprecision(1) << c.mean << std::noshowpos;
    if (std::isfinite(c.se)) t << " (" << c.se << ")";
    return t.str();
}

json change_json(const PairedChange& c) { return {{"mean_pct", c.mean}, {"se_pct", c.se}, {"pairs", c.pairs}}; }

// Rate against frequency, one line per angle, the SD as error bars.
// The table of one angle's rates: the runs' own spelling of the angle (RunSpec::name), distinct for distinct cells.
std::string rate_table_name(double theta) {
    std::ostringstream name;
    name << "vibration_theta" << theta << ".dat";
    return name.str();
}

void plot_rates(const VibrationCli& o, const fs::path& dir, const std::map<double, std::string>& data_by_theta) {
    if (data_by_theta.empty()) return;
    std::ostringstream body;
    body << "set xlabel 'vibration frequency [Hz]'\nset ylabel 'discharge rate [g/s]'\nset key outside right\n"
         << "set title 'amplitude " << o.amplitude * 1e3 << " mm, direction " << o.direction << ", vibrating "
         << o.part << "'\nplot ";
    bool first = true;
    for (const auto& [theta, data] : data_by_theta) {
        const fs::path file = dir / rate_table_name(theta);
        write_result_file(file, data);
        body << (first ? "" : ", ") << gnuplot_quote(file) << " using 1:2:3 with yerrorlines title 'theta = "
             << theta << " deg'";
        first = false;
    }
    body << "\n";
    try {
        render_gnuplot(dir / "vibration.png", body.str());
    } catch (const std::exception& e) {
        std::cerr << "demcal vibration: warning: the plot was not drawn (" << e.what() << "); the tables are written\n";
    }
}

json run_json(const RunSpec& r, const RunResult& res) {
    json entry = {{"theta_deg", r.theta}, {"frequency_hz", r.frequency}, {"seed", r.seed}};
    if (res.never_vibrated) entry["never_vibrated"] = true;
    if (res.finished && !res.never_vibrated) {
        entry["rate_g_s"] = res.rate;
        entry["flow_pattern"] = res.pattern;
        if (std::isfinite(res.outlet_density)) {
            entry["outlet_solid_density_kg_m3"] = res.outlet_density;
            entry["outlet_downward_speed_m_s"] = res.outlet_speed;
        }
    } else if (res.failed) {
        entry["failed"] = true;
    }
    return entry;
}

// The runs by (theta, frequency), each beside the still run of its angle and seed (the same filled bed).
std::map<std::pair<double, double>, Cell> cells_of(const std::vector<RunSpec>& runs,
                                                   const std::vector<RunResult>& results) {
    std::map<std::pair<double, long long>, RunResult> still_of;  // (theta, seed)
    for (std::size_t i = 0; i < runs.size(); ++i)
        if (runs[i].frequency == 0) still_of[{runs[i].theta, runs[i].seed}] = results[i];
    std::map<std::pair<double, double>, Cell> cells;
    for (std::size_t i = 0; i < runs.size(); ++i) {
        Cell& c = cells[{runs[i].theta, runs[i].frequency}];
        c.runs.push_back(results[i]);
        const auto still = still_of.find({runs[i].theta, runs[i].seed});
        c.still.push_back(still == still_of.end() ? RunResult{} : still->second);
    }
    return cells;
}

// One cell's statistics: the rate's mean and spread, the most frequent flow pattern, and the paired changes of the
// rate and of its two factors at the outlet against the still runs.
struct CellSummary {
    double mean = NAN, sd = NAN, outlet_density = NAN, outlet_speed = NAN;
    std::size_t n = 0;  // runs with a rate
    int failed = 0;
    int never_vibrated = 0;  // runs left out: their discharge ended before the vibration started
    std::string pattern = "-";
    PairedChange rate_change, density_change, speed_change;
};

CellSummary summarize(const Cell& c, bool vibrated) {
    CellSummary s;
    std::vector<double> rates, densities, speeds, still_rates, still_densities, still_speeds;
    std::map<std::string, int> patterns;
    for (std::size_t i = 0; i < c.runs.size(); ++i) {
        const RunResult& r = c.runs[i];
        s.failed += r.failed;
        s.never_vibrated += r.never_vibrated;
        if (r.finished && !r.never_vibrated) ++patterns[r.pattern];
        rates.push_back(r.rate), densities.push_back(r.outlet_density), speeds.push_back(r.outlet_speed);
        still_rates.push_back(c.still[i].rate), still_densities.push_back(c.still[i].outlet_density);
        still_speeds.push_back(c.still[i].outlet_speed);
    }
    std::tie(s.mean, s.sd) = mean_sd(rates);
    for (double x : rates) s.n += std::isfinite(x);
    s.outlet_density = mean_sd(densities).first;
    s.outlet_speed = mean_sd(speeds).first;
    if (vibrated) {  // a still cell is its own reference: no change to report
        s.rate_change = paired_change(rates, still_rates);
        s.density_change = paired_change(densities, still_densities);
        s.speed_change = paired_change(speeds, still_speeds);
    }
    // the most frequent pattern; a tie names every pattern tied, mass/mixed (a 1-1 cell said "mass" by alphabetical
    // order; not '|', which would split the cell of vibration.md's table)
    int most = 0;
    for (const auto& [p, count] : patterns) most = std::max(most, count);
    std::string tied;
    for (const auto& [p, count] : patterns)
        if (count == most) tied += (tied.empty() ? "" : "/") + p;
    if (most > 0) s.pattern = tied;
    return s;
}

json cell_json(double theta, double f, double g, const CellSummary& s) {
    return {{"theta_deg", theta}, {"frequency_hz", f}, {"peak_acceleration_g", g},
            {"rate_mean_g_s", s.mean}, {"rate_sd_g_s", s.sd}, {"n", s.n}, {"failed", s.failed},
            {"never_vibrated", s.never_vibrated},
            {"flow_pattern", s.pattern}, {"rate_change_paired", change_json(s.rate_change)},
            {"outlet_solid_density_mean_kg_m3", s.outlet_density},
            {"outlet_density_change_paired", change_json(s.density_change)},
            {"outlet_downward_speed_mean_m_s", s.outlet_speed},
            {"outlet_speed_change_paired", change_json(s.speed_change)}};
}

std::string cell_row(double theta, double f, double g, const CellSummary& s) {
    std::ostringstream md;
    md << "| " << theta << " | " << f << " | " << number_text(g, 3) << " | " << number_text(s.mean, 5) << " | "
       << number_text(s.sd, 3) << " | " << s.n << " | " << s.pattern << " | " << change_text(s.rate_change) << " | "
       << number_text(s.outlet_density, 4) << " | " << change_text(s.density_change) << " | "
       << number_text(s.outlet_speed, 3) << " | " << change_text(s.speed_change) << " |\n";
    return md.str();
}

// Returns how many cells have a rate (a mean over at least one run whose rate was determined). `stopped`: the sweep
// stopped before its end (a signal); the report says so and counts the runs finished (a stopped sweep's report read
// as a whole one, n = 0 in every cell).
int report(const VibrationCli& o, const json& settings, const fs::path& dir, const std::vector<RunSpec>& runs,
           bool stopped) {
    std::vector<RunResult> results;
    json all = json::array();
    for (const RunSpec& r : runs) {
        results.push_back(read_run(dir, r));
        all.push_back(run_json(r, results.back()));
    }
    int cells_with_rate = 0;
    json table = json::array();
    std::ostringstream md;
    md << "| theta [deg] | f [Hz] | peak acceleration [g] | rate mean [g/s] | SD [g/s] | n | flow pattern | rate change "
          "against still, paired [%] (SE) | outlet density [kg/m^3] | its change [%] | outlet speed [m/s] | its change "
          "[%] |\n"
       << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    std::map<double, std::string> data_by_theta;
    int never_vibrated = 0;
    for (const auto& [key, c] : cells_of(runs, results)) {
        const auto [theta, f] = key;
        const CellSummary s = summarize(c, f > 0);
        never_vibrated += s.never_vibrated;
        cells_with_rate += s.n > 0;
        const double g = o.amplitude * std::pow(2 * M_PI * f, 2) / 9.81;
        table.push_back(cell_json(theta, f, g, s));
        md << cell_row(theta, f, g, s);
        if (std::isfinite(s.mean))
            data_by_theta[theta] += std::to_string(f) + " " + std::to_string(s.mean) + " " +
                                    std::to_string(std::isfinite(s.sd) ? s.sd : 0.0) + "\n";
    }
    const auto finished = std::count_if(results.begin(), results.end(), [](const RunResult& r) { return r.finished; });
    if (stopped)
        md << "\n**The sweep stopped before its end: " << finished << " of " << runs.size()
           << " runs finished; the same command continues it.**\n";
    if (never_vibrated > 0) {
        md << "\n**" << never_vibrated << " run(s) of vibrating cells discharged before their vibration started "
           << "(--vibration-start after the discharge's end): still discharges, left out of their cells (n).**\n";
        std::cerr << "demcal vibration: warning: " << never_vibrated << " run(s) of vibrating cells ended before "
                  << "their vibration started (--vibration-start): left out of their cells\n";
    }
    md << "\nChanges are paired seed by seed against the still run of the same angle and seed (the same filled bed); "
          "SE: the standard error of the pairs' mean. d ln(rate) = d ln(density) + d ln(speed) at the outlet splits a "
          "change of the rate.\n";
    const json out = {{"settings", settings}, {"complete", !stopped && finished == std::ptrdiff_t(runs.size())},
                      {"stopped", stopped},         {"runs_finished", finished},
                      {"runs_planned", runs.size()}, {"cells", table},
                      {"runs", all}};
    write_result_file(dir / "vibration.json", out.dump(1) + "\n");
    write_result_file(dir / "vibration.md", md.str());
    std::cout << md.str();
    plot_rates(o, dir, data_by_theta);
    return cells_with_rate;
}

int run(const VibrationCli& o) {
    check_options(o);
    const fs::path dir = o.campaign;
    std::vector<RunSpec> runs;  // repeat-major: an interrupted campaign has covered every cell once before repeating
    for (int k = 0; k < o.repeats; ++k)
        for (double theta : o.thetas)
            for (double f : o.frequencies) runs.push_back({theta, f, o.first_seed + k});
    std::vector<SiloRunPlan> plans;
    for (const RunSpec& r : runs) plans.push_back(silo_plan(o, r));
    // every cell's settings checked by silo itself before anything is written (the repeats differ by seed only)
    check_silo_runs({plans.begin(), plans.begin() + std::ptrdiff_t(o.thetas.size() * o.frequencies.size())});
    // the sweep's reports go into its folder: an input file kept there under one of their names would be replaced
    std::vector<NamedPath> reports;
    for (const char* name : {"vibration.json", "vibration.md", "vibration.png"})
        reports.push_back({(dir / name).string(), "the sweep's report (--campaign)"});
    for (double theta : o.thetas)
        reports.push_back({(dir / rate_table_name(theta)).string(), "the sweep's table (--campaign)"});
    check_paths_apart(silo_campaign_inputs(o.silo_args, dir), reports);
    // a run is its angle, frequency and seed under the shared settings: a grid that grows (or shrinks) is the same
    // campaign, its finished runs reused
    // read once: the report states the settings (and input digests) the runs were checked against
    const json settings = campaign_settings(o);
    open_silo_campaign(dir, settings, "vibration", {"thetas_deg", "frequencies_hz", "repeats", "first_seed"});
    const SiloCampaignOutcome outcome =
        run_silo_campaign(dir, plans, o.jobs, "vibration", {o.executor, o.partition});
    if (outcome.stopped) {
        report(o, settings, dir, runs, true);
        return kExitResumeLater;
    }
    std::cout << outcome.finished << " runs finished, " << outcome.failed << " failed\n";
    if (report(o, settings, dir, runs, false) == 0 && outcome.finished > 0) {
        std::cout << "no cell has a rate: no run's discharge rate was determined (see each run's summary.json, "
                     "rate.message), so the sweep measured nothing (exit 1)\n";
        return 1;
    }
    return outcome.failed == 0 ? 0 : 1;
}

}  // namespace

void add_vibration_command(CLI::App& app) {
    auto o = std::make_shared<VibrationCli>();
    CLI::App* sub = app.add_subcommand(
        "vibration", "vibrational-discharge sweep: hopper angles x frequencies x repeats of demcal silo, resumable");
    sub->add_option("--theta", o->thetas, "hopper half angles [deg], e.g. 10,30,60")
        ->delimiter(',')
        ->required()
        ->check(number_in(1, 89));
    sub->add_option("--frequency", o->frequencies, "frequencies [Hz], e.g. 0,25,50,100,145 (0: still bin)")
        ->delimiter(',')
        ->required()
        ->check(number_in(0, 1000));
    sub->add_option("--amplitude", o->amplitude, "vibration amplitude [m] (the seed: up to 1.1e-4)")
        ->check(number_in(0, 0.01));
    sub->add_option("--direction", o->direction, "x (perpendicular to the axis, the seed's) or z")->capture_default_str();
    sub->add_option("--part", o->part, "the walls that vibrate: bin (every wall) or hopper (the hopper and the outlet "
                                       "plate; the body still)")
        ->capture_default_str();
    sub->add_option("--repeats", o->repeats, "runs per angle and frequency (seeds first-seed, first-seed + 1, ...)")
        ->check(integer_in(1, 100))
        ->capture_default_str();
    sub->add_option("--first-seed", o->first_seed, "seed of the first repeat")->check(integer_in(0, 1LL << 62));
    sub->add_option("--campaign", o->campaign, "campaign directory (the same command continues it)")->required();
    sub->add_option("--jobs,-j", o->jobs, "runs at once (locally 1 by default: each run takes the cores --threads "
                                       "gives it; on SLURM the array's slots)")
        ->check(integer_in(1, 256))
        ->capture_default_str();
    sub->add_option("--executor", o->executor, "local (processes of this machine) or slurm (job arrays)")
        ->check(CLI::IsMember({"local", "slurm"}))
        ->capture_default_str();
    sub->add_option("--partition", o->partition, "SLURM partition (--executor slurm)");
    sub->add_option("--max-runs", o->max_runs, "most runs the sweep may plan (a guard against typos)")
        ->check(integer_in(1, 100000000))
        ->capture_default_str();
    sub->add_option("silo_args", o->silo_args, "after --: options for every demcal silo run (e.g. --geometry F "
                                               "--particles N --stiffness-scale S --threads 1)");
    sub->footer("Example: demcal vibration --theta 10,30,60 --frequency 0,50,100,145 --amplitude 1.1e-4 --repeats 3 "
                "--campaign vib -- --geometry examples/silo/reduced_conical_70deg.json --particles 4000 "
                "--stiffness-scale 0.001 --fill-time 0.5 --threads 1 --no-plots");
    sub->callback([o, sub] {
        for (const char* option : {"--amplitude", "--direction", "--part"})
            if (sub->count(option)) o->vibration_options_given.push_back(option);
        const int status = run(*o);
        if (status != 0) throw CLI::RuntimeError(status);
    });
}

}  // namespace demcal
