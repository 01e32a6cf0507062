// demcal vibration: the seed's vibrational-discharge sweep (sections 2.1.3, 3.5; figures 3.10-3.12) as a campaign of
// `demcal silo` runs: every hopper angle x frequency x repeat (seed) is one run in DIR/runs/<name>/, a subprocess of
// this demcal (its own checkpoint, its own summary.json; a crash or Ctrl-C of one run loses nothing finished). The
// same command again continues the campaign: finished runs are read, suspended ones resumed (--resume), the rest run.
// The report: per angle and frequency the discharge rate's mean, standard deviation and count, and the flow pattern;
// DIR/vibration.json, DIR/vibration.md and DIR/vibration.png (rate against frequency, one line per angle).
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/gnuplot.hpp"
#include "app/silo_campaign.hpp"
#include "kernel/silo/bin_vibration.hpp"
#include "orchestrator/shear_campaign.hpp"  // check_run_count
#include "orchestrator/run_identity.hpp"  // write_text_file_atomically

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
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
    a.insert(a.end(), o.silo_args.begin(), o.silo_args.end());
    return {r.name(), a};
}

json campaign_settings(const VibrationCli& o) {
    json s = {{"thetas_deg", o.thetas},     {"frequencies_hz", o.frequencies}, {"amplitude_m", o.amplitude},
              {"direction", o.direction},   {"repeats", o.repeats},           {"first_seed", o.first_seed},
              {"silo_args", o.silo_args}};
    // absent for the whole bin: sweeps from before --part continue
    if (kernel::silo::vibrating_part_named(o.part) != kernel::silo::VibratingPart::bin) s["part"] = o.part;
    return s;
}

void check_options(const VibrationCli& o) {
    refuse_owned_silo_options(o.silo_args, kOwnedSiloOptions, "demcal vibration");
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
    bool vibrating = false;
    for (double f : o.frequencies) vibrating = vibrating || f > 0;
    if (vibrating && !(o.amplitude > 0)) throw UserError("--amplitude: a frequency above 0 needs an amplitude > 0 m");
    if (o.direction != "x" && o.direction != "z")
        throw UserError("--direction = '" + o.direction.substr(0, 20) + "': x (perpendicular to the axis) or z");
    if (!kernel::silo::vibrating_part_named(o.part))
        throw UserError("--part = '" + o.part.substr(0, 20) + "': bin (every wall) or hopper (the body still)");
}

struct Cell {
    std::vector<double> rates;  // g/s
    std::vector<double> outlet_densities, outlet_speeds;  // kg/m^3, m/s (runs of a demcal that measures them)
    std::map<std::string, int> patterns;
    int failed = 0;
};

// Mean and sample standard deviation (NaN where there are too few values).
std::pair<double, double> mean_sd(const std::vector<double>& v) {
    double mean = NAN, sd = NAN;
    if (v.empty()) return {mean, sd};
    mean = 0;
    for (double x : v) mean += x;
    mean /= double(v.size());
    if (v.size() > 1) {
        sd = 0;
        for (double x : v) sd += (x - mean) * (x - mean);
        sd = std::sqrt(sd / double(v.size() - 1));
    }
    return {mean, sd};
}

void report(const VibrationCli& o, const fs::path& dir, const std::vector<RunSpec>& runs) {
    std::map<std::pair<double, double>, Cell> cells;
    json all = json::array();
    for (const RunSpec& r : runs) {
        Cell& c = cells[{r.theta, r.frequency}];
        json entry = {{"theta_deg", r.theta}, {"frequency_hz", r.frequency}, {"seed", r.seed}};
        if (const auto s = silo_run_summary(dir, r.name())) {
            // no rate where the run ended without a steady discharge
            const double rate = s->optional_number("rate/rate_kg_s").value_or(NAN) * 1e3;
            const std::string pattern = s->text("flow_pattern/pattern");
            entry["rate_g_s"] = rate;
            entry["flow_pattern"] = pattern;
            if (std::isfinite(rate)) c.rates.push_back(rate);
            ++c.patterns[pattern];
            if (s->optional_number("outlet_flow/frames").value_or(0) > 0) {
                const double density = s->number("outlet_flow/solid_density_kg_m3");
                const double speed = s->number("outlet_flow/downward_speed_m_s");
                entry["outlet_solid_density_kg_m3"] = density;
                entry["outlet_downward_speed_m_s"] = speed;
                c.outlet_densities.push_back(density);
                c.outlet_speeds.push_back(speed);
            }
        } else if (silo_run_failed(dir, r.name())) {
            entry["failed"] = true;
            ++c.failed;
        }
        all.push_back(entry);
    }
    json table = json::array();
    std::ostringstream md;
    md << "| theta [deg] | f [Hz] | peak acceleration [g] | rate mean [g/s] | SD [g/s] | n | flow pattern | outlet "
          "density [kg/m^3] | outlet speed [m/s] |\n"
       << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    std::map<double, std::string> data_by_theta;
    for (const auto& [key, c] : cells) {
        const auto [theta, f] = key;
        const auto [mean, sd] = mean_sd(c.rates);
        const double outlet_density = mean_sd(c.outlet_densities).first, outlet_speed = mean_sd(c.outlet_speeds).first;
        std::string pattern = "-";
        int most = 0;
        for (const auto& [p, n] : c.patterns)
            if (n > most) pattern = p, most = n;
        const double g = o.amplitude * std::pow(2 * M_PI * f, 2) / 9.81;
        table.push_back({{"theta_deg", theta}, {"frequency_hz", f}, {"peak_acceleration_g", g},
                         {"rate_mean_g_s", mean}, {"rate_sd_g_s", sd}, {"n", c.rates.size()}, {"failed", c.failed},
                         {"flow_pattern", pattern}, {"outlet_solid_density_mean_kg_m3", outlet_density},
                         {"outlet_downward_speed_mean_m_s", outlet_speed}});
        auto cell = [](double v, int digits) {
            std::ostringstream t;
            if (std::isfinite(v)) t << std::setprecision(digits) << v; else t << "-";
            return t.str();
        };
        md << "| " << theta << " | " << f << " | " << cell(g, 3) << " | " << cell(mean, 5) << " | " << cell(sd, 3)
           << " | " << c.rates.size() << " | " << pattern << " | " << cell(outlet_density, 4) << " | "
           << cell(outlet_speed, 3) << " |\n";
        if (std::isfinite(mean))
            data_by_theta[theta] += std::to_string(f) + " " + std::to_string(mean) + " " +
                                    std::to_string(std::isfinite(sd) ? sd : 0.0) + "\n";
    }
    const json out = {{"settings", campaign_settings(o)}, {"cells", table}, {"runs", all}};
    orchestrator::write_text_file_atomically(dir / "vibration.json", out.dump(1) + "\n");
    orchestrator::write_text_file_atomically(dir / "vibration.md", md.str());
    std::cout << md.str();
    if (data_by_theta.empty()) return;
    std::ostringstream body;
    body << "set xlabel 'vibration frequency [Hz]'\nset ylabel 'discharge rate [g/s]'\nset key outside right\n"
         << "set title 'amplitude " << o.amplitude * 1e3 << " mm, direction " << o.direction << ", vibrating "
         << o.part << "'\nplot ";
    bool first = true;
    for (const auto& [theta, data] : data_by_theta) {
        const fs::path file = dir / ("vibration_theta" + std::to_string(int(std::lround(theta))) + ".dat");
        std::ofstream(file) << data;
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
    open_silo_campaign(dir, campaign_settings(o), "vibration");
    const SiloCampaignOutcome outcome =
        run_silo_campaign(dir, plans, o.silo_args, o.jobs, "vibration", {o.executor, o.partition});
    if (outcome.stopped) {
        report(o, dir, runs);
        return kExitResumeLater;
    }
    std::cout << outcome.finished << " runs finished, " << outcome.failed << " failed\n";
    report(o, dir, runs);
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
    sub->add_option("--jobs", o->jobs, "runs at once (locally 1 by default: each run takes the cores --threads "
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
    sub->callback([o] {
        const int status = run(*o);
        if (status != 0) throw CLI::RuntimeError(status);
    });
}

}  // namespace demcal
