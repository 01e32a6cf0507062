// demcal predict GEOMETRY.json: every discharge model's rate with its validity.
// demcal diagnose --model M --data F.csv: fit, residual diagnosis, the effect the model lacks, before/after errors.
#include "analytics/dem_diagnosis.hpp"
#include "analytics/diagnose.hpp"
#include "analytics/discharge_models.hpp"
#include "analytics/measured_data.hpp"
#include "analytics/number_text.hpp"
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/diagnose_silo_dem.hpp"
#include "app/gnuplot.hpp"
#include "app/result_files.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace demcal {

namespace {

constexpr const char* geometry_keys_help = R"(GEOMETRY.json keys (SI units, angles in degrees):
  geometry      "conical" (cylindrical silo with a conical hopper) or "rectangular"
  D_m           silo diameter (conical)
  b_m, c_m      silo depth and width (rectangular; the slot outlet spans the depth b)
  outlet_m      outlet diameter d (conical) or slot width a (rectangular)
  theta_deg     hopper half angle from the vertical, 90 = flat bottom
  d_p_m         particle size
  rho_b_kg_m3   bulk density
optional model constants (defaults in brackets):
  beverloo_C [0.58], beverloo_k [1.5], slot_C [1.03] (Myers-Sellers slot), delta [0.5] (Oldal's arch),
  phi_d_deg [45] (Rose-Tanaka stagnant-zone angle to the horizontal),
  delta_e_deg, phi_w_deg (effective internal and wall friction angles: with both, Jenike's mass-flow limit decides
  the flow pattern and each model says whether it applies))";

void run_predict(const std::string& geometry_path, const std::string& json_out) {
    const JsonOnStandardOutput json_stdout(json_out);
    if (!json_stdout.active()) {
        check_output_file_in_new_folders(json_out, "--json");  // before anything is printed as a result
        check_paths_apart({{geometry_path, "geometry"}}, {{json_out, "--json"}});
    }
    analytics::SiloGeometry geometry;
    try {
        geometry = analytics::geometry_from_json(read_json_file(geometry_path, "GEOMETRY"));
    } catch (const std::invalid_argument& e) {
        throw UserError(geometry_path + ": " + e.what());
    }
    const auto predictions = analytics::predict_discharge(geometry);
    std::cout << "model                  W [kg/s]   valid  notes\n";
    for (const auto& p : predictions) {
        std::string line = p.model;
        line.resize(22, ' ');
        // four significant digits: a slot of a few grains discharges 2e-5 kg/s, which four decimals showed as 0
        std::string rate = p.rate ? analytics::number_text(*p.rate, 4) : "-";
        rate.resize(10, ' ');
        std::cout << line << " " << rate << " " << (p.valid ? "yes  " : "NO   ") << "  ";
        for (size_t i = 0; i < p.warnings.size(); ++i) std::cout << (i ? "; " : "") << p.warnings[i];
        std::cout << "\n";
    }
    if (!json_out.empty()) {
        nlohmann::json j{{"geometry", geometry_path}, {"predictions", nlohmann::json::array()}};
        for (const auto& p : predictions) j["predictions"].push_back(p.to_json());
        if (geometry.effective_friction_deg)
            j["jenike_mass_flow_limit_deg"] =
                analytics::jenike_mass_flow_limit_deg(*geometry.effective_friction_deg, *geometry.wall_friction_deg);
        write_json_result(json_out, j.dump(2) + "\n");
    }
}


constexpr const char* diagnose_help = R"(Data: CSV with a header of column names, SI units, angles in degrees.
  discharge (beverloo, johanson, oldal, oldal-rect): geometry (conical|rectangular), D_m (conical) or b_m, c_m
    (rectangular), outlet_m, theta_deg, d_p_m, rho_b_kg_m3, W_kg_s
  shear (failure-line): sigma_Pa, tau_Pa
  any other column is a covariate the model does not use (numeric, or categorical such as operator).
Method: least-squares fit (GSL; discharge on log W), lack of fit against pure error of replicates, every column tried
as a candidate effect (nested F test, Holm correction over the candidates of a round), cross-validation leaving whole
conditions out; an effect is added when significant and it cuts the CV RMSE by at least --min-cv-gain; repeated until
nothing more is. Candidates include a covariate whose effect differs by regime: by flow mode (conical hoppers; from
the angle by the seed's classes, mass < 30 <= mixed <= 40 < funnel deg, or by Jenike's limit with
--effective-friction-deg and --wall-friction-deg), by the values of a --regime-column, or linearly with a condition
variable (x*z). Outliers: externally studentized residuals beyond a Bonferroni threshold (--outlier-alpha) are named
by file line; the effect search never uses them; --drop-outliers also reports the fits without them.
See examples/diagnose/README.md.)";

constexpr const char* silo_dem_help = R"(--model silo-dem --material M.json [--campaign DIR] [--jobs N] [-- silo options]:
  data: theta_deg, rate_g_s (g/s), optional outlet_m, D_m, body_height_m (conical), replicate; repeats as rows.
  Every condition is predicted by demcal silo with the declared material (a resumable, cached campaign); the
  residuals are traced to a DEM effect among the candidates below (or those named by --candidates), each fitted
  (coarse bracket, refinement), tested (F against the repeat scatter, Holm) and cross-validated leaving one
  condition out. A material without a candidate's field has the reader's default (no cohesion; the seed's grain).
  Candidates (material fields, bounds):)";

// The candidate table as the help lists it: one line each, from the table itself.
std::string candidate_help() {
    std::string text;
    for (const auto& c : analytics::dem_effect_candidates()) {
        std::string fields;
        for (const auto& f : c.fields) fields += (fields.empty() ? "" : ", ") + f;
        text += "\n    " + c.name + " (" + fields + ", " + analytics::number_text(c.lower) + " to " +
                analytics::number_text(c.upper) + ")";
    }
    return text;
}

// "all of a, b, c" for --candidates' help.
std::string candidate_names() {
    std::string names;
    for (const auto& c : analytics::dem_effect_candidates()) names += (names.empty() ? "" : ", ") + c.name;
    return names;
}

std::string sci(double v) {
    if (!std::isfinite(v)) return "n/a";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

// "vibration_Hz by flow_mode" for a regime effect, the column otherwise.
std::string effect_name(const std::string& variable, const std::string& kind, const std::string& regime) {
    if (regime.empty()) return variable;
    return variable + (kind == "interaction" ? " x " : " by ") + regime;
}

// Residual of row i: relative [%] for discharge rates, absolute for shear stresses.
double residual_of(const analytics::DiagnoseResult& r, double fitted, std::size_t i) {
    return r.residual_scale == "relative" ? 100.0 * (r.observed[i] - fitted) / fitted : r.observed[i] - fitted;
}

// The regime of each row for the first regime effect added (flow mode or a column's value); empty when none.
std::vector<std::string> regime_labels(const analytics::DiagnoseResult& r, const analytics::MeasuredData& data) {
    for (const auto& e : r.effects) {
        if (e.kind != "regime") continue;
        if (e.regime == "flow_mode") return r.flow_mode_of_row;
        if (const auto* c = data.find(e.regime)) return c->text;
    }
    return {};
}

// The residual plots beside a report REPORT.md: their data and the two pictures.
struct ReportPlots {
    std::filesystem::path data, before, after;
};
ReportPlots report_plots(const std::filesystem::path& report) {
    const std::string stem = report.stem().string();
    const auto dir = report.parent_path();
    return {dir / (stem + "_residuals.dat"), dir / (stem + "_residuals_before.png"),
            dir / (stem + "_residuals_after.png")};
}

// Every file report_plots' plots write (the data, each picture with its gnuplot files).
std::vector<std::filesystem::path> report_plot_files(const std::filesystem::path& report) {
    const ReportPlots p = report_plots(report);
    std::vector<std::filesystem::path> files = {p.data};
    for (const auto& picture : {p.before, p.after})
        for (auto& f : gnuplot_files(picture)) files.push_back(std::move(f));
    return files;
}

// Residuals against the fitted value and against the first added effect's column (or the file order): before/after.
// Rows are coloured by the regime of a regime effect, so that its slopes show; outliers are drawn apart.
void plot_residuals(const analytics::DiagnoseResult& r, const analytics::MeasuredData& data,
                    const std::filesystem::path& dat, const std::filesystem::path& before,
                    const std::filesystem::path& after) {
    // x: the covariate of a regime effect (its slopes by regime are the finding), else the first effect's column.
    std::string x_name = "row in file";
    const analytics::DataColumn* x_col = nullptr;
    for (const bool regime_only : {true, false}) {
        for (const auto& e : r.effects)
            if (const auto* c = data.find(e.variable); c && c->numeric && (!regime_only || e.kind == "regime")) {
                x_col = c;
                x_name = e.variable;
                break;
            }
        if (x_col) break;
    }
    const auto labels = regime_labels(r, data);
    std::vector<std::string> levels;  // in order of appearance
    for (const auto& l : labels)
        if (std::find(levels.begin(), levels.end(), l) == levels.end()) levels.push_back(l);
    if (levels.empty()) levels.push_back("rows");
    {
        std::ostringstream out;
        out << "# line observed fitted_before fitted_after residual_before residual_after x outlier regime_index\n";
        for (std::size_t i = 0; i < r.observed.size(); ++i) {
            const bool outlier = std::any_of(r.outliers.rows.begin(), r.outliers.rows.end(),
                                             [&](const analytics::Outlier& o) { return o.line == r.lines[i]; });
            out << r.lines[i] << " " << r.observed[i] << " " << r.fitted_before[i] << " " << r.fitted_after[i] << " "
                << residual_of(r, r.fitted_before[i], i) << " " << residual_of(r, r.fitted_after[i], i) << " "
                << (x_col ? x_col->values[i] : static_cast<double>(i + 1)) << " " << (outlier ? 1 : 0) << " "
                << (labels.empty() ? 0 : std::find(levels.begin(), levels.end(), labels[i]) - levels.begin()) << "\n";
        }
        write_result_file(dat, out.str());
    }
    const std::string unit = r.residual_scale == "relative" ? "residual [%]" : "residual [Pa]";
    for (int which = 0; which < 2; ++which) {
        const int col = which == 0 ? 5 : 6, fitted = which == 0 ? 3 : 4;
        const std::string title = which == 0 ? "before" : "after";
        std::ostringstream g;
        g << "set multiplot layout 1,2 title "
          << gnuplot_text(r.model + " residuals " + title +
                          (which == 1 ? " (" + std::to_string(r.effects.size()) + " effect(s) added)" : std::string()))
          << " noenhanced\n"
          << "set grid\nset ylabel '" << unit << "'\nset key top right\nset title noenhanced\n"
          << "set xlabel " << gnuplot_text("fitted " + r.response) << " noenhanced\n";
        // Outliers (column 8 = 1) drawn apart, so that the eye does not read them as a trend.
        auto points = [&](const std::string& x) {
            const std::string q = gnuplot_quote(dat), y = "$" + std::to_string(col);
            std::string series;
            for (std::size_t k = 0; k < levels.size(); ++k)
                series += q + " using " + x + ":($8 == 0 && $9 == " + std::to_string(k) + " ? " + y +
                          " : 1/0) with points pt 7 ps 0.8 lc " + std::to_string(k + 1) + " title " + gnuplot_text(levels[k]) +
                          " noenhanced, ";
            if (!r.outliers.rows.empty())
                series += q + " using " + x + ":($8 == 1 ? " + y +
                          " : 1/0) with points pt 6 ps 2 lc rgb '#d62728' title 'outliers', ";
            return series + "0 lt -1 notitle\n";
        };
        g << "plot " << points(std::to_string(fitted)) << "set xlabel " << gnuplot_text(x_name) << " noenhanced\n"
          << "plot " << points("7") << "unset multiplot\n";
        render_gnuplot(which == 0 ? before : after, g.str(), 1100, 450);
    }
}

std::string markdown_report(const analytics::DiagnoseResult& r, const std::string& data_path,
                            const std::string& plot_before, const std::string& plot_after) {
    std::ostringstream md;
    md << "# diagnose: " << r.model << " on " << data_path << "\n\n"
       << r.n << " rows, " << r.conditions << " distinct conditions, " << r.folds
       << "-fold cross-validation leaving whole conditions out; residuals " << r.residual_scale << ".\n\n"
       << "| | RMSE | CV RMSE | MAPE [%] |\n|---|---|---|---|\n"
       << "| before | " << sci(r.before.rmse) << " | " << sci(r.before.cv_rmse) << " | " << sci(r.before.mape) << " |\n"
       << "| after | " << sci(r.after.rmse) << " | " << sci(r.after.cv_rmse) << " | " << sci(r.after.mape) << " |\n\n";
    auto lof = [&](const char* when, const std::optional<analytics::LackOfFitTest>& t) {
        if (t)
            md << "Lack of fit " << when << ": F = " << sci(t->f_statistic) << " (" << t->df_lack_of_fit << ", "
               << t->df_pure_error << " dof), p = " << sci(t->p_value) << "\n\n";
        else
            md << "Lack of fit " << when << ": not testable (no replicates or too few conditions)\n\n";
    };
    lof("before", r.lack_of_fit_before);
    lof("after", r.lack_of_fit_after);
    md << "## Effects added\n\n";
    if (r.effects.empty()) md << "None: no candidate was significant after Holm's correction and improved the CV RMSE.\n\n";
    for (const auto& e : r.effects) {
        md << "- **" << effect_name(e.variable, e.kind, e.regime) << "** (" << e.kind << "): `" << e.form << "`; ";
        for (const auto& p : e.params)
            md << p.name << " = " << sci(p.value) << " +/- " << sci(p.std_error) << " (1 SE); ";
        md << "F = " << sci(e.f_statistic) << ", p = " << sci(e.p_value) << ", Holm p = " << sci(e.p_holm) << " over "
           << e.candidates_tried << " candidates; CV RMSE " << sci(e.cv_rmse_before) << " -> " << sci(e.cv_rmse_after)
           << "\n";
    }
    if (!r.flow_mode_rule.empty()) md << "\nFlow mode (a regime of the candidates): " << r.flow_mode_rule << ".\n";
    md << "\n## Outliers\n\nExternally studentized residuals under the final model, Bonferroni threshold |t| > "
       << sci(r.outliers.threshold) << " (alpha " << sci(r.outliers.alpha) << " over " << r.n
       << " rows). The effect search ran without the rows flagged.\n\n";
    if (r.outliers.rows.empty()) {
        md << "None.\n";
    } else {
        md << "| line | observed | fitted | studentized residual |\n|---|---|---|---|\n";
        for (const auto& o : r.outliers.rows)
            md << "| " << o.line << " | " << sci(o.observed) << " | " << sci(o.fitted) << " | " << sci(o.studentized)
               << " |\n";
        const auto& w = r.outliers.with_outliers;
        const auto& wo = r.outliers.without_outliers;
        md << "\n| final model fitted | RMSE | CV RMSE | MAPE [%] |\n|---|---|---|---|\n"
           << "| with them (" << r.n << " rows) | " << sci(w.rmse) << " | " << sci(w.cv_rmse) << " | " << sci(w.mape)
           << " |\n| without them (" << r.n - static_cast<int>(r.outliers.rows.size()) << " rows) | " << sci(wo.rmse)
           << " | " << sci(wo.cv_rmse) << " | " << sci(wo.mape) << " |\n\nThe fits reported above are "
           << (r.outliers.dropped ? "without them (--drop-outliers)" : "with them (--drop-outliers refits without)")
           << ".\n";
    }
    md << "\n## Parameters\n\n| parameter | before (+/- 1 SE) | after (+/- 1 SE) |\n|---|---|---|\n";
    for (std::size_t i = 0; i < r.params_after.size(); ++i) {
        const auto& a = r.params_after[i];
        md << "| " << a.name << " | "
           << (i < r.params_before.size() ? sci(r.params_before[i].value) + " +/- " + sci(r.params_before[i].std_error)
                                          : std::string("-"))
           << " | " << sci(a.value) << " +/- " << sci(a.std_error) << " |\n";
    }
    md << "\n## Candidates examined\n\n";
    for (std::size_t k = 0; k < r.rounds.size(); ++k) {
        md << "Round " << k + 1 << "\n\n| effect | kind | form | F | p | Holm p | CV RMSE | added |\n"
           << "|---|---|---|---|---|---|---|---|\n";
        for (const auto& c : r.rounds[k])
            md << "| " << effect_name(c.variable, c.kind, c.regime) << " | " << c.kind << " | `" << c.form << "` | "
               << sci(c.f_statistic) << " | "
               << sci(c.p_value) << " | " << sci(c.p_holm) << " | " << sci(c.cv_rmse) << " | "
               << (c.accepted ? "yes" : "") << " |\n";
        md << "\n";
    }
    if (!r.undetermined.empty()) {
        md << "## Not determined by these data\n\n";
        for (const auto& w : r.undetermined) md << "- " << w << "\n";
        md << "\n";
    }
    if (!r.warnings.empty()) {
        md << "## Warnings\n\n";
        for (const auto& w : r.warnings) md << "- " << w << "\n";
        md << "\n";
    }
    if (!plot_before.empty())
        md << "## Residuals\n\n![before](" << plot_before << ")\n\n![after](" << plot_after << ")\n";
    return md.str();
}

struct DiagnoseArgs {
    std::string model, data, json_out, report_out;
    analytics::DiagnoseOptions options;
    double effective_friction_deg = std::nan(""), wall_friction_deg = std::nan("");  // NaN: not given
    bool no_plots = false;
    bool allow_undetermined = false;  // exit 0 even when the diagnosis is not determined by the data
    int max_rows = int(analytics::kMaxMeasuredRows);
    SiloDemArgs silo_dem;  // --model silo-dem: the kernel's silo as the model
};

// Options that only the silo-dem model takes, refused (named) with an analytical model.
const char* const kSiloDemOptions[] = {"--material", "--campaign", "--jobs", "--seeds", "--first-seed", "--grid-points",
                                       "--refine-steps", "--executor", "--partition", "--candidates", "--max-runs"};
// Options of the analytical search that silo-dem does not use (one effect from its table, no regimes or outliers yet):
// refused rather than ignored.
const char* const kAnalyticalOnlyOptions[] = {"--max-effects", "--regime-column", "--effective-friction-deg",
                                              "--wall-friction-deg", "--outlier-alpha", "--drop-outliers",
                                              "--allow-undetermined"};

// The diagnosis on the console: the fit before, each effect added with its parameters and test, after, outliers,
// warnings and what the data do not determine.
void print_diagnosis(const analytics::DiagnoseResult& r, int max_effects) {
    std::cout << "model " << r.model << ": " << r.n << " rows, " << r.conditions << " conditions, " << r.folds
              << " CV folds\n"
              << "before: RMSE " << sci(r.before.rmse) << "  CV RMSE " << sci(r.before.cv_rmse) << "  MAPE "
              << sci(r.before.mape) << " %\n";
    for (const auto& e : r.effects) {
        std::cout << "  + " << effect_name(e.variable, e.kind, e.regime) << " (" << e.kind << "): " << e.form
                  << "\n    ";
        for (const auto& p : e.params)
            std::cout << p.name << " = " << sci(p.value) << " +/- " << sci(p.std_error) << " (1 SE)  ";
        std::cout << "p = " << sci(e.p_value) << " (Holm " << sci(e.p_holm) << ", " << e.candidates_tried
                  << " candidates), CV RMSE " << sci(e.cv_rmse_before) << " -> " << sci(e.cv_rmse_after) << "\n";
    }
    if (r.effects.empty())
        std::cout << (max_effects == 0 ? "  no effect searched for (--max-effects 0): the base model only\n"
                                       : "  no effect added: nothing significant and better out of sample\n");
    std::cout << "after:  RMSE " << sci(r.after.rmse) << "  CV RMSE " << sci(r.after.cv_rmse) << "  MAPE "
              << sci(r.after.mape) << " %\n";
    for (const auto& o : r.outliers.rows)
        std::cout << "outlier: line " << o.line << ": observed " << sci(o.observed) << ", fitted " << sci(o.fitted)
                  << ", studentized residual " << sci(o.studentized) << " (|t| > " << sci(r.outliers.threshold)
                  << " flags)\n";
    if (!r.outliers.rows.empty())
        std::cout << "  final model with them: RMSE " << sci(r.outliers.with_outliers.rmse) << "  CV RMSE "
                  << sci(r.outliers.with_outliers.cv_rmse) << "; without: RMSE "
                  << sci(r.outliers.without_outliers.rmse) << "  CV RMSE " << sci(r.outliers.without_outliers.cv_rmse)
                  << (r.outliers.dropped ? " (reported fits: without)" : " (reported fits: with; --drop-outliers)")
                  << "\n";
    for (const auto& w : r.warnings) std::cout << "warning: " << w << "\n";
    for (const auto& w : r.undetermined) std::cout << "not determined: " << w << "\n";
}

// --json and --report (with its residual plots unless --no-plots).
void write_diagnosis_files(const DiagnoseArgs& a, const analytics::DiagnoseResult& r,
                           const analytics::MeasuredData& data) {
    // a JSON file first; on standard output last, once every file is whole (a pipe cannot take it back)
    const bool json_to_stdout = names_standard_output(a.json_out);
    if (!a.json_out.empty() && !json_to_stdout) write_json_result(a.json_out, r.to_json().dump(2) + "\n");
    if (!a.report_out.empty()) {
        const std::filesystem::path report(a.report_out);
        std::string before_name, after_name;
        std::optional<ReportPlots> plots;
        if (!a.no_plots) {
            plots = report_plots(report);
            before_name = plots->before.filename().string();
            after_name = plots->after.filename().string();
        }
        // the report before its plots: a plot that fails, or a stop signal while gnuplot draws, takes the report
        // with it (app/result_files.hpp, app/gnuplot.cpp); a kill -9 meanwhile leaves the report, which the same
        // command then replaces with its side files (without it, they would be files it may not replace)
        write_result_file(a.report_out, markdown_report(r, a.data, before_name, after_name));
        if (plots) plot_residuals(r, data, plots->data, plots->before, plots->after);
    }
    if (json_to_stdout) write_json_result(a.json_out, r.to_json().dump(2) + "\n");
}

// Every output place before any work (issue 23): a path that cannot be written is refused at once.
void check_diagnosis_outputs(const DiagnoseArgs& a) {
    const std::string json_file = names_standard_output(a.json_out) ? "" : a.json_out;  // (--json -: stdout)
    check_output_file_in_new_folders(json_file, "--json");
    check_output_file_in_new_folders(a.report_out, "--report");
    std::vector<NamedPath> outputs = {{json_file, "--json"}, {a.report_out, "--report"}};
    std::vector<std::string> side_files;
    if (!a.report_out.empty() && !a.no_plots)  // the report's plots and their data, beside it by its name
        for (const auto& f : report_plot_files(a.report_out)) {
            outputs.push_back({f.string(), "--report's plot file"});
            side_files.push_back(f.string());
        }
    check_paths_apart({{a.data, "--data"}}, outputs);
    check_side_files_free(a.report_out, side_files, "--report");
    if (!a.report_out.empty() && !a.no_plots) require_gnuplot("--no-plots");
}

// 0, or 1 when the diagnosis is not determined by the data (and not --allow-undetermined): results are written.
int run_diagnose(const DiagnoseArgs& a) {
    check_diagnosis_outputs(a);
    const analytics::MeasuredData data = [&] {
        try {
            return analytics::read_measured_csv(a.data, analytics::data_kind_of(a.model), std::size_t(a.max_rows));
        } catch (const std::invalid_argument& e) {
            throw UserError(with_data_option(e.what()));
        }
    }();
    auto options = a.options;
    options.names = {"--regime-column", "--effective-friction-deg", "--wall-friction-deg"};
    if (!std::isnan(a.effective_friction_deg)) options.effective_friction_deg = a.effective_friction_deg;
    if (!std::isnan(a.wall_friction_deg)) options.wall_friction_deg = a.wall_friction_deg;
    const analytics::DiagnoseResult r = analytics::diagnose(data, a.model, options);
    print_diagnosis(r, options.max_effects);
    write_diagnosis_files(a, r, data);
    if (r.undetermined.empty() || a.allow_undetermined) return 0;
    // the verdict behind exit 1 on stderr too, one line (it was on stdout only: a script saw exit 1 and an empty
    // stderr, held-back probe 65); the details stay in the report above
    std::cout.flush();
    std::cerr << "demcal: failed: the diagnosis is not determined by these data ("
              << analytics::shortened_text(r.undetermined.front(), 300)
              << ")" << (a.json_out.empty() && a.report_out.empty() ? "" : "; its results are written")
              << " (exit 1; --allow-undetermined: exit 0)" << std::endl;
    return 1;
}

// The model decides the run: silo-dem (kernel runs), or an analytical model; the options of the other refused.
void run_diagnose_command(const DiagnoseArgs& args, const CLI::App& diagnose) {
    const JsonOnStandardOutput json_stdout(args.json_out);
    const auto& analytical = analytics::diagnose_models();
    if (args.model != "silo-dem" && std::find(analytical.begin(), analytical.end(), args.model) == analytical.end()) {
        std::string known;
        for (const auto& m : analytical) known += m + ", ";
        throw UserError("--model = '" + analytics::shortened_text(args.model, 60) + "' is unknown; expected one of " +
                        known + "silo-dem");
    }
    if (args.model == "silo-dem") {
        for (const char* option : kAnalyticalOnlyOptions)
            if (diagnose.count(option))
                throw UserError(std::string(option) + ": the analytical models take it, not --model silo-dem");
        SiloDemArgs dem = args.silo_dem;
        dem.data = args.data;
        dem.json_out = args.json_out;
        dem.report_out = args.report_out;
        dem.no_plots = args.no_plots;
        dem.alpha = args.options.family_alpha;
        dem.min_cv_gain = args.options.min_cv_improvement;
        if (const int status = run_silo_dem_diagnosis(dem); status != 0) throw CLI::RuntimeError(status);
        return;
    }
    for (const char* option : kSiloDemOptions)
        if (diagnose.count(option))
            throw UserError(std::string(option) + ": only --model silo-dem takes it (model '" + args.model + "')");
    // the flow mode (mass / funnel) is the silo models' regime: a shear test has none, and the angles did nothing
    if (args.model == "failure-line")
        for (const char* option : {"--effective-friction-deg", "--wall-friction-deg"})
            if (diagnose.count(option))
                throw UserError(std::string(option) + ": the silo models' flow mode takes it; --model failure-line "
                                "(a shear test) has no flow mode");
    if (!args.silo_dem.silo_args.empty())
        throw UserError("options after -- ('" + args.silo_dem.silo_args.front() +
                        "'): only --model silo-dem runs demcal silo");
    if (const int status = run_diagnose(args); status != 0) throw CLI::RuntimeError(status);
}

void add_predict_command(CLI::App& app) {
    auto predict = app.add_subcommand("predict", "Discharge rate of a silo by every analytical model, with validity");
    auto geometry = std::make_shared<std::string>();
    auto predict_json = std::make_shared<std::string>();
    predict->add_option("GEOMETRY", *geometry, "silo geometry JSON (keys below)")->required();
    predict->add_option("--json", *predict_json,
                        "also write the predictions as JSON to this file (-: to standard output, the table to stderr)");
    predict->footer(geometry_keys_help);
    predict->callback([geometry, predict_json] { run_predict(*geometry, *predict_json); });
}

// --model silo-dem's options: the kernel campaign that predicts every measured condition.
void add_silo_dem_options(CLI::App* diagnose, SiloDemArgs& dem) {
    diagnose->add_option("--material", dem.material, "silo-dem: the declared silo material (JSON, as demcal silo's)");
    diagnose->add_option("--campaign", dem.campaign,
                         "silo-dem: campaign folder of the kernel runs (default silo_dem_<data stem>); the same "
                         "command continues it and reruns nothing");
    diagnose->add_option("--jobs", dem.jobs, "silo-dem: kernel runs at once")->capture_default_str()->check(
        integer_in(1, 256));
    diagnose->add_option("--executor", dem.executor, "silo-dem: local (processes) or slurm (job arrays)")
        ->capture_default_str()
        ->check(CLI::IsMember({"local", "slurm"}));
    diagnose->add_option("--partition", dem.partition, "silo-dem: SLURM partition (--executor slurm)");
    diagnose->add_option("--seeds", dem.seeds, "silo-dem: kernel runs (seeds) averaged per condition and material")
        ->capture_default_str()
        ->check(integer_in(1, 20));
    diagnose->add_option("--first-seed", dem.first_seed, "silo-dem: seed of the first prediction run")
        ->capture_default_str()
        ->check(integer_in(0, 1LL << 62));
    diagnose->add_option("--grid-points", dem.grid_points, "silo-dem: coarse bracket per candidate (values run)")
        ->capture_default_str()
        ->check(integer_in(3, 30));
    diagnose->add_option("--refine-steps", dem.refine_steps, "silo-dem: refinement proposals after the bracket")
        ->capture_default_str()
        ->check(integer_in(0, 20));
    diagnose->add_option("--max-runs", dem.max_runs,
                         "silo-dem: most kernel runs the search may take (conditions x seeds x (1 + candidates x "
                         "(grid points + refine steps)), at most; a guard against typos), refused before any run")
        ->capture_default_str()
        ->check(integer_in(1, 1000000000));
    diagnose->add_option("--candidates", dem.candidates,
                         "silo-dem: the DEM effects to try, by name (default: all of " + candidate_names() +
                             "; e.g. wall_friction,cohesion)")
        ->delimiter(',');
    diagnose->add_option("silo_args", dem.silo_args,
                         "silo-dem, after --: options of every demcal silo run (e.g. --geometry G --particles 2000 "
                         "--stiffness-scale 0.001 --fill-time 0.5 --threads 1 --no-plots)");
}

void add_diagnose_command(CLI::App& app) {
    auto diagnose = app.add_subcommand("diagnose", "Fit a model to measured data, trace its residuals to the effect "
                                                   "it lacks, report the error before and after");
    auto args = std::make_shared<DiagnoseArgs>();
    std::string models;
    for (const auto& m : analytics::diagnose_models()) models += (models.empty() ? "" : ", ") + m;
    models += ", silo-dem (the kernel's silo with --material)";
    diagnose->add_option("--model", args->model, "the model: " + models)->required();
    diagnose->add_option("--data", args->data, "measured data, CSV (columns below)")->required();
    diagnose->add_option("--json", args->json_out,
                         "write the result as JSON to this file (-: to standard output, the text to stderr)");
    diagnose->add_option("--report", args->report_out,
                         "write a Markdown report here, with residual plots (PNG) beside it");
    diagnose->add_flag("--no-plots", args->no_plots, "report without the gnuplot residual plots");
    diagnose->add_flag("--allow-undetermined", args->allow_undetermined,
                       "exit 0 even when the fit did not converge or the data cannot determine it (default: exit 1)");
    diagnose->add_option("--alpha", args->options.family_alpha,
                         "family-wise error rate of each round's candidate tests (Holm)")
        ->capture_default_str()
        ->check(number_in(1e-6, 0.5));
    diagnose->add_option("--min-cv-gain", args->options.min_cv_improvement,
                         "least relative drop of the cross-validated RMSE for an effect to be added")
        ->capture_default_str()
        ->check(number_in(0.0, 0.9));
    diagnose->add_option("--max-rows", args->max_rows,
                         "most data rows (about 2 ms of diagnosis per row: a limit against a wrong file)")
        ->capture_default_str()
        ->check(integer_in(1, 10000000));
    diagnose->add_option("--max-effects", args->options.max_effects, "most effects to add")
        ->capture_default_str()
        ->check(number_in(0, 10));
    diagnose->add_option("--regime-column", args->options.regime_columns,
                         "a column whose values may change a covariate's effect (repeatable); the flow mode is "
                         "always tried for conical hoppers");
    diagnose->add_option("--effective-friction-deg", args->effective_friction_deg,
                         "effective angle of internal friction delta_e: with --wall-friction-deg, the flow mode "
                         "comes from Jenike's mass-flow limit instead of the seed's classes")
        ->check(number_in(0, 90));
    diagnose->add_option("--wall-friction-deg", args->wall_friction_deg, "wall friction angle phi_w (see above)")
        ->check(number_in(0, 90));
    diagnose->add_option("--outlier-alpha", args->options.outlier_alpha,
                         "chance of flagging any row of a set without outliers (Bonferroni over the rows)")
        ->capture_default_str()
        ->check(number_in(1e-6, 0.5));
    diagnose->add_flag("--drop-outliers", args->options.drop_outliers,
                       "report the fits without the rows flagged as outliers (the search never uses them)");
    add_silo_dem_options(diagnose, args->silo_dem);
    diagnose->footer(std::string(diagnose_help) + "\n\n" + silo_dem_help + candidate_help());
    diagnose->callback([args, diagnose] { run_diagnose_command(*args, *diagnose); });
}

}  // namespace

void add_discharge_commands(CLI::App& app) {
    add_predict_command(app);
    add_diagnose_command(app);
}

}  // namespace demcal
