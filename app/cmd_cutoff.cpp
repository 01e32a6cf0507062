// demcal cutoff: the lowest vibration frequency at which a cohesive bed arched over a hopper's outlet flows
// (kernel/cases/cohesive_hopper.hpp; measured cases in examples/cohesive_arch/README.md).
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "kernel/cases/cohesive_hopper.hpp"
#include "analytics/number_text.hpp"
#include "orchestrator/run_identity.hpp"  // write_text_file_atomically
#include "orchestrator/shear_campaign.hpp"  // check_run_count

#include <nlohmann/json.hpp>

#include <cmath>
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

struct CutoffCli {
    kc::CohesiveHopperCase base;
    std::string bracket = "0,400";
    double tol = 25;
    std::vector<long long> seeds{1};
    std::string json;
    long max_runs = 10000;
};

std::pair<double, double> parse_bracket(const std::string& text) {
    const auto comma = text.find(',');
    const std::string shown = "--bracket = '" + analytics::shortened_text(text, 40) + "'";
    if (comma == std::string::npos) throw UserError(shown + ": give LO,HI in Hz, e.g. 0,400");
    double ends[2];
    const std::string parts[2] = {text.substr(0, comma), text.substr(comma + 1)};
    for (int i = 0; i < 2; ++i) {  // the number rule of every option (a subnormal or NaN end was searched)
        const auto n = analytics::read_typed_number(parts[i]);
        if (!n.is_number) throw UserError(shown + ": give LO,HI in Hz, e.g. 0,400");
        if (n.defect) throw UserError(shown + ": '" + analytics::shortened_text(parts[i], 40) + "' " + *n.defect);
        ends[i] = n.value;
    }
    return {ends[0], ends[1]};
}

// Bisections that halve HI - LO down to the tolerance: below 2^-30 of the bracket the frequencies no longer differ
// in any digit a run could resolve, and near 2^-52 the midpoint equals an end and the search never ends.
constexpr int kMaxBisections = 30;

// The runs the search may make (both ends, then every bisection, each with every seed), refused above --max-runs
// before the first run; a tolerance finer than the bisection bound is refused by name.
void check_search_size(const kc::CutoffSearch& s, long max_runs) {
    const double width = s.hi - s.lo;
    if (!(width > 0) || !(s.tol > 0) || s.tol >= width) return;  // kc::validate names these
    if (s.tol < std::ldexp(width, -kMaxBisections))
        throw UserError("--tol = " + analytics::number_text(s.tol) + " Hz: finer than 2^-" +
                        std::to_string(kMaxBisections) + " of the bracket (" + analytics::number_text(width) +
                        " Hz), more bisections than frequencies a run can tell apart");
    const int bisections = static_cast<int>(std::ceil(std::log2(width / s.tol)));
    orchestrator::check_run_count(static_cast<double>(2 + bisections) * s.seeds.size(), max_runs,
                                  "cutoff: (2 ends + " + std::to_string(bisections) + " bisections) x " +
                                      std::to_string(s.seeds.size()) + " seeds");
}

int run(const CutoffCli& o) {
    if (!o.json.empty()) check_output_file(o.json, "--json");
    kc::CutoffSearch search;
    std::tie(search.lo, search.hi) = parse_bracket(o.bracket);
    search.tol = o.tol;
    search.seeds.assign(o.seeds.begin(), o.seeds.end());
    try {
        check_search_size(search, o.max_runs);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    nlohmann::json runs = nlohmann::json::array();
    auto report = [&](const kc::CohesiveHopperCase& c, const kc::CohesiveHopperOutcome& r) {
        std::printf("  f = %6.1f Hz (%6.2f g), seed %u: %5.1f %% out in %.2f s -> %s  [%.1f s]\n", c.frequency,
                    r.peak_acceleration_g, c.seed, 100 * r.discharged_fraction, c.window,
                    r.flows() ? "flows" : "arched", r.wall_s);
        std::fflush(stdout);
        runs.push_back({{"frequency_hz", c.frequency}, {"seed", c.seed}, {"peak_acceleration_g", r.peak_acceleration_g},
                        {"discharged_fraction", r.discharged_fraction}, {"flows", r.flows()}, {"wall_s", r.wall_s}});
    };
    kc::CutoffResult res;
    try {
        kc::validate(o.base, search);  // before the first run
        std::printf("cut-off search: Bo = %g, theta = %g deg, A = %g m, bracket [%g, %g] Hz to %g Hz, %zu seed(s); "
                    "flows = half the mass out within %g s of the opening\n",
                    o.base.bond_number, o.base.theta_deg, o.base.amplitude, search.lo, search.hi, search.tol,
                    search.seeds.size(), o.base.window);
        res = kc::find_cutoff(o.base, search, report);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    nlohmann::json out = {{"bond_number", o.base.bond_number}, {"theta_deg", o.base.theta_deg},
                          {"amplitude_m", o.base.amplitude}, {"grains", o.base.grains}, {"window_s", o.base.window},
                          {"criterion", "flows: at least half of the mass out within window_s of the opening, "
                                        "in at least half of the seeds"},
                          {"runs", runs}};
    if (res.found) {
        out["cutoff_hz"] = {res.lo, res.hi};
        std::printf("cut-off frequency in [%g, %g] Hz\n", res.lo, res.hi);
    } else {
        out["cutoff_hz"] = nullptr;
        out["reason"] = res.reason;
        std::printf("no cut-off found: %s\n", res.reason);
    }
    if (!o.json.empty()) orchestrator::write_text_file_atomically(o.json, out.dump(1) + "\n");
    return res.found ? 0 : 1;
}

}  // namespace

void add_cutoff_command(CLI::App& app) {
    auto o = std::make_shared<CutoffCli>();
    CLI::App* sub = app.add_subcommand(
        "cutoff", "lowest vibration frequency at which a cohesive (JKR) bed arched over a small hopper's outlet flows");
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
    sub->add_option("--window", o->base.window, "time after the opening for half the mass to leave [s]")
        ->check(number_in(0.05, 10))
        ->capture_default_str();
    sub->add_option("--json", o->json, "write the search and its runs to this JSON file");
    sub->add_option("--max-runs", o->max_runs, "most runs the search may make (a guard against typos)")
        ->check(integer_in(1, 1000000000))
        ->capture_default_str();
    sub->callback([o] {
        const int status = run(*o);
        if (status != 0) throw CLI::RuntimeError(status);
    });
}

}  // namespace demcal
