// demcal cutoff: the lowest vibration frequency at which a cohesive bed arched over a hopper's outlet flows, in a
// small hopper of JKR spheres (kernel/cases/cohesive_hopper.hpp) or, with silo options after --, in the silo case
// with a cohesive material (kernel/silo/silo_case.hpp); measured cases in examples/cohesive_arch/README.md.
#include "app/cli_support.hpp"
#include "orchestrator/campaign_suspended.hpp"
#include "orchestrator/executor.hpp"
#include "kernel/walls/wall_motion.hpp"
#include "app/commands.hpp"
#include "app/result_files.hpp"
#include "app/silo_campaign.hpp"
#include "app/silo_settings.hpp"
#include "kernel/cases/cohesive_hopper.hpp"
#include "analytics/number_text.hpp"
#include "kernel/silo/input_error.hpp"  // setting_text
#include "kernel/silo/silo_case.hpp"
#include "orchestrator/run_identity.hpp"  // sha256_hex
#include "orchestrator/shear_campaign.hpp"  // check_run_count

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

namespace demcal {

namespace {

namespace kc = kernel::cases;
namespace fs = std::filesystem;

struct CutoffCli {
    kc::CohesiveHopperCase base;
    std::string bracket = "0,400";
    std::string criterion{kc::flow_criterion_name(kc::FlowCriterion::flow_stops)};
    double tol = 25;
    double max_window = 0;  // 0: not given (kDefaultWindowFactor x --window by flow-stops)
    std::vector<long long> seeds{1};
    std::string json;
    long max_runs = 10000;
    std::vector<std::string> silo_args;  // after --: the silo case (demcal silo's options) instead of the small hopper
    // the silo search's runs: a campaign of demcal silo subprocesses (default folder: campaigns/cutoff-<hash of the
    // settings>), the seeds of a frequency side by side
    std::string campaign;
    int jobs = 1;
    std::string executor = "local", partition;
};

// The silo options a cut-off search sets for every run itself.
const std::vector<std::string> kOwnedSiloOptions{"--seed", "--vibration-frequency", "--vibration-amplitude",
                                                 "--vibration-direction", "--vibration-start", "--stop-fraction",
                                                 "--max-time"};
// The small hopper's own options, which a silo search does not use (the silo options after -- say the case).
constexpr const char* kHopperOptions[] = {"--bond-number", "--theta", "--grains"};
// The silo search's own options (its campaign), which the small hopper (run in this process) does not use.
constexpr const char* kSiloSearchOptions[] = {"--campaign", "--jobs", "--executor", "--partition"};

// Without --max-window a run still discharging at its window's end runs again in up to this many times the window
// (two doublings): the silo's meal at 40 deg had two of three runs at 50 Hz undecided at 5 s, both decided by 10 s.
constexpr double kDefaultWindowFactor = 4;

// Every run of a search ends once this fraction of the filled mass is out (by either criterion it has flowed then),
// when its flow stops, or at the window's end.
constexpr double kFlowingFraction = 0.5;

std::pair<double, double> parse_bracket(const std::string& text) {
    const auto comma = text.find(',');
    const std::string shown = "--bracket = '" + analytics::shortened_text(text, 40) + "'";
    if (comma == std::string::npos) throw UserError(shown + ": give LO,HI in Hz, e.g. 0,400");
    double ends[2];
    const std::string parts[2] = {analytics::trimmed(text.substr(0, comma)), analytics::trimmed(text.substr(comma + 1))};
    for (int i = 0; i < 2; ++i) {  // the number rule of every option (a subnormal or NaN end was searched)
        const auto n = analytics::read_typed_number(parts[i]);
        if (!n.is_number) throw UserError(shown + ": give LO,HI in Hz, e.g. 0,400");
        if (n.defect) throw UserError(shown + ": '" + analytics::shortened_text(parts[i], 40) + "' " + *n.defect);
        ends[i] = n.value;
    }
    return {ends[0], ends[1]};
}

// The runs the search may make (both ends, then every bisection, each with every seed in every window of its
// ladder at most), refused above --max-runs
// before the first run; a tolerance finer than the search's bisection bound (kc::kMaxBisections) is refused naming
// the option.
void check_search_size(const kc::CutoffSearch& s, double first_window, long max_runs) {
    const double width = s.hi - s.lo;
    if (!(width > 0) || !(s.tol > 0) || s.tol >= width) return;  // kc::validate names these
    if (s.tol < std::ldexp(width, -kc::kMaxBisections))
        throw UserError("--tol = " + analytics::number_text(s.tol) + " Hz: finer than 2^-" +
                        std::to_string(kc::kMaxBisections) + " of the bracket (" + analytics::number_text(width) +
                        " Hz), more bisections than frequencies a run can tell apart");
    const int bisections = static_cast<int>(std::ceil(std::log2(width / s.tol)));
    const std::size_t windows = kc::window_ladder(first_window, s.longest_window).size();
    orchestrator::check_run_count(static_cast<double>(2 + bisections) * s.seeds.size() * windows, max_runs,
                                  "cutoff: (2 ends + " + std::to_string(bisections) + " bisections) x " +
                                      std::to_string(s.seeds.size()) + " seeds" +
                                      (windows > 1 ? " x up to " + std::to_string(windows) + " windows" : ""));
}

// The lowest frequency the search can run (its low end, or from 0 its finest bisection) must still shake the bed:
// a run below kMinVibrationPeakAcceleration is refused, which would end the search midway.
void check_weakest_shaking(const kc::CutoffSearch& s, double amplitude) {
    const double width = s.hi - s.lo;
    if (!(width > 0) || !(s.tol > 0) || s.tol >= width) return;  // kc::validate names these
    const double lowest = s.lo > 0 ? s.lo : std::ldexp(width, -static_cast<int>(std::ceil(std::log2(width / s.tol))));
    if (amplitude * std::pow(2 * M_PI * lowest, 2) >= kernel::kMinVibrationPeakAcceleration) return;  // (the top: validate)
    if (const std::string defect = kernel::vibration_strength_defect(amplitude, lowest); !defect.empty())
        throw UserError("--amplitude = " + analytics::number_text(amplitude) + " m with --bracket " +
                        analytics::number_text(s.lo) + "," + analytics::number_text(s.hi) + " and --tol " +
                        analytics::number_text(s.tol) + ": the lowest frequency the search may run, " + defect +
                        "; give a larger amplitude, a coarser --tol or a higher low end");
}

kc::CutoffSearch search_from(const CutoffCli& o) {
    kc::CutoffSearch search;
    std::tie(search.lo, search.hi) = parse_bracket(o.bracket);
    search.tol = o.tol;
    for (const auto& [criterion, name] : kc::kFlowCriterionNames)
        if (name == o.criterion) search.criterion = criterion;  // the option's check admits the names only
    search.seeds.assign(o.seeds.begin(), o.seeds.end());
    search.longest_window = o.max_window > 0 ? o.max_window
                            : search.criterion == kc::FlowCriterion::flow_stops
                                ? std::min(kDefaultWindowFactor * o.base.window, kc::kWindowMax)
                                : o.base.window;
    // a seed twice is one bed counted twice in the majority (and one run folder for two runs)
    for (std::size_t i = 0; i < o.seeds.size(); ++i)
        if (std::find(o.seeds.begin(), o.seeds.begin() + i, o.seeds[i]) != o.seeds.begin() + i)
            throw UserError("--seeds: seed " + std::to_string(o.seeds[i]) + " is given twice");
    // without vibration every frequency is the same still bed: the search would bisect nothing
    if (!(o.base.amplitude > 0))
        throw UserError("--amplitude = " + analytics::number_text(o.base.amplitude) +
                        " m: the cut-off search vibrates the bin; give an amplitude > 0");
    try {
        check_search_size(search, o.base.window, o.max_runs);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    check_weakest_shaking(search, o.base.amplitude);
    return search;
}

// One seed's own bracket in words: "arched up to 50 Hz, flows from 100 Hz".
std::string seed_bracket_text(const kc::SeedBracket& b) {
    const auto hz = [](double f) { return kernel::silo::setting_text(f) + " Hz"; };
    std::string text = !b.flows_from    ? "arched at every frequency run (up to " + hz(b.arched_up_to.value_or(0)) + ")"
                       : !b.arched_up_to ? "flowed at every frequency run (from " + hz(*b.flows_from) + ")"
                                         : "arched up to " + hz(*b.arched_up_to) + ", flows from " + hz(*b.flows_from);
    if (b.inconsistent) text += "; it also arched above a frequency at which it flowed";
    return text;
}

// Each seed's own bracket, printed and added to the report; a note where the seeds' brackets do not meet the
// majority's (the cut-off then differs from bed to bed by more than the tolerance).
void report_seed_brackets(const kc::CutoffResult& res, nlohmann::json& out) {
    const auto brackets = kc::seed_brackets(res.runs);
    out["seeds"] = nlohmann::json::array();
    bool all_overlap = true;
    for (const auto& b : brackets) {
        const bool overlap = !res.found || kc::overlaps(b, res.lo, res.hi);
        all_overlap = all_overlap && overlap;
        std::printf("  seed %u on its own: %s\n", b.seed, seed_bracket_text(b).c_str());
        out["seeds"].push_back({{"seed", b.seed},
                                {"arched_up_to_hz", b.arched_up_to ? nlohmann::json(*b.arched_up_to) : nullptr},
                                {"flows_from_hz", b.flows_from ? nlohmann::json(*b.flows_from) : nullptr},
                                {"inconsistent", b.inconsistent},
                                {"overlaps_cutoff", overlap}});
    }
    out["seeds_agree"] = all_overlap;
    if (!all_overlap)
        std::printf("note: the seeds' own brackets do not all meet the cut-off's: it is the majority's (at least half "
                    "of the seeds flowing), and the cut-off differs from bed to bed by more than the tolerance\n");
}

// The runs still discharging at the end of the longest window, counted and named in a note: by the flow-stops
// criterion they flow (their flow had not stopped), and a longer --max-window would decide them. (A run at the end of
// a shorter window ran again in a longer one.)
void report_window_end_runs(kc::FlowCriterion criterion, double longest_window, nlohmann::json& out) {
    long undecided = 0, extended = 0;
    for (const auto& run : out.at("runs")) {
        if (run.at("end") != kernel::silo::discharge_end_name(kernel::silo::DischargeEnd::time_limit)) continue;
        (run.at("window_s").get<double>() >= longest_window ? undecided : extended) += 1;
    }
    out["runs_at_window_end"] = undecided;
    out["runs_run_again_in_a_longer_window"] = extended;
    if (undecided > 0 && criterion == kc::FlowCriterion::flow_stops)
        std::printf("note: %ld run(s) still discharging at the end of the longest window (%g s) counted as flowing; "
                    "a longer --max-window decides whether their flow stops\n",
                    undecided, longest_window);
}

// The windows of a search in words: "window 5 s" or "window 5 s, a run still discharging at its end again in 10, 20 s".
std::string ladder_text(const std::vector<double>& ladder) {
    std::string text = "window " + kernel::silo::setting_text(ladder.front()) + " s";
    for (std::size_t k = 1; k < ladder.size(); ++k)
        text += (k == 1 ? ", a run still discharging at its end again in " : ", ") +
                kernel::silo::setting_text(ladder[k]) + (k + 1 == ladder.size() ? " s" : "");
    return text;
}

// What a run's end says by the criterion, for its printed line: flows, arched, or undecided (a longer window decides).
const char* answer_word(kc::FlowCriterion c, kernel::silo::DischargeEnd end) {
    return !kc::decided(c, end) ? "undecided" : kc::flows(c, end) ? "flows" : "arched";
}

// The search's result, printed and added to the JSON report; the exit status.
int conclude(const kc::CutoffResult& res, nlohmann::json out, const std::string& json_file) {
    if (res.found) {
        out["cutoff_hz"] = {res.lo, res.hi};
        std::printf("cut-off frequency in [%g, %g] Hz\n", res.lo, res.hi);
    } else {
        out["cutoff_hz"] = nullptr;
        out["reason"] = res.reason;
        std::printf("no cut-off found: %s\n", res.reason);
        std::fprintf(stderr, "demcal: no cut-off found: %s (exit 1; the runs are kept)\n", res.reason);
    }
    if (res.runs.size() > 0) report_seed_brackets(res, out);
    if (!json_file.empty()) write_result_file(json_file, out.dump(1) + "\n");
    return res.found ? 0 : 1;
}

// One silo run of the search: the base settings with this seed and frequency, stopped once half the mass is out, when
// its flow stops (the silo's stall rule) or at the window's end.
kernel::silo::SiloCaseSettings silo_run_settings(kernel::silo::SiloCaseSettings s, double frequency, unsigned seed,
                                                 double amplitude, double window) {
    s.seed = seed;
    s.stop_fraction = kFlowingFraction;
    s.max_time = window;
    s.vibration = {};
    if (frequency > 0 && amplitude > 0) {
        s.vibration.frequency = frequency;
        s.vibration.amplitude = amplitude;  // horizontal (x), the whole bin, from the opening: as the small hopper
    }
    return s;
}

// The same run as demcal silo's options, for the campaign (silo_run_settings is what they parse to); named by its
// frequency and seed, and by its window where it is longer than the campaign's (a run again in a longer window), the
// rest being the campaign's settings.
SiloRunPlan silo_run_plan(const CutoffCli& o, double frequency, unsigned seed, double window) {
    std::vector<std::string> a = o.silo_args;
    if (std::find(a.begin(), a.end(), "--no-plots") == a.end()) a.push_back("--no-plots");  // a search reads numbers
    a.insert(a.end(), {"--seed", std::to_string(seed), "--stop-fraction", silo_number(kFlowingFraction), "--max-time",
                       silo_number(window)});
    if (frequency > 0 && o.base.amplitude > 0)
        a.insert(a.end(), {"--vibration-frequency", silo_number(frequency), "--vibration-amplitude",
                           silo_number(o.base.amplitude)});
    std::ostringstream name;
    name << "f" << std::setprecision(12) << frequency << "_seed" << seed;
    if (window != o.base.window) name << "_w" << window;
    return {name.str(), a};
}

// What every run of a silo search shares: the campaign's identity. Searches that differ only by bracket, tolerance
// or seeds share a campaign and reuse each other's runs.
nlohmann::json silo_campaign_settings(const CutoffCli& o) {
    return {{"command", "cutoff"},         {"silo_args", o.silo_args},     {"amplitude_m", o.base.amplitude},
            {"direction", "x"},            {"window_s", o.base.window},    {"flowing_fraction", kFlowingFraction},
            {kInputFileDigestsKey, silo_input_file_digests(o.silo_args)}};
}

struct SearchStopped {};  // a signal or a suspended run stopped the campaign: the same command continues it

// One finished run of the campaign, read from its summary.json: the line printed and the JSON entry; how it ended.
// A run that failed ends the search (its log named).
// `run`: its settings (silo_run_settings), whose vibration gives the peak acceleration and max_time the window.
kernel::silo::DischargeEnd read_search_run(const fs::path& dir, const SiloRunPlan& plan, double frequency,
                     const kernel::silo::SiloCaseSettings& run, kc::FlowCriterion criterion, nlohmann::json& runs) {
    const unsigned seed = static_cast<unsigned>(run.seed);
    const auto summary = silo_run_summary(dir, plan.name);
    if (!summary)
        throw std::runtime_error("the silo run " + plan.name + " failed or left no summary: see " +
                                 (dir / "runs" / plan.name / "silo.log").string());
    const double filled = summary->number("filled_mass_kg");
    const double fraction = filled > 0 ? summary->number("discharge/discharged_mass_kg") / filled : 0;
    const std::string end_name = summary->text("discharge/end");
    const auto end = kernel::silo::discharge_end_from_name(end_name);
    if (!end || *end == kernel::silo::DischargeEnd::running || *end == kernel::silo::DischargeEnd::suspended)
        summary->fail("discharge/end", "= '" + analytics::shortened_text(end_name, 40) + "': not how a finished run ends");
    const bool flows = kc::flows(criterion, *end);
    const double peak_g = run.vibration.peak_acceleration() / run.gravity;
    const std::string stop_reason = summary->text("discharge/stop_reason");
    const double cpu = summary->number("cpu_s"), discharge_time = summary->number("discharge/time_s");
    const bool decided = kc::decided(criterion, *end);
    std::printf("  f = %6.1f Hz (%6.2f g), seed %u: %5.1f %% of %.1f g out in %.2f s -> %s  [%s; %.1f s CPU]\n",
                frequency, peak_g, seed, 100 * fraction, 1e3 * filled, discharge_time,
                answer_word(criterion, *end), stop_reason.c_str(), cpu);
    std::fflush(stdout);
    runs.push_back({{"frequency_hz", frequency}, {"seed", seed}, {"run", plan.name}, {"peak_acceleration_g", peak_g},
                    {"discharged_fraction", fraction}, {"filled_mass_kg", filled},
                    {"bulk_density_kg_m3", summary->number("bulk_density_kg_m3")}, {"discharge_time_s", discharge_time},
                    {"window_s", run.max_time}, {"end", end_name}, {"stop_reason", stop_reason}, {"flows", flows},
                    {"decided", decided}, {"cpu_s", cpu},
                    {"wall_s", summary->number("wall_s")}});
    return *end;
}

int run_silo_search(const CutoffCli& o, CLI::App& sub) {
    namespace ks = kernel::silo;
    for (const char* option : kHopperOptions)
        if (sub.count(option))
            throw UserError(std::string(option) + " applies to the small hopper; with silo options after -- the silo "
                            "case and its material say it (--theta and --material there)");
    refuse_owned_silo_options(o.silo_args, kOwnedSiloOptions, "demcal cutoff");
    if (!o.json.empty()) check_output_file(o.json, "--json");
    const ks::SiloCaseSettings base = silo_case_settings(o.silo_args, "demcal cutoff");
    const kc::CutoffSearch search = search_from(o);
    try {
        kc::validate(search);
        for (double f : {search.lo, search.hi})  // every frequency of the search lies in the bracket
            ks::validate(silo_run_settings(base, f, search.seeds.front(), o.base.amplitude, o.base.window));
        kc::validate_window(o.base.window, search.criterion);
        kc::validate_window_ladder(o.base.window, search.longest_window, search.criterion);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    const std::vector<double> ladder = kc::window_ladder(o.base.window, search.longest_window);
    // the longest run the search may start, checked by demcal silo itself (its step count: the first window's runs
    // passed where a 20 s one would not end)
    if (ladder.size() > 1) check_silo_runs({silo_run_plan(o, search.hi, search.seeds.front(), ladder.back())});
    const nlohmann::json settings = silo_campaign_settings(o);
    nlohmann::json named = settings;  // the folder named by the search, not by the spelling of its silo options
    canonicalize_silo_args(named);
    const auto default_folder = [](const nlohmann::json& s) {
        return fs::path("campaigns") / ("cutoff-" + orchestrator::sha256_hex(s.dump()).substr(0, 12));
    };
    // a search begun before that was named by its options as typed: continued there (review of stop 61)
    std::error_code ec;
    const fs::path typed_folder = default_folder(settings);
    const fs::path dir = !o.campaign.empty()                      ? fs::path(o.campaign)
                         : fs::is_directory(typed_folder, ec)     ? typed_folder
                                                                  : default_folder(named);
    check_output_folder(dir.string(), "--campaign");
    check_paths_apart(silo_campaign_inputs(o.silo_args, dir), {{o.json, "--json"}});
    if (!base.materials.cohesive())
        std::printf("note: the material has no cohesion (surface_energy_J_m2 = 0): a cohesionless bed rarely arches\n");
    open_silo_campaign(dir, settings, "cutoff");
    const std::string amount = base.fill_mass > 0 ? ks::setting_text(base.fill_mass) + " kg of grain"
                                                   : std::to_string(base.particles) + " grains";
    std::printf("cut-off search in the silo: %s, %s, stiffness scale %g; %s; A = %g m along x; bracket "
                "[%g, %g] Hz to %g Hz, %zu seed(s); %s; %s; runs in %s\n",
                base.geometry.describe().c_str(), amount.c_str(), base.materials.stiffness_scale,
                ks::contact_law_name(base).c_str(), o.base.amplitude, search.lo, search.hi, search.tol,
                search.seeds.size(), kc::flow_criterion_text(search.criterion).c_str(),
                ladder_text(ladder).c_str(), dir.string().c_str());
    std::fflush(stdout);
    nlohmann::json runs = nlohmann::json::array();
    kc::CutoffResult res;
    try {
        res = kc::find_cutoff_batched(search, [&](double f, const std::vector<unsigned>& seeds) {
            // the seeds side by side in each window; those still discharging at its end again in the next
            const auto ends = kc::deciding_ends(search.criterion, ladder, seeds, [&](double window,
                                                                                   const std::vector<unsigned>& batch) {
                std::vector<SiloRunPlan> plans;
                for (unsigned seed : batch) plans.push_back(silo_run_plan(o, f, seed, window));
                const SiloCampaignOutcome outcome =
                    run_silo_campaign(dir, plans, o.jobs, "cutoff", {o.executor, o.partition});
                if (outcome.stopped) throw SearchStopped{};
                std::vector<ks::DischargeEnd> got;
                for (std::size_t k = 0; k < batch.size(); ++k)
                    got.push_back(read_search_run(dir, plans[k], f,
                                                  silo_run_settings(base, f, batch[k], o.base.amplitude, window),
                                                  search.criterion, runs));
                return got;
            });
            std::vector<bool> answers;
            for (ks::DischargeEnd end : ends) answers.push_back(kc::flows(search.criterion, end));
            return answers;
        });
    } catch (const SearchStopped&) {
        std::printf("stopped; the same command continues the search in %s (finished runs kept)\n",
                    dir.string().c_str());
        return kExitResumeLater;
    }
    nlohmann::json out = {{"case", "silo"},
                          {"geometry", base.geometry.describe()},
                          {"silo_options", o.silo_args},
                          {"contact_law", ks::contact_law_name(base)},
                          {"amplitude_m", o.base.amplitude},
                          {"direction", "x"},
                          {"window_s", o.base.window},
                          {"max_window_s", ladder.back()},
                          {"campaign", dir.string()},
                          {"criterion", kc::flow_criterion_name(search.criterion)},
                          {"criterion_text", kc::flow_criterion_text(search.criterion) +
                                                 "; a frequency flows when at least half of the seeds flow"},
                          {"runs", runs}};
    report_window_end_runs(search.criterion, ladder.back(), out);
    return conclude(res, std::move(out), o.json);
}

int run(const CutoffCli& o, CLI::App& sub) {
    if (!o.silo_args.empty()) return run_silo_search(o, sub);
    for (const char* option : kSiloSearchOptions)
        if (sub.count(option))
            throw UserError(std::string(option) + " applies to the silo search (silo options after --); the small "
                            "hopper runs in this process");
    if (!o.json.empty()) check_output_file(o.json, "--json");
    const kc::CutoffSearch search = search_from(o);
    nlohmann::json runs = nlohmann::json::array();
    auto report = [&](const kc::CohesiveHopperCase& c, const kc::CohesiveHopperOutcome& r) {
        const bool flows = r.flows(search.criterion);
        const std::string_view end = kernel::silo::discharge_end_name(r.end);
        const bool decided = kc::decided(search.criterion, r.end);
        std::printf("  f = %6.1f Hz (%6.2f g), seed %u: %5.1f %% out in %.2f s, %s -> %s  [%.1f s]\n", c.frequency,
                    r.peak_acceleration_g, c.seed, 100 * r.discharged_fraction, r.discharge_s,
                    std::string(end).c_str(), answer_word(search.criterion, r.end), r.wall_s);
        std::fflush(stdout);
        runs.push_back({{"frequency_hz", c.frequency}, {"seed", c.seed}, {"peak_acceleration_g", r.peak_acceleration_g},
                        {"discharged_fraction", r.discharged_fraction}, {"discharge_time_s", r.discharge_s},
                        {"window_s", c.window}, {"end", end}, {"flows", flows}, {"decided", decided},
                        {"wall_s", r.wall_s}});
    };
    // SIGINT, SIGTERM, SIGHUP: the run under way ends, then the search stops (exit 75), where the signal killed it
    // (exit 143, no word, nothing kept). The small hopper keeps no checkpoint: the same command starts over.
    const orchestrator::InterruptGuard interrupts;
    const auto report_then_stop_if_asked = [&](const kc::CohesiveHopperCase& c, const kc::CohesiveHopperOutcome& r) {
        report(c, r);
        if (orchestrator::interrupted())
            throw orchestrator::CampaignSuspended(
                "interrupted after " + std::to_string(runs.size()) + " run" + (runs.size() == 1 ? "" : "s") +
                " of the small hopper's search (printed above); it keeps no checkpoint: run the same command again "
                "to search afresh");
    };
    kc::CutoffResult res;
    try {
        kc::validate(o.base, search);  // before the first run
        std::printf("cut-off search: Bo = %g, theta = %g deg, A = %g m, bracket [%g, %g] Hz to %g Hz, %zu seed(s); "
                    "%s; %s\n",
                    o.base.bond_number, o.base.theta_deg, o.base.amplitude, search.lo, search.hi, search.tol,
                    search.seeds.size(), kc::flow_criterion_text(search.criterion).c_str(),
                    ladder_text(kc::window_ladder(o.base.window, search.longest_window)).c_str());
        std::fflush(stdout);  // before minutes of runs: a search stopped by a signal keeps what it printed
        res = kc::find_cutoff(o.base, search, report_then_stop_if_asked);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    nlohmann::json out = {{"case", "small hopper"}, {"bond_number", o.base.bond_number}, {"theta_deg", o.base.theta_deg},
                          {"amplitude_m", o.base.amplitude}, {"grains", o.base.grains}, {"window_s", o.base.window},
                          {"max_window_s", kc::window_ladder(o.base.window, search.longest_window).back()},
                          {"criterion", kc::flow_criterion_name(search.criterion)},
                          {"criterion_text", kc::flow_criterion_text(search.criterion) +
                                                 "; a frequency flows when at least half of the seeds flow"},
                          {"runs", runs}};
    report_window_end_runs(search.criterion, kc::window_ladder(o.base.window, search.longest_window).back(), out);
    return conclude(res, std::move(out), o.json);
}

}  // namespace

void add_cutoff_command(CLI::App& app) {
    auto o = std::make_shared<CutoffCli>();
    CLI::App* sub = app.add_subcommand(
        "cutoff", "lowest vibration frequency at which a cohesive (JKR) bed arched over the outlet flows: a small hopper of "
                  "spheres, or the silo case with the silo options after --");
    sub->add_option("--bond-number", o->base.bond_number, "cohesion as F_pulloff / (m g) of two equal grains")
        ->check(number_in(0, 1e4))
        ->capture_default_str();
    sub->add_option("--theta", o->base.theta_deg, "hopper half angle from the vertical [deg]")
        ->check(number_in(5, 80))
        ->capture_default_str();
    sub->add_option("--amplitude", o->base.amplitude, "vibration amplitude [m] (horizontal, the whole bin)")
        ->check(number_in(0, 0.01))
        ->capture_default_str();
    sub->add_option("--bracket", o->bracket, "LO,HI [Hz]: arched at LO, flowing at HI")->capture_default_str();
    sub->add_option("--tol", o->tol, "width of the final bracket [Hz]")->check(positive_number())->capture_default_str();
    sub->add_option("--seeds", o->seeds, "seeds of the bed (repeats at each frequency)")
        ->delimiter(',')
        ->check(integer_in(0, 4294967295LL));
    sub->add_option("--grains", o->base.grains, "number of grains")->check(integer_in(10, 20000))->capture_default_str();
    sub->add_option("--window", o->base.window,
                    "longest time a run lasts after the opening [s] (it ends once half the mass is out or its flow "
                    "stops); at least " +
                        kernel::silo::setting_text(kc::shortest_window(kc::FlowCriterion::flow_stops)) +
                        " s with --criterion flow-stops")
        ->check(number_in(kc::kWindowMin, kc::kWindowMax))
        ->capture_default_str();
    sub->add_option("--max-window", o->max_window,
                    "longest window [s]: a run still discharging at its window's end (not decided by flow-stops) runs "
                    "again from the start in twice the window, up to this one (default " +
                        kernel::silo::setting_text(kDefaultWindowFactor) + " x --window, at most " +
                        kernel::silo::setting_text(kc::kWindowMax) + " s; equal to --window: no run again)")
        ->check(number_in(kc::kWindowMin, kc::kWindowMax));
    std::vector<std::string> criteria;
    for (const auto& named : kc::kFlowCriterionNames) criteria.emplace_back(named.second);
    sub->add_option("--criterion", o->criterion,
                    "what flows means: flow-stops (arched: the flow stopped, no grain out for " +
                        kernel::silo::setting_text(kernel::silo::kFlowStallTime) +
                        " s, before half the mass was out) or half-within-window (half the mass out within --window; "
                        "the criterion before 2026-12-06, which depends on the window)")
        ->check(CLI::IsMember(criteria))
        ->capture_default_str();
    sub->add_option("--json", o->json, "write the search and its runs to this JSON file");
    sub->add_option("--max-runs", o->max_runs, "most runs the search may make (a guard against typos)")
        ->check(integer_in(1, 1000000000))
        ->capture_default_str();
    sub->add_option("--campaign", o->campaign,
                    "silo search: the folder of its runs (default campaigns/cutoff-<hash of the silo options, "
                    "amplitude and window>); the same command continues a stopped search, and searches of the same "
                    "settings (another bracket, tolerance or seeds) reuse each other's runs");
    sub->add_option("--jobs,-j", o->jobs, "silo search: runs at once (the seeds of a frequency side by side)")
        ->check(integer_in(1, 256))
        ->capture_default_str();
    sub->add_option("--executor", o->executor, "silo search: local (processes of this machine) or slurm (job arrays)")
        ->check(CLI::IsMember({"local", "slurm"}))
        ->capture_default_str();
    sub->add_option("--partition", o->partition, "silo search: SLURM partition (--executor slurm)");
    sub->add_option("silo_args", o->silo_args,
                    "after --: search in the silo case instead, with these demcal silo options (a cohesive --material, "
                    "--theta, --geometry, --particles, --stiffness-scale, ...)");
    sub->footer("Silo (the measured search of examples/cohesive_arch/README.md): demcal cutoff --amplitude 1.1e-4 "
                "--bracket 0,400 --tol 25 --seeds 1,2,3 --jobs 2 -- --material examples/materials/silo_meal_g04.json "
                "--theta 30 --particles 2000 --stiffness-scale 0.01 --fill-time 0.5");
    sub->callback([o, sub] {
        const int status = run(*o, *sub);
        if (status != 0) throw CLI::RuntimeError(status);
    });
}

}  // namespace demcal
