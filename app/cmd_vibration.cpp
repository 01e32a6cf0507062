// demcal vibration: the seed's vibrational-discharge sweep (sections 2.1.3, 3.5; figures 3.10-3.12) as a campaign of
// `demcal silo` runs: every hopper angle x frequency x repeat (seed) is one run in DIR/runs/<name>/, a subprocess of
// this demcal (its own checkpoint, its own summary.json; a crash or Ctrl-C of one run loses nothing finished). The
// same command again continues the campaign: finished runs are read, suspended ones resumed (--resume), the rest run.
// The report: per angle and frequency the discharge rate's mean, standard deviation and count, and the flow pattern;
// DIR/vibration.json, DIR/vibration.md and DIR/vibration.png (rate against frequency, one line per angle).
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/gnuplot.hpp"
#include "orchestrator/run_identity.hpp"  // write_text_file_atomically

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace demcal {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct VibrationCli {
    std::vector<double> thetas, frequencies;
    double amplitude = 0;
    std::string direction = "x";
    int repeats = 3;
    long long first_seed = 1;
    std::string campaign;
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
const char* const kOwnedSiloOptions[] = {"--theta", "--seed", "--out", "--resume", "--vibration-frequency",
                                         "--vibration-amplitude", "--vibration-direction", "--check"};

std::vector<std::string> silo_command(const VibrationCli& o, const RunSpec& r, const fs::path& out, bool check) {
    auto num = [](double v) {
        std::ostringstream s;
        s << std::setprecision(17) << v;
        return s.str();
    };
    std::vector<std::string> a{"silo", "--theta", num(r.theta), "--seed", std::to_string(r.seed), "--out", out.string()};
    if (r.frequency > 0)
        a.insert(a.end(), {"--vibration-frequency", num(r.frequency), "--vibration-amplitude", num(o.amplitude),
                           "--vibration-direction", o.direction});
    a.insert(a.end(), o.silo_args.begin(), o.silo_args.end());
    if (check) a.push_back("--check");
    return a;
}

// `demcal silo --resume DIR` with the session options of the silo options (the rest is in the checkpoint).
std::vector<std::string> resume_command(const VibrationCli& o, const fs::path& dir) {
    std::vector<std::string> a{"silo", "--resume", dir.string()};
    for (std::size_t k = 0; k < o.silo_args.size(); ++k) {
        const std::string& arg = o.silo_args[k];
        if (arg == "--no-plots") a.push_back(arg);
        if ((arg == "--threads" || arg == "--checkpoint-every" || arg == "--wall-limit") && k + 1 < o.silo_args.size())
            a.insert(a.end(), {arg, o.silo_args[k + 1]});
    }
    return a;
}

// Runs this demcal with `args`, stdout and stderr to `log`; returns its exit status.
int run_demcal(const std::vector<std::string>& args, const fs::path& log) {
    std::vector<char*> argv;
    // this very binary, even when the file was replaced since it started (a rebuild during a long sweep)
    std::string self = "/proc/self/exe";
    argv.push_back(self.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    posix_spawnattr_t attr;  // the run gets the default dispositions (it checkpoints on SIGINT/SIGTERM itself)
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF);
    pid_t pid = 0;
    const int err = posix_spawn(&pid, self.c_str(), &fa, &attr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&attr);
    if (err != 0) throw std::runtime_error("cannot start " + self + ": " + std::strerror(err));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

json campaign_settings(const VibrationCli& o) {
    return {{"thetas_deg", o.thetas},     {"frequencies_hz", o.frequencies}, {"amplitude_m", o.amplitude},
            {"direction", o.direction},   {"repeats", o.repeats},           {"first_seed", o.first_seed},
            {"silo_args", o.silo_args}};
}

void check_options(const VibrationCli& o) {
    for (const std::string& a : o.silo_args)
        for (const char* owned : kOwnedSiloOptions)
            if (a == owned || a.rfind(std::string(owned) + "=", 0) == 0)
                throw UserError("silo option " + a + " after --: demcal vibration sets it for every run");
    bool vibrating = false;
    for (double f : o.frequencies) vibrating = vibrating || f > 0;
    if (vibrating && !(o.amplitude > 0)) throw UserError("--amplitude: a frequency above 0 needs an amplitude > 0 m");
    if (o.direction != "x" && o.direction != "z")
        throw UserError("--direction = '" + o.direction.substr(0, 20) + "': x (perpendicular to the axis) or z");
}

struct Cell {
    std::vector<double> rates;  // g/s
    std::map<std::string, int> patterns;
    int failed = 0;
};

void report(const VibrationCli& o, const fs::path& dir, const std::vector<RunSpec>& runs) {
    std::map<std::pair<double, double>, Cell> cells;
    json all = json::array();
    for (const RunSpec& r : runs) {
        Cell& c = cells[{r.theta, r.frequency}];
        const fs::path summary = dir / "runs" / r.name() / "summary.json";
        json entry = {{"theta_deg", r.theta}, {"frequency_hz", r.frequency}, {"seed", r.seed}};
        if (fs::exists(summary)) {
            const json s = read_json_file(summary.string(), "run summary");
            const double rate = s.at("rate").value("rate_kg_s", NAN) * 1e3;
            const std::string pattern = s.at("flow_pattern").value("pattern", "?");
            entry["rate_g_s"] = rate;
            entry["flow_pattern"] = pattern;
            if (std::isfinite(rate)) c.rates.push_back(rate);
            ++c.patterns[pattern];
        } else if (fs::exists(dir / "runs" / r.name() / "failed")) {
            entry["failed"] = true;
            ++c.failed;
        }
        all.push_back(entry);
    }
    json table = json::array();
    std::ostringstream md;
    md << "| theta [deg] | f [Hz] | peak acceleration [g] | rate mean [g/s] | SD [g/s] | n | flow pattern |\n"
       << "| --- | --- | --- | --- | --- | --- | --- |\n";
    std::map<double, std::string> data_by_theta;
    for (const auto& [key, c] : cells) {
        const auto [theta, f] = key;
        double mean = NAN, sd = NAN;
        if (!c.rates.empty()) {
            mean = 0;
            for (double x : c.rates) mean += x;
            mean /= double(c.rates.size());
            if (c.rates.size() > 1) {
                sd = 0;
                for (double x : c.rates) sd += (x - mean) * (x - mean);
                sd = std::sqrt(sd / double(c.rates.size() - 1));
            }
        }
        std::string pattern = "-";
        int most = 0;
        for (const auto& [p, n] : c.patterns)
            if (n > most) pattern = p, most = n;
        const double g = o.amplitude * std::pow(2 * M_PI * f, 2) / 9.81;
        table.push_back({{"theta_deg", theta}, {"frequency_hz", f}, {"peak_acceleration_g", g},
                         {"rate_mean_g_s", mean}, {"rate_sd_g_s", sd}, {"n", c.rates.size()}, {"failed", c.failed},
                         {"flow_pattern", pattern}});
        auto cell = [](double v, int digits) {
            std::ostringstream t;
            if (std::isfinite(v)) t << std::setprecision(digits) << v; else t << "-";
            return t.str();
        };
        md << "| " << theta << " | " << f << " | " << cell(g, 3) << " | " << cell(mean, 5) << " | " << cell(sd, 3)
           << " | " << c.rates.size() << " | " << pattern << " |\n";
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
         << "set title 'amplitude " << o.amplitude * 1e3 << " mm, direction " << o.direction << "'\nplot ";
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

volatile std::sig_atomic_t g_stop_requested = 0;
extern "C" void request_stop(int) { g_stop_requested = 1; }

int run(const VibrationCli& o) {
    check_options(o);
    // Ctrl-C or SIGTERM: the running silo run checkpoints and exits 75 (it gets the signal too, or is sent it); this
    // process waits for it and stops the sweep (the same command continues it)
    std::signal(SIGINT, request_stop);
    std::signal(SIGTERM, request_stop);
    const fs::path dir = o.campaign;
    std::vector<RunSpec> runs;  // repeat-major: an interrupted campaign has covered every cell once before repeating
    for (int k = 0; k < o.repeats; ++k)
        for (double theta : o.thetas)
            for (double f : o.frequencies) runs.push_back({theta, f, o.first_seed + k});
    // every cell's settings checked by silo itself before anything is written (the repeats differ by seed only)
    const fs::path scratch = fs::temp_directory_path() / ("demcal-vibration-check-" + std::to_string(::getpid()));
    for (std::size_t k = 0; k < o.thetas.size() * o.frequencies.size(); ++k) {
        const fs::path log = scratch.string() + ".log";
        const int rc = run_demcal(silo_command(o, runs[k], scratch / runs[k].name(), true), log);
        std::ifstream is(log);
        std::stringstream text;
        text << is.rdbuf();
        fs::remove(log);
        if (rc != 0) throw UserError("run " + runs[k].name() + ": " + text.str().substr(0, 500));
    }
    const json settings = campaign_settings(o);
    const fs::path settings_file = dir / "campaign.json";
    if (fs::exists(settings_file)) {
        if (read_json_file(settings_file.string(), "campaign settings") != settings)
            throw UserError("campaign = '" + dir.string() + "' holds a sweep with other settings (" +
                            settings_file.string() + "): give another --campaign, or the same settings to continue it");
    } else {
        fs::create_directories(dir / "runs");
        orchestrator::write_text_file_atomically(settings_file, settings.dump(1) + "\n");
    }
    std::size_t done = 0, failed = 0;
    for (const RunSpec& r : runs) {
        const fs::path rd = dir / "runs" / r.name();
        if (fs::exists(rd / "summary.json")) { ++done; continue; }
        if (fs::exists(rd / "failed")) { ++failed; continue; }
        const bool resume = fs::exists(rd / "checkpoint.bin");
        fs::create_directories(rd);
        std::cout << "[" << done + failed + 1 << "/" << runs.size() << "] " << r.name() << (resume ? " (resumed)" : "")
                  << std::endl;
        const int rc = resume ? run_demcal(resume_command(o, rd), rd / "silo.log")
                              : run_demcal(silo_command(o, r, rd, false), rd / "silo.log");
        if (rc == 0 && !g_stop_requested) { ++done; continue; }
        if (rc == 0) ++done;
        if (rc == 0 || rc == kExitResumeLater || rc == 128 + SIGINT || rc == 128 + SIGTERM || g_stop_requested) {
            std::cout << "stopped at " << r.name() << " (exit " << rc << "); the same command continues the sweep\n";
            report(o, dir, runs);
            return kExitResumeLater;
        }
        std::ofstream(rd / "failed") << "exit status " << rc << "; see silo.log\n";
        std::cerr << "demcal vibration: run " << r.name() << " failed (exit " << rc << "), see " << (rd / "silo.log")
                  << "\n";
        ++failed;
    }
    std::cout << done << " runs finished, " << failed << " failed\n";
    report(o, dir, runs);
    return failed == 0 ? 0 : 1;
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
    sub->add_option("--repeats", o->repeats, "runs per angle and frequency (seeds first-seed, first-seed + 1, ...)")
        ->check(integer_in(1, 100))
        ->capture_default_str();
    sub->add_option("--first-seed", o->first_seed, "seed of the first repeat")->check(integer_in(0, 1LL << 62));
    sub->add_option("--campaign", o->campaign, "campaign directory (the same command continues it)")->required();
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
