// demcal scale: the seed's particle-enlargement study (section 3.2) end to end, as stored, cached, resumable
// campaigns (calibration/particle_enlargement.hpp): base lines and cost per radius, the calibration of E and nu that
// restores the reference line, E(r) and nu(r) with intervals, and the verification of the laws' materials.
#include "analytics/number_text.hpp"
#include "app/campaign_cli.hpp"
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/result_files.hpp"
#include "app/scaling_plots.hpp"
#include "calibration/particle_enlargement.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_params.hpp"

#include <algorithm>
#include <iostream>
#include <memory>

namespace demcal {

namespace fs = std::filesystem;

namespace {

struct ScaleCli {
    std::string base_file;
    std::vector<double> radii;
    double tol = 0.05;
    double alpha = 0.05;
    int levels = 3;
    double span = 0.5;
    std::vector<std::string> ranges, bounds;
    int max_evaluations = 6;
    bool strict = false;
    bool point_targets = false;
    bool allow_unconverged = false;
    bool no_plot = false;
    std::string output;  // default CAMPAIGN/scale.json
    CampaignCli campaign;
};

calibration::EnlargementOptions enlargement_options(const ScaleCli& o) {
    calibration::EnlargementOptions e;
    e.radii = o.radii;
    e.line = calibration::line_kind_from_string(o.campaign.line);
    e.tolerance = o.tol;
    e.trend.alpha = o.alpha;
    e.study.levels = o.levels;
    e.study.relative_span = o.span;
    e.study.ranges = parse_ranges(o.ranges, "--range");
    e.calibration.max_evaluations = o.max_evaluations;
    e.calibration.accept_simulated_interval = !o.strict;
    e.bounds = parse_ranges(o.bounds, "--bounds");
    e.fit_unconverged = o.allow_unconverged;
    e.point_targets = o.point_targets;
    return e;
}

fs::path output_of(const ScaleCli& o) {
    return o.output.empty() ? fs::path(o.campaign.campaign_dir) / "scale.json" : fs::path(o.output);
}

// Everything checked before the campaign directory is touched: a bad radius must not cost simulations.
void check_scale(const nlohmann::json& base, const ScaleCli& o, const calibration::EnlargementOptions& options) {
    if (!o.output.empty()) {
        if (fs::path(o.output).extension() != ".json")  // the table and plots take the same stem
            throw UserError("--output = '" + o.output + "': must end in .json");
        check_output_in_campaign_or_existing_folder(o.output, "--output", o.campaign.campaign_dir);
        check_output_outside_run_folders(o.output, "--output");
    }
    check_paths_apart({{o.base_file, "base material"}}, {{output_of(o).string(), "--output"}});
    calibration::check_enlargement(base, options);
    const auto& c = o.campaign;
    // the design and every radius's material first: their messages name the cause, the run count only the total
    for (double r : o.radii) check_campaign(c, calibration::material_at_radius(base, r));
    const double lines = calibration::planned_failure_lines(options);
    orchestrator::check_run_count(lines * c.normal_stresses.size() * c.replicates, c.exec.max_runs,
                                  "scale: at most " + analytics::number_text(lines, 10) + " failure lines x " +
                                      std::to_string(c.normal_stresses.size()) + " normal stresses x " +
                                      std::to_string(c.replicates) + " replicates");
}

// The JSON, the Markdown table beside it and the three plots (a missing gnuplot costs only the pictures).
void write_outputs(const calibration::EnlargementStudy& study, const ScaleCli& o) {
    const fs::path json = output_of(o);
    write_result_file(json, study.to_json().dump(2) + "\n");
    fs::path table = json;
    write_result_file(table.replace_extension(".md"), study.markdown());
    if (o.no_plot) return;
    const std::string stem = (json.parent_path() / json.stem()).string(), ext = "." + o.campaign.plot_format;
    try {
        plot_macro_trends(stem + "_macro" + ext, study);
        plot_run_cost(stem + "_cost" + ext, study);
        if (study.young_law && study.poisson_law) {
            plot_enlargement(stem + "_laws.json", study.law_radii, study.law_young_moduli, study.law_poisson_ratios,
                             *study.young_law, *study.poisson_law, o.campaign.plot_format);
        } else {  // a resumed study whose laws are no longer fitted must not leave the last run's picture of them
            for (const std::string& suffix : {"_laws" + ext, std::string("_laws.dat")}) fs::remove(stem + suffix);
        }
    } catch (const std::exception& e) {
        std::cerr << "demcal: warning: plot not written: " << e.what() << "\n";
    }
}

void print_summary(const calibration::EnlargementStudy& study, const ScaleCli& o) {
    std::cout << "\n" << study.markdown() << "\n"
              << study.evaluations << " failure lines, " << study.simulations_run << " simulations run now, "
              << study.simulations_reused << " reused; " << runs_cpu_text(study.cpu_s, study.simulations_reused) << "\n";
    if (study.simulations_failed > 0)
        std::cout << study.simulations_failed << " runs failed (left out of their lines); "
                  << study.replacement_rounds << " rounds of fresh packings replaced them where a line could not be fitted\n";
    std::cout << "results: " << output_of(o).string()
              << (o.no_plot ? " (Markdown: .md; no plot drawn, --no-plot)"
                  : study.young_law && study.poisson_law
                      ? " (Markdown: .md; plots: _macro, _cost, _laws)"
                      : " (Markdown: .md; plots: _macro, _cost; no _laws: the laws were not fitted)")
              << std::endl;
    for (const auto& w : study.warnings) std::cerr << "demcal: warning: " << w << "\n";
}

}  // namespace

void add_scale_command(CLI::App& app) {
    auto o = std::make_shared<ScaleCli>();
    o->campaign.campaign_dir = "campaigns/scale";
    auto* cmd = app.add_subcommand(
        "scale", "particle-enlargement study (seed section 3.2): failure line and cost per radius, E and nu calibrated "
                 "to the smallest radius's line, E(r) = A r + B and nu(r) = C r^-D, verification");
    cmd->add_option("base", o->base_file, "base material JSON (its particle_radius is replaced by each radius)")
        ->required();
    cmd->add_option("--radii", o->radii, "particle radii [m], increasing; the first is the reference")
        ->delimiter(',')
        ->required();
    cmd->add_option("--tol", o->tol, "relative distance to the reference line that counts as restored")
        ->check(positive_number())
        ->capture_default_str();
    cmd->add_option("--alpha", o->alpha, "significance of the F test of a trend's slope")->capture_default_str();
    cmd->add_option("--levels", o->levels, "study of E and nu at each radius: values per parameter")
        ->check(integer_in(3, calibration::kMaxLevels))
        ->capture_default_str();
    cmd->add_option("--span", o->span, "study: base * (1 -+ span)")->capture_default_str();
    cmd->add_option("--range", o->ranges, "study: explicit range NAME=LOW:HIGH (young_modulus, poisson_ratio)");
    cmd->add_option("--bounds", o->bounds, "search bounds NAME=LOW:HIGH (default: the studied range)");
    cmd->add_option("--max-evaluations", o->max_evaluations, "failure lines per calibration at most (start included)")
        ->capture_default_str();
    cmd->add_flag("--strict", o->strict, "accept a calibration on the tolerance (and the reference's interval) only, "
                                         "not because the target lies inside the simulated line's interval");
    cmd->add_flag("--point-targets", o->point_targets,
                  "aim at the reference line's mu_b and tau_c within --tol only, not widened by the reference's own "
                  "interval");
    cmd->add_flag("--allow-unconverged", o->allow_unconverged,
                  "fit the laws through unconverged calibrations' best points too, and exit 0 when a fit is not "
                  "determined (reported all the same)");
    cmd->add_flag("--no-plot", o->no_plot, "write no plot (no gnuplot needed)");
    cmd->add_option("--output,-o", o->output, "result JSON (default CAMPAIGN/scale.json; table and plots beside it)");
    add_campaign_options(cmd, o->campaign);
    cmd->callback([o, cmd] {
        const auto base = orchestrator::validate_material(read_json_file(o->base_file, "base"), o->base_file);
        const auto options = enlargement_options(*o);
        const auto& controls = calibration::enlargement_controls();
        if (cmd->count("--span") &&
            std::all_of(controls.begin(), controls.end(), [&](const std::string& n) { return options.study.ranges.count(n); }))
            throw UserError("--span = " + analytics::number_text(o->span) + " sets the range of a control without "
                            "--range, and both (young_modulus, poisson_ratio) have their --range; leave --span out");
        check_scale(base, *o, options);
        CampaignSession session(o->campaign, "scale");
        const auto print = [](const std::string& line) { std::cout << line << std::endl; };
        const auto study = calibration::run_enlargement_study(base, session.evaluate, options, print);
        write_outputs(study, *o);
        keep_results();  // the study is written: an undetermined law below is its verdict, not a lost result
        print_summary(study, *o);
        if (!study.problems.empty() && !o->allow_unconverged) {
            // one line per problem, then the verdict on one line (a message is kept to one line)
            for (const auto& p : study.problems) std::cerr << "demcal: scale: " << p << "\n";
            throw std::runtime_error("scale: not every fit is determined (" + std::to_string(study.problems.size()) +
                                     (study.problems.size() == 1 ? " problem" : " problems") +
                                     " above; results written all the same)");
        }
    });
}

}  // namespace demcal
