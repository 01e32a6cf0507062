// demcal sensitivity / calibrate / enlarge: the failure-line sensitivity study (seed Table 3.1), the calibration loop
// and the particle-enlargement laws (seed eqs. 3.1-3.2). Every simulation is a stored, cached, resumable campaign run.
#include "analytics/number_text.hpp"
#include "analytics/scaling_law.hpp"
#include "analytics/user_input.hpp"
#include "app/campaign_cli.hpp"
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/execution_options.hpp"
#include "app/gnuplot.hpp"
#include "app/result_files.hpp"
#include "app/scaling_plots.hpp"
#include "calibration/calibration_loop.hpp"
#include "calibration/campaign_evaluator.hpp"
#include "calibration/sensitivity_study.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_params.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

namespace demcal {

namespace fs = std::filesystem;
using namespace calibration;
using orchestrator::check_run_count;

namespace {

// A study read with --sensitivity must be of the --start material: its responses hold around its base, so any field
// it did not vary (box, density, radius, a parameter left out) must equal the start's. Throws UserError naming it.
void check_study_matches_start(const SensitivityStudy& study, const nlohmann::json& start, const std::string& file,
                               std::vector<std::string>& warnings) {
    nlohmann::json base = study.base_material, here = start;
    for (const auto& p : study.parameters) {
        // a studied parameter may start elsewhere in its studied range (the search moves it there anyway), not
        // outside it, where the study measured nothing (held-back suite: friction 0.3 against a study of 0.5)
        if (here.contains(p.name) && here[p.name].is_number()) {
            const double v = here[p.name].get<double>();
            if (v < p.low() || v > p.high())
                throw UserError("--sensitivity = '" + analytics::shortened_text(file, 200) + "': the start material's " +
                                p.name + " = " + analytics::number_text(v) + " lies outside the range the study " +
                                "varied (" + analytics::number_text(p.low()) + " to " + analytics::number_text(p.high()) +
                                " around " + analytics::number_text(p.base_value) + "): run the study around this " +
                                "start, or start inside that range");
            if (v != p.base_value)
                warnings.push_back("--start's " + p.name + " = " + analytics::number_text(v) + " is not the study's " +
                                   "base (" + analytics::number_text(p.base_value) + "): its responses, measured " +
                                   "around the base, steer the search from there");
        }
        base.erase(p.name);
        here.erase(p.name);
    }
    for (const char* k : {"name", "description"}) {
        base.erase(k);
        here.erase(k);
    }
    for (const auto& [key, value] : here.items())
        if (!base.contains(key) || base[key] != value)
            throw UserError("--sensitivity = '" + analytics::shortened_text(file, 200) + "': its base material has " +
                            key + " = " + (base.contains(key) ? analytics::json_value_text(base[key]) : "(absent)") +
                            ", the start material " + analytics::json_value_text(value) +
                            ": a study holds for the material it varied (run it for this start, or start from its "
                            "base)");
    for (const auto& [key, value] : base.items())
        if (!here.contains(key))
            throw UserError("--sensitivity = '" + analytics::shortened_text(file, 200) + "': its base material has " +
                            key + ", the start material has not");
}

// ---- sensitivity ----

struct SensitivityCli {
    std::string base_file;
    std::vector<std::string> params;
    int levels = 5;
    double span = 0.5;
    std::vector<std::string> ranges;
    std::string criterion = "f-test";
    double alpha = 0.05;
    bool span_given = false;  // --span typed (it is void when every studied parameter has its --range)
    CampaignCli campaign;
};

// The fewest levels AICc can rank the response shapes with (n > k + 1 for the parabola's k = 4).
constexpr int kMinLevelsForAicc = 6;

SensitivityOptions sensitivity_options(const SensitivityCli& o) {
    SensitivityOptions s;
    s.params = o.params;
    s.levels = o.levels;
    s.relative_span = o.span;
    s.ranges = parse_ranges(o.ranges, "--range");
    for (std::size_t i = 0; i < o.params.size(); ++i)  // one parameter twice is one factor counted twice
        if (std::find(o.params.begin(), o.params.begin() + i, o.params[i]) != o.params.begin() + i)
            throw UserError("--params: " + o.params[i] + " is given twice");
    // a range for a parameter the study does not vary was silently ignored
    if (!o.params.empty())
        for (const auto& [name, range] : s.ranges)
            if (std::find(o.params.begin(), o.params.end(), name) == o.params.end())
                throw UserError("--range " + name + "=...: " + name + " is not among --params; add it there or drop "
                                "the range");
    if (o.span_given) {
        const auto studied = o.params.empty() ? orchestrator::micromechanical_param_names() : o.params;
        if (std::all_of(studied.begin(), studied.end(), [&](const std::string& n) { return s.ranges.count(n) > 0; }))
            throw UserError("--span = " + analytics::number_text(o.span) + " sets the range of a studied parameter "
                            "without --range, and every one here has its --range; leave --span out");
    }
    s.shape.criterion = analytics::shape_criterion_from_string(o.criterion);
    // AICc needs more points than a model's parameters + 2 (the parabola: 3 coefficients and the scale): with fewer
    // the line's and the parabola's AICc are undefined and every response came out "constant"
    if (s.shape.criterion == analytics::ShapeCriterion::aicc && o.levels < kMinLevelsForAicc)
        throw UserError("--criterion aicc with --levels " + std::to_string(o.levels) + ": AICc tells the parabola from " +
                        std::to_string(kMinLevelsForAicc) + " levels on (with fewer every response is called "
                        "constant); give --levels " + std::to_string(kMinLevelsForAicc) + " or more, or --criterion "
                        "f-test");
    s.shape.alpha = o.alpha;
    s.line = line_kind_from_string(o.campaign.line);
    return s;
}

void print_level(const std::string& param, const SensitivityLevel& l) {
    // a stream of its own: std::cout's precision is not left at 1 for the next level's value (it printed 0.75 as 0.8)
    std::ostringstream line;
    line << "  " << std::left << std::setw(22) << param << std::right << " = " << std::setw(10) << l.value
         << "  mu_b " << std::fixed << std::setprecision(4) << l.mu_b << " +/- " << l.se_mu_b << "  tau_c "
         << std::setprecision(1) << l.tau_c << " +/- " << l.se_tau_c << " Pa (+/- 1 SE)  (" << l.simulations_run << " run, "
         << l.simulations_reused << " reused)";
    std::cout << line.str() << std::endl;
}

// One PNG per parameter: mu_b and tau_c against the parameter, with error bars and the selected fit.
void plot_parameter(const fs::path& dir, const ParameterSensitivity& p, const std::string& format) {
    const fs::path data = dir / ("sensitivity_" + p.name + ".dat"), fit = dir / ("sensitivity_" + p.name + "_fit.dat");
    {
        std::ostringstream d, f;
        d << "# value mu_b se_mu_b tau_c se_tau_c\n";
        for (const auto& l : p.levels) d << l.value << " " << l.mu_b << " " << l.se_mu_b << " " << l.tau_c << " " << l.se_tau_c << "\n";
        f << "# value mu_b_fit tau_c_fit\n";
        for (int i = 0; i <= 60; ++i) {
            const double x = p.low() + (p.high() - p.low()) * i / 60;
            f << x << " " << p.mu_b.value(x) << " " << p.tau_c.value(x) << "\n";
        }
        write_result_file(data, d.str());
        write_result_file(fit, f.str());
    }
    // 5 % of the range on each side, so that the end levels' error bars do not sit on the frame
    const double pad = 0.05 * (p.high() - p.low());
    std::ostringstream g;
    g << "set multiplot layout 1,2 title 'Sensitivity to " << p.name << " (error bars: 1 standard error)' noenhanced\n"
      << "set grid\nset xlabel " << gnuplot_text(p.name) << " noenhanced\nset key bottom right\n"
      << "set xrange [" << p.low() - pad << ":" << p.high() + pad << "]\n"
      << "set ylabel 'mu_b [-]'\nset title 'internal friction: " << analytics::to_string(p.mu_b.shape) << "'\n"
      << "plot " << gnuplot_quote(data) << " using 1:2:3 with yerrorbars pt 7 lc rgb '#08519c' title 'simulated', "
      << gnuplot_quote(fit) << " using 1:2 with lines lw 2 lc rgb '#08519c' title 'fit'\n"
      << "set ylabel 'tau_c [Pa]'\nset title 'cohesion: " << analytics::to_string(p.tau_c.shape) << "'\n"
      << "plot " << gnuplot_quote(data) << " using 1:4:5 with yerrorbars pt 7 lc rgb '#a50f15' title 'simulated', "
      << gnuplot_quote(fit) << " using 1:3 with lines lw 2 lc rgb '#a50f15' title 'fit'\n"
      << "unset multiplot\n";
    render_gnuplot(dir / ("sensitivity_" + p.name + "." + format), g.str(), 1200, 500);
}

void write_study(const fs::path& dir, const SensitivityStudy& study, const std::string& format) {
    write_result_file(dir / "sensitivity.json", study.to_json().dump(2) + "\n");
    write_result_file(dir / "sensitivity_table.txt", study.table());
    for (const auto& p : study.parameters) {
        try {
            plot_parameter(dir, p, format);
        } catch (const std::exception& e) {
            std::cerr << "demcal: warning: plot for " << p.name << " not written: " << e.what() << "\n";
        }
    }
    keep_results();  // the study is whole: calibrate's loop, hours later, does not take it with a failure of its own
}

// Checks every level's material before anything is written or run: a bad range must not cost simulations.
void check_study(const nlohmann::json& base, const SensitivityCli& o) {
    // the count first: planning a billion levels would itself take the memory
    const std::size_t params = o.params.empty() ? orchestrator::micromechanical_param_names().size() : o.params.size();
    const auto& c = o.campaign;
    check_run_count(static_cast<double>(params) * o.levels * c.normal_stresses.size() * c.replicates, c.exec.max_runs,
                    "sensitivity study: " + std::to_string(params) + " parameters x " + std::to_string(o.levels) +
                        " levels x " + std::to_string(c.normal_stresses.size()) + " normal stresses x " +
                        std::to_string(c.replicates) + " replicates");
    for (const auto& name : o.params) orchestrator::require_micromechanical_param(name, "--params");
    sensitivity_plan(base, sensitivity_options(o));
    check_campaign(o.campaign, base);
}

SensitivityStudy run_study(const nlohmann::json& base, const SensitivityCli& o, const FailureLineEvaluator& evaluate) {
    const auto options = sensitivity_options(o);
    std::cout << "sensitivity study: " << (options.params.empty() ? orchestrator::micromechanical_param_names().size()
                                                                  : options.params.size())
              << " parameters x " << options.levels << " levels, failure lines at " << o.campaign.normal_stresses.size()
              << " normal stresses x " << o.campaign.replicates << " packings" << std::endl;
    SensitivityStudy study = run_sensitivity_study(base, evaluate, options, print_level);
    study.campaign = StudyCampaign::of(settings_of(o.campaign, "sensitivity"));
    return study;
}

void add_sensitivity(CLI::App& app) {
    auto o = std::make_shared<SensitivityCli>();
    auto* cmd = app.add_subcommand("sensitivity", "vary each micro parameter around a base material; classify the "
                                                  "responses of mu_b and tau_c (seed Table 3.1)");
    cmd->add_option("base", o->base_file, "base material JSON")->required();
    cmd->add_option("--params", o->params, "parameters to vary (default: all micromechanical)")->delimiter(',');
    cmd->add_option("--levels", o->levels, "values per parameter (>= 3; 5 lets a curvature be tested)")
        ->check(integer_in(3, calibration::kMaxLevels))
        ->capture_default_str();
    cmd->add_option("--span", o->span, "default range: base * (1 -+ span)")->capture_default_str();
    cmd->add_option("--range", o->ranges, "explicit range NAME=LOW:HIGH (repeatable)");
    cmd->add_option("--criterion", o->criterion, "shape selection: f-test or aicc")->capture_default_str();
    cmd->add_option("--alpha", o->alpha, "significance level of the F tests")->capture_default_str();
    add_campaign_options(cmd, o->campaign);
    cmd->callback([o, cmd] {
        o->span_given = cmd->count("--span") > 0;
        const auto base = orchestrator::validate_material(read_json_file(o->base_file, "base"), o->base_file);
        check_study(base, *o);  // option errors before any campaign
        CampaignSession session(o->campaign, "sensitivity");
        const auto study = run_study(base, *o, session.evaluate);
        write_study(o->campaign.campaign_dir, study, o->campaign.plot_format);
        std::cout << "\n" << study.table() << "\n" << study.evaluations << " failure lines, " << study.simulations_run
                  << " simulations run now, " << study.simulations_reused << " reused; " << runs_cpu_text(study.cpu_s, study.simulations_reused)
                  << "\nresults: " << (fs::path(o->campaign.campaign_dir) / "sensitivity.json").string()
                  << ", sensitivity_table.txt, sensitivity_<param>." << o->campaign.plot_format << std::endl;
    });
}

// ---- calibrate ----

struct CalibrateCli {
    std::string target;
    std::string measured;
    std::string start_file;
    double tol = 0.02;
    std::string sensitivity_file;
    std::vector<std::string> controls;
    std::vector<std::string> bounds;
    std::string method = "surrogate";
    bool sequential = false;
    bool strict = false;
    int max_evaluations = 12;
    int grid_points = 9;
    std::string output;
    SensitivityCli study;  // used when no --sensitivity file is given
};

std::vector<MacroTarget> targets_of(const CalibrateCli& o) {
    if (o.target.empty() == o.measured.empty()) throw UserError("give exactly one of --target and --measured");
    if (!o.target.empty()) {
        try {
            return parse_targets(o.target);
        } catch (const std::invalid_argument& e) {
            throw UserError(std::string("--target: ") + e.what());
        }
    }
    refuse_empty_list_items(o.measured, "--measured");
    std::vector<double> sigma, tau;
    std::stringstream items(o.measured);
    std::string item;
    while (std::getline(items, item, ',')) {
        item = analytics::trimmed(item);  // "4e3:6500, 6e3:7200", a pasted line end
        const auto colon = item.find(':');
        try {
            if (colon == std::string::npos) throw std::invalid_argument(item);
            const auto whole_number = [&item](const std::string& text) {  // "5e3x" is not 5e3
                const auto n = analytics::read_typed_number(text);
                if (!n.is_number) throw std::invalid_argument(text);
                if (n.defect)
                    throw UserError("--measured: point '" + analytics::shortened_text(item) + "': " +
                                    analytics::shortened_text(text) + " " + *n.defect);
                return n.value;
            };
            sigma.push_back(whole_number(analytics::trimmed(item.substr(0, colon))));
            tau.push_back(whole_number(analytics::trimmed(item.substr(colon + 1))));
        } catch (const std::invalid_argument&) {
            throw UserError("--measured: point '" + analytics::shortened_text(item) +
                            "' is not of the form SIGMA:TAU (Pa)");
        }
    }
    std::vector<MacroTarget> targets;
    try {
        targets = targets_from_measured_line(sigma, tau);  // (its own checks first: the points' values and spread)
    } catch (const std::invalid_argument& e) {
        throw UserError(std::string("--measured: ") + e.what());
    }
    // the simulated lines are compared with the measured one over the stresses they share: a line measured at
    // 100-300 kPa was "reproduced" by boxes at 4-8 kPa, an extrapolation of both
    const auto& stresses = o.study.campaign.normal_stresses;
    const auto [m_lo, m_hi] = std::minmax_element(sigma.begin(), sigma.end());
    const auto [c_lo, c_hi] = std::minmax_element(stresses.begin(), stresses.end());
    if (!stresses.empty() && (*c_hi < *m_lo || *c_lo > *m_hi))
        throw UserError("--normal-stress " + analytics::number_text(*c_lo) + " to " + analytics::number_text(*c_hi) +
                        " Pa lies outside the --measured line's stresses (" + analytics::number_text(*m_lo) + " to " +
                        analytics::number_text(*m_hi) + " Pa): simulate the failure lines over the measured "
                        "stresses");
    return targets;
}

using RangeMap = std::map<std::string, std::pair<double, double>>;  // NAME -> [low, high], from NAME=LOW:HIGH

CalibrationOptions calibration_options(const CalibrateCli& o) {
    CalibrationOptions options;
    options.tolerance = o.tol;
    options.method = search_method_from_string(o.method);
    options.sequential = o.sequential;
    options.accept_simulated_interval = !o.strict;
    options.max_evaluations = o.max_evaluations;
    options.grid_points = o.grid_points;
    options.line = line_kind_from_string(o.study.campaign.line);
    return options;
}

std::string surrogate_control_outside_study(const std::string& name) {
    return "--controls: '" + name + "' is not a parameter of the sensitivity study, and the surrogate search (the "
           "default --method) models each control from the study's responses; add it to the study's --params, or "
           "search it with --method coordinate (with --bounds)";
}

// Every option checked before the study or the campaign runs, and before the log is rewritten. Fills the study's
// parameters with the controls when neither they nor a stored study are given.
void check_calibrate_options(CalibrateCli& o, const nlohmann::json& start, const std::vector<MacroTarget>& targets,
                             const RangeMap& bounds, const CalibrationOptions& options) {
    const auto& camp = o.study.campaign;
    check_calibration_options(options);
    if (o.sequential && targets.size() < 2)
        throw UserError("--sequential orders two targets (slope first, then cohesion); the calibration has one (" +
                        targets.front().quantity + ")");
    if (!o.controls.empty() && o.controls.size() != targets.size())
        throw UserError("--controls: " + std::to_string(o.controls.size()) + " given for " +
                        std::to_string(targets.size()) + " targets");
    for (const auto& [name, range] : bounds) {
        // a bound acts on a searched parameter only: one on another parameter was ignored
        // (a stored study's parameters are checked when it is read: pick_controls)
        const auto searchable = !o.controls.empty()         ? o.controls
                                : !o.study.params.empty()   ? o.study.params
                                : o.sensitivity_file.empty() ? orchestrator::micromechanical_param_names()
                                                             : std::vector<std::string>{};
        if (!searchable.empty() && std::find(searchable.begin(), searchable.end(), name) == searchable.end())
            throw UserError("--bounds " + name + "=...: " + name + " is not among " +
                            (!o.controls.empty()         ? "--controls"
                             : !o.study.params.empty()   ? "the studied --params"
                                                         : "the micromechanical parameters the study varies") +
                            ", and a bound acts on a searched parameter only; add it there or drop the bound");
        check_control(start, {name, range.first, range.second});
    }
    if (o.sensitivity_file.empty()) {
        if (o.study.params.empty() && !o.controls.empty()) {
            // the controls become the study's parameters: named as the option that gave them (a control given
            // --bounds with a stored study or other --params may be any material field check_control takes)
            for (const auto& name : o.controls) orchestrator::require_micromechanical_param(name, "--controls");
            o.study.params = o.controls;
        }
        // the surrogate models each control from the study's responses: one the study does not vary was found
        // only after the study and a first evaluation had run (probe 62)
        if (options.method == SearchMethod::surrogate)
            for (const auto& name : o.controls)
                if (std::find(o.study.params.begin(), o.study.params.end(), name) == o.study.params.end())
                    throw UserError(surrogate_control_outside_study(name));
        check_study(start, o.study);
    }
    // a grid evaluates all of itself: grid-points ^ controls, whatever --max-evaluations says
    const double control_count = static_cast<double>(o.controls.empty() ? targets.size() : o.controls.size());
    const double evaluations = options.method == SearchMethod::grid ? std::pow(double(o.grid_points), control_count)
                                                                    : double(o.max_evaluations);
    check_run_count(evaluations * camp.normal_stresses.size() * camp.replicates, camp.exec.max_runs,
                    "calibration: " + analytics::number_text(evaluations, 10) + " evaluations x " +
                        std::to_string(camp.normal_stresses.size()) + " normal stresses x " +
                        std::to_string(camp.replicates) + " replicates");
    check_campaign(camp, start);
}

// The controls given (their bounds from --bounds or the study's range), or those the study chooses.
std::vector<ControlParameter> pick_controls(const CalibrateCli& o, const SensitivityStudy& study,
                                            const std::vector<MacroTarget>& targets, const RangeMap& bounds) {
    if (o.controls.empty()) {
        for (const auto& [name, range] : bounds)  // (with --params the names were checked before the study ran)
            if (!study.find(name))
                throw UserError("--bounds " + name + "=...: " + name + " is not a parameter of the sensitivity study, "
                                "which chooses the controls among its own; drop the bound, or name --controls");
        auto chosen = choose_controls(study, targets, o.tol, {}, bounds);
        for (const auto& [name, range] : bounds)
            if (std::none_of(chosen.begin(), chosen.end(), [&](const ControlParameter& c) { return c.name == name; }))
                std::cerr << "demcal: warning: --bounds " << name << "=...: the study did not choose " << name
                          << " as a control, so its bound is not used" << std::endl;
        return chosen;
    }
    std::vector<ControlParameter> picked;
    for (const auto& name : o.controls) {
        const auto* p = study.find(name);
        auto b = bounds.find(name);
        if (!p && b == bounds.end())
            throw UserError("--controls: '" + name + "' is neither in the study nor given --bounds");
        if (!p && search_method_from_string(o.method) == SearchMethod::surrogate)
            throw UserError(surrogate_control_outside_study(name));
        picked.push_back({name, b != bounds.end() ? b->second.first : p->low(),
                          b != bounds.end() ? b->second.second : p->high()});
    }
    return picked;
}

// Its warnings go to `warnings`, said by the caller once every check has passed: a refusal is one line.
SensitivityStudy read_stored_study(const std::string& file, const nlohmann::json& start, LineKind line,
                                   const CampaignCli& campaign, std::vector<std::string>& warnings) {
    SensitivityStudy study;
    try {
        study = SensitivityStudy::from_json(read_json_file(file, "sensitivity"));
    } catch (const std::invalid_argument& e) {  // a field missing, of the wrong type or out of range
        throw UserError("--sensitivity = '" + file + "': " + e.what());
    }
    check_study_matches_start(study, start, file, warnings);
    // its responses are of the line it studied: a study of the peak line steered a calibration of the residual one
    if (study.options.line != line)
        throw UserError("--sensitivity = '" + analytics::shortened_text(file, 200) + "': a study of the " +
                        to_string(study.options.line) + " failure line, and --line " + to_string(line) +
                        ": its responses are of the other line (run the study with --line " + to_string(line) +
                        ", or calibrate the " + to_string(study.options.line) + " line)");
    if (!study.campaign) {
        warnings.push_back("--sensitivity = '" + analytics::shortened_text(file, 200) +
                           "' does not record the engine, normal stresses and YADE script its lines ran on (written "
                           "before demcal recorded them): not checked against this calibration's");
        return study;
    }
    StudyCampaign here;
    try {
        here = StudyCampaign::of(settings_of(campaign, "calibrate"));
    } catch (const std::exception& e) {
        throw UserError("--template = '" + analytics::shortened_text(campaign.template_path, 200) + "': " + e.what());
    }
    if (const std::string why = study.campaign->difference_from(here); !why.empty())
        throw UserError("--sensitivity = '" + analytics::shortened_text(file, 200) + "': " + why +
                        ": its responses hold for the campaign it ran (calibrate with the same options, or run the "
                        "study for these)");
    if (const std::string why = study.campaign->packing_difference_from(here); !why.empty())
        warnings.push_back("--sensitivity = '" + analytics::shortened_text(file, 200) + "': " + why +
                           ": none of its lines is reused, and the search meets other packings' scatter");
    else if ((!study.campaign->replicates || !study.campaign->base_seed) && here.replicates && here.base_seed)
        warnings.push_back("--sensitivity = '" + analytics::shortened_text(file, 200) +
                           "' does not record the packings its lines sheared (written before demcal recorded them): if "
                           "they were not this calibration's (" + std::to_string(*here.replicates) +
                           " per stress from seed " + std::to_string(*here.base_seed) +
                           "), none of its lines is reused and the search meets other packings' scatter");
    return study;
}

// One evaluation's console line.
std::string iteration_line(const CalibrationIteration& it) {
    std::ostringstream line;  // own stream: cout's format stays as it was
    line << "  #" << std::setw(2) << it.evaluation << " " << std::left << std::setw(10) << it.phase << std::right;
    for (const auto& [name, v] : it.values) line << " " << name << "=" << v;
    line << std::fixed << std::setprecision(4) << "  mu_b " << it.mu_b << " +/- " << it.mu_b_half_width
         << std::setprecision(1) << "  tau_c " << it.tau_c << " +/- " << it.tau_c_half_width << " Pa (95 %)"
         << std::setprecision(2) << "  miss " << it.mismatch
         << (it.accepted ? "  ACCEPTED (" + it.accepted_by + ")" : "") << "  [" << it.simulations_run << " run, "
         << it.simulations_reused << " reused]";
    return line.str();
}

void print_calibration_plan(const CalibrateCli& o, const std::vector<MacroTarget>& targets,
                            const std::vector<ControlParameter>& controls) {
    std::cout << "calibrating";
    for (std::size_t i = 0; i < targets.size(); ++i)
        std::cout << (i ? ", " : " ") << targets[i].quantity << " = " << targets[i].value << " +/- "
                  << targets[i].acceptance(o.tol) << (targets[i].quantity == "tau_c" ? " Pa" : "") << " (acceptance band) with " << controls[i].name << " in [" << controls[i].low
                  << ", " << controls[i].high << "]";
    std::cout << " (" << o.method << (o.sequential ? ", slope first" : "") << ")" << std::endl;
}

// calibration_<method>.json and the calibrated material; returns the material's path.
fs::path write_calibration_results(const CalibrateCli& o, const fs::path& dir, const CalibrationResult& result,
                                   const SensitivityStudy& study) {
    auto summary = result.to_json();
    summary["sensitivity"] = {{"evaluations", study.evaluations},
                              {"simulations_run", study.simulations_run},
                              {"simulations_reused", study.simulations_reused},
                              {"cpu_s", study.cpu_s}};
    write_result_file(dir / ("calibration_" + o.method + ".json"), summary.dump(2) + "\n");
    // a baseline run over the same campaign must not overwrite the loop's material
    const std::string default_name =
        o.method == "surrogate" ? "calibrated_material.json" : "calibrated_material_" + o.method + ".json";
    const fs::path out = o.output.empty() ? dir / default_name : fs::path(o.output);
    nlohmann::json material = result.material;
    material["description"] = "calibrated by demcal calibrate (" + to_string(result.status) + "): " + result.message;
    write_result_file(out, material.dump(1) + "\n");
    return out;
}

void print_calibration_summary(const CalibrateCli& o, const CalibrationResult& result, const SensitivityStudy& study,
                               const fs::path& material) {
    const auto& best = result.iterations[result.best];
    std::cout << "\n" << to_string(result.status) << ": " << result.message << "\n"
              << "final: mu_b = " << best.mu_b << " +/- " << best.mu_b_half_width << ", tau_c = " << best.tau_c
              << " +/- " << best.tau_c_half_width << " Pa (95 % intervals)\n"
              << "calibration: " << result.evaluations << " failure lines, " << result.simulations_run
              << " simulations run, " << result.simulations_reused << " reused, "
              << runs_cpu_text(result.cpu_s, result.simulations_reused)
              << "; sensitivity study: " << study.evaluations << " failure lines, "
              << (o.sensitivity_file.empty() ? std::to_string(study.simulations_run) + " simulations run now"
                                             : "read from " + o.sensitivity_file + " (not run now)")
              << "\nmaterial: " << material.string() << "\n";
}

void run_calibrate(CalibrateCli& o) {
    const auto& camp = o.study.campaign;
    if (!o.output.empty()) {  // before hours of calibration, not after
        check_output_in_campaign_or_existing_folder(o.output, "--output", camp.campaign_dir);
        check_output_outside_run_folders(o.output, "--output");
    }
    // nor on one of the reports this calibration writes into its campaign folder (its history was replaced)
    const fs::path reports = camp.campaign_dir;
    std::vector<NamedPath> outputs{
        {o.output, "--output"},
        {(reports / ("calibration_" + o.method + ".json")).string(), "the calibration's report"},
        {(reports / ("calibration_log_" + o.method + ".jsonl")).string(), "the calibration's log"}};
    if (o.sensitivity_file.empty())  // the study is run, and written, here
        outputs.insert(outputs.end(), {{(reports / "sensitivity.json").string(), "the study's report"},
                                       {(reports / "sensitivity_table.txt").string(), "the study's table"}});
    check_paths_apart({{o.start_file, "--start"}, {o.sensitivity_file, "--sensitivity"}}, outputs);
    const auto start = orchestrator::validate_material(read_json_file(o.start_file, "start"), o.start_file);
    const auto targets = targets_of(o);
    const auto bounds = parse_ranges(o.bounds, "--bounds");
    const CalibrationOptions options = calibration_options(o);
    check_calibrate_options(o, start, targets, bounds, options);
    SensitivityStudy study;
    std::vector<ControlParameter> controls;
    std::vector<std::string> warnings;
    if (!o.sensitivity_file.empty()) {
        study = read_stored_study(o.sensitivity_file, start, line_kind_from_string(o.study.campaign.line),
                                  o.study.campaign, warnings);
        controls = pick_controls(o, study, targets, bounds);  // a study that cannot serve: refused before the campaign
    }
    CampaignSession session(camp, "calibrate");
    for (const auto& w : warnings) std::cerr << "demcal: warning: " << w << std::endl;
    const fs::path dir = camp.campaign_dir;
    if (o.sensitivity_file.empty()) {
        study = run_study(start, o.study, session.evaluate);
        write_study(dir, study, camp.plot_format);
        std::cout << "\n" << study.table() << std::endl;
        try {
            controls = pick_controls(o, study, targets, bounds);
        } catch (const std::invalid_argument& e) {  // the study's finding, after its runs: not bad input (exit 1)
            throw std::runtime_error(std::string(e.what()) + "; the study is kept: " +
                                     (dir / "sensitivity.json").string());
        }
    }
    print_calibration_plan(o, targets, controls);

    const fs::path log_path = dir / ("calibration_log_" + o.method + ".jsonl");
    // Rewritten by every invocation, like calibration_<method>.json: a resumed calibration replays its finished
    // evaluations from the store, so the log still holds all of them once, in order (appending repeated them).
    // Opened at the first evaluation: a calibration refused before it leaves the previous log as it was.
    std::ofstream log;
    const auto result = calibrate(start, targets, controls, &study, session.evaluate, options,
                                  [&](const CalibrationIteration& it) {
                                      std::cout << iteration_line(it) << std::endl;
                                      if (!log.is_open()) log.open(log_path, std::ios::trunc);
                                      log << it.to_json().dump() << "\n" << std::flush;
                                  });
    const fs::path material = write_calibration_results(o, dir, result, study);
    print_calibration_summary(o, result, study, material);
    keep_results();  // what follows is the verdict on these results, not a failure to write them
    if (result.status == CalibrationStatus::unreachable) throw UserError("calibration stopped: " + result.message);
    if (result.status != CalibrationStatus::converged) throw std::runtime_error(result.message);
}

void add_calibrate(CLI::App& app) {
    auto o = std::make_shared<CalibrateCli>();
    auto* cmd = app.add_subcommand("calibrate", "find micro parameters whose simulated failure line matches a target");
    cmd->add_option("--target", o->target, "targets, e.g. mu_b=0.55,tau_c=800 (tau_c in Pa)");
    cmd->add_option("--measured", o->measured, "measured failure line SIGMA:TAU,... [Pa] (targets with its intervals)");
    cmd->add_option("--start", o->start_file, "starting material JSON")->required();
    cmd->add_option("--tol", o->tol, "relative tolerance on each target")->check(positive_number())->capture_default_str();
    cmd->add_option("--sensitivity", o->sensitivity_file, "stored sensitivity.json to reuse (default: run the study "
                                                          "around the start, reusing stored runs)");
    cmd->add_option("--controls", o->controls, "controlling parameters, one per target in order (default: chosen "
                                               "from the study)")->delimiter(',');
    cmd->add_option("--bounds", o->bounds, "search bounds NAME=LOW:HIGH (default: the studied range)");
    cmd->add_option("--method", o->method, "surrogate (default), coordinate or grid (baselines)")
        ->check(CLI::IsMember({"surrogate", "coordinate", "grid"}));
    cmd->add_flag("--sequential", o->sequential, "slope first, then cohesion (the seed's order)");
    cmd->add_flag("--strict", o->strict, "stop on the tolerance only, not when a target is inside the simulated interval");
    cmd->add_option("--max-evaluations", o->max_evaluations, "failure lines at most (start included)")->capture_default_str();
    cmd->add_option("--grid-points", o->grid_points, "points per parameter (grid method)")
        ->check(integer_in(2, 1000))
        ->capture_default_str();
    cmd->add_option("--output,-o", o->output, "calibrated material JSON (default CAMPAIGN/calibrated_material.json; calibrated_material_<method>.json for the baselines)");
    cmd->add_option("--params", o->study.params, "study: parameters to vary")->delimiter(',');
    cmd->add_option("--levels", o->study.levels, "study: values per parameter")->check(integer_in(3, calibration::kMaxLevels))->capture_default_str();
    cmd->add_option("--span", o->study.span, "study: base * (1 -+ span)")->capture_default_str();
    cmd->add_option("--range", o->study.ranges, "study: explicit range NAME=LOW:HIGH");
    add_campaign_options(cmd, o->study.campaign);
    cmd->callback([o, cmd] {
        // a stored study is read, not run: its own options were ignored (probe 59)
        if (!o->sensitivity_file.empty())
            for (const char* option : {"--params", "--levels", "--span", "--range"})
                if (cmd->count(option))
                    throw UserError(std::string(option) + " sets the sensitivity study, and --sensitivity reads a "
                                    "stored one instead of running it: leave it out, or run the study here (no "
                                    "--sensitivity)");
        o->study.span_given = cmd->count("--span") > 0;
        run_calibrate(*o);
    });
}

// ---- enlarge ----

struct EnlargeCli {
    std::vector<std::string> materials;
    std::string output = "enlargement.json";
    std::string plot_format = "png";
    bool no_plot = false;
    bool allow_unconverged = false;
};

// The output and the plot files beside it: checked, and apart from the inputs, before anything is read.
void check_enlarge_outputs(const EnlargeCli& o) {
    if (fs::path(o.output).extension() != ".json")  // the plot and its data take the same name
        throw UserError("--output = '" + o.output + "': must end in .json");
    check_output_file(o.output, "output");
    check_output_outside_run_folders(o.output, "--output");
    std::vector<NamedPath> inputs;
    for (const auto& file : o.materials) inputs.push_back({file, "material"});
    std::vector<NamedPath> outputs = {{o.output, "output"}};
    std::vector<std::string> side_files;
    if (!o.no_plot)  // the plot's files are written beside the output, by its name
        for (const fs::path& f : enlargement_plot_files(o.output, o.plot_format)) {
            outputs.push_back({f.string(), "output's plot file"});
            side_files.push_back(f.string());
        }
    check_paths_apart(inputs, outputs);
    check_side_files_free(o.output, side_files, "output");
}

// One material at several radii: every field but the radius, E, nu and the labels the same as in the first file
// (friction, density, box ...), or the laws would mix materials and say nothing of enlargement.
void check_same_material(const nlohmann::json& rest, const std::string& file, const nlohmann::json& first_rest,
                         const std::string& first_file) {
    for (const auto& [key, value] : first_rest.items())
        if (!rest.contains(key) || rest[key] != value)
            throw UserError("materials: " + key + " = " +
                            (rest.contains(key) ? analytics::json_value_text(rest[key]) : "(absent)") + " in '" +
                            analytics::shortened_text(file, 200) + "' but " + analytics::json_value_text(value) +
                            " in '" + analytics::shortened_text(first_file, 200) +
                            "': the laws are fitted to one material at several radii (only "
                            "particle_radius, young_modulus and poisson_ratio may differ)");
    for (const auto& [key, value] : rest.items())
        if (!first_rest.contains(key))
            throw UserError("materials: " + key + " is in '" + analytics::shortened_text(file, 200) +
                            "' but not in '" + analytics::shortened_text(first_file, 200) + "'");
}

// (radius, E, nu) of each calibrated material, one per radius.
struct EnlargementPoints {
    std::vector<double> r, e, nu;
};

// The calibration status demcal calibrate wrote into a material's description ("calibrated by demcal calibrate
// (not_converged): ..."); empty for a material it did not write.
std::string calibration_status_of(const nlohmann::json& material) {
    const std::string prefix = "calibrated by demcal calibrate (";
    if (!material.contains("description") || !material["description"].is_string()) return "";
    const std::string d = material["description"].get<std::string>();
    if (d.rfind(prefix, 0) != 0) return "";
    const auto end = d.find(')', prefix.size());
    return end == std::string::npos ? "" : d.substr(prefix.size(), end - prefix.size());
}

EnlargementPoints read_enlargement_points(const std::vector<std::string>& materials, bool allow_unconverged) {
    EnlargementPoints p;
    std::map<double, std::string> file_of_radius;
    nlohmann::json first_rest;  // the first material without the fields the laws are about
    std::string first_file;
    for (const auto& file : materials) {
        const nlohmann::json given = read_json_file(file, "material");
        const auto m = orchestrator::validate_material(given, file);  // (without its description)
        // a calibration that did not reach its target gives no point of the law (laws were fitted to them, exit 0)
        if (const std::string status = calibration_status_of(given);
            !status.empty() && status != to_string(CalibrationStatus::converged) && !allow_unconverged)
            throw UserError("materials: '" + analytics::shortened_text(file, 200) + "' was calibrated with status " +
                            analytics::shortened_text(status, 40) + " (its description), not converged: its E and nu "
                            "do not reproduce the reference line (--allow-unconverged takes it anyway)");
        nlohmann::json rest = m;
        for (const char* k : {"particle_radius", "young_modulus", "poisson_ratio", "name", "description"})
            rest.erase(k);
        if (first_file.empty()) {
            first_rest = rest;
            first_file = file;
        } else {
            check_same_material(rest, file, first_rest, first_file);
        }
        const double radius = m.at("particle_radius").get<double>();
        // the same radius twice (often the same file twice) is a point counted twice: it fakes the degrees of
        // freedom the intervals stand on (two radii given three times fitted "exactly", +/- 1e-15)
        if (const auto [it, fresh] = file_of_radius.emplace(radius, file); !fresh)
            throw UserError("materials: '" + analytics::shortened_text(file, 200) + "' and '" +
                            analytics::shortened_text(it->second, 200) + "' both have particle_radius = " +
                            analytics::number_text(radius) + " m; give one calibrated material per radius");
        p.r.push_back(radius);
        p.e.push_back(m.at("young_modulus").get<double>());
        p.nu.push_back(m.at("poisson_ratio").get<double>());
    }
    if (p.r.size() < 3) throw UserError("materials: " + std::to_string(p.r.size()) + " given, need at least 3 radii");
    try {
        analytics::check_radius_spacing(p.r, "materials' particle_radius");
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    return p;
}

nlohmann::json enlargement_json(const EnlargementPoints& p, const analytics::ScalingLawFit& e_law,
                                const analytics::ScalingLawFit& nu_law) {
    nlohmann::json j = {{"young_modulus", e_law.to_json()},
                        {"poisson_ratio", nu_law.to_json()},
                        {"note", "r in m; poisson_ratio is YADE's ks/kn stiffness ratio, so nu(r) is a law for it"},
                        {"points", nlohmann::json::array()}};
    for (std::size_t i = 0; i < p.r.size(); ++i)
        j["points"].push_back({{"particle_radius", p.r[i]}, {"young_modulus", p.e[i]}, {"poisson_ratio", p.nu[i]}});
    return j;
}

void print_enlargement(const analytics::ScalingLawFit& e_law, const analytics::ScalingLawFit& nu_law,
                       const std::string& output, const std::string& plot_file) {
    std::cout << "E(r)  = A r + B:  A = " << e_law.params[0].value << " +/- " << e_law.params[0].std_error
              << " Pa/m, B = " << e_law.params[1].value << " +/- " << e_law.params[1].std_error << " Pa (+/- 1 SE; R^2 "
              << e_law.r_squared << ")\n"
              << "nu(r) = C r^-D:   C = " << nu_law.params[0].value << " +/- " << nu_law.params[0].std_error
              << ", D = " << nu_law.params[1].value << " +/- " << nu_law.params[1].std_error << " (R^2 "
              << nu_law.r_squared << "; nu is YADE's ks/kn; +/- 1 SE)\nresults: " << output
              << (plot_file.empty() ? "" : ", " + plot_file) << "\n";
}

void run_enlarge(const EnlargeCli& o) {
    check_enlarge_outputs(o);
    const EnlargementPoints p = read_enlargement_points(o.materials, o.allow_unconverged);
    const auto e_law = analytics::fit_linear_law(p.r, p.e);
    const auto nu_law = analytics::fit_power_law(p.r, p.nu);
    for (const auto* law : {&e_law, &nu_law})  // e.g. nu equal at every radius: D is not identifiable
        if (!law->determined() && !o.allow_unconverged)
            throw std::runtime_error("enlarge: " + law->formula() + " is not determined by these " +
                                     std::to_string(p.r.size()) + " points: " + law->undetermined +
                                     "; nothing written (--allow-unconverged writes it anyway)");
    write_result_file(o.output, enlargement_json(p, e_law, nu_law).dump(2) + "\n");
    std::string plot_file;
    if (!o.no_plot) try {  // the laws are written: a missing gnuplot costs only the picture
            plot_enlargement(o.output, p.r, p.e, p.nu, e_law, nu_law, o.plot_format);
            plot_file = fs::path(o.output).replace_extension("." + o.plot_format).string();
        } catch (const std::exception& err) {
            std::cerr << "demcal: warning: plot not written: " << err.what() << "\n";
        }
    print_enlargement(e_law, nu_law, o.output, plot_file);
}

void add_enlarge(CLI::App& app) {
    auto o = std::make_shared<EnlargeCli>();
    auto* cmd = app.add_subcommand("enlarge", "fit E(r_p) = A r_p + B and nu(r_p) = C r_p^-D (seed eqs. 3.1-3.2) to "
                                              "materials calibrated at several particle radii");
    cmd->add_option("materials", o->materials, "calibrated material JSONs (one per radius; from demcal calibrate)")
        ->required();
    cmd->add_option("--output,-o", o->output, "result JSON (a plot beside it)")->capture_default_str();
    cmd->add_option("--plot", o->plot_format, "plot format")->check(CLI::IsMember({"png", "svg"}));
    cmd->add_flag("--no-plot", o->no_plot, "write no plot (no gnuplot needed)");
    cmd->add_flag("--allow-unconverged", o->allow_unconverged,
                  "write the laws even when the power-law fit did not converge (exit 0), and take materials whose "
                  "calibration did not converge");
    cmd->callback([o] { run_enlarge(*o); });
}

}  // namespace

void add_calibration_commands(CLI::App& app) {
    add_sensitivity(app);
    add_calibrate(app);
    add_enlarge(app);
}

}  // namespace demcal
