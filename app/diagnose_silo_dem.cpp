#include "app/diagnose_silo_dem.hpp"

#include "analytics/dem_diagnosis.hpp"
#include "analytics/number_text.hpp"
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/gnuplot.hpp"
#include "app/result_files.hpp"
#include "app/silo_campaign.hpp"
#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_campaign.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <tuple>
#include <sstream>

namespace demcal {

namespace {

namespace fs = std::filesystem;
namespace an = analytics;
using json = nlohmann::json;

// A campaign stopped by a signal or a run's suspension: the same command continues it.
struct CampaignStopped {};

// Silo options the diagnosis sets for every run (the data's geometry columns add theirs).
const std::vector<std::string> kOwnedSiloOptions = {"--theta", "--seed", "--out", "--resume", "--material", "--check"};

struct GeometryColumnOption {
    double an::SiloCondition::*value;
    const char* column;
    const char* option;
};
constexpr GeometryColumnOption kGeometryColumns[] = {{&an::SiloCondition::outlet_m, "outlet_m", "--outlet"},
                                                     {&an::SiloCondition::diameter_m, "D_m", "--diameter"},
                                                     {&an::SiloCondition::body_height_m, "body_height_m",
                                                      "--body-height"}};

std::vector<std::string> condition_options(const an::SiloCondition& c) {
    std::vector<std::string> a{"--theta", silo_number(c.theta_deg)};
    for (const auto& g : kGeometryColumns)
        if (std::isfinite(c.*g.value)) a.insert(a.end(), {g.option, silo_number(c.*g.value)});
    return a;
}

// A condition as its data columns give it: "theta_deg = 20, outlet_m = 30".
std::string condition_text(const an::SiloCondition& c) {
    std::string t = "theta_deg = " + silo_number(c.theta_deg);
    for (const auto& g : kGeometryColumns)
        if (std::isfinite(c.*g.value)) t += std::string(", ") + g.column + " = " + silo_number(c.*g.value);
    return t;
}

// The material file's JSON object at "object.key", or null when absent.
const json* field_at(const json& material, const std::string& path) {
    const auto dot = path.find('.');
    const std::string object = path.substr(0, dot), key = path.substr(dot + 1);
    if (!material.contains(object) || !material.at(object).is_object() || !material.at(object).contains(key))
        return nullptr;
    return &material.at(object).at(key);
}

// The declared value of a candidate (its fields' common value), or why it cannot be tried on this material.
std::pair<std::optional<double>, std::string> declared_value(const json& material, const an::DemEffectCandidate& c) {
    std::optional<double> value;
    for (const auto& f : c.fields) {
        const json* v = field_at(material, f);
        if (!v && c.absent) {  // the reader's default stands for the missing field
            if (value && *value != *c.absent)
                return {std::nullopt, "its fields are declared with different values (" + f + " absent, meaning " +
                                          an::number_text(*c.absent) + ", and " + an::number_text(*value) +
                                          "); the candidate sets them to one value"};
            value = *c.absent;
            continue;
        }
        if (!v) return {std::nullopt, "the material has no field " + f};
        if (!v->is_number()) return {std::nullopt, f + " is not a number"};
        if (value && *value != v->get<double>())
            return {std::nullopt, "its fields are declared with different values (" + c.fields.front() + " = " +
                                      an::number_text(*value) + ", " + f + " = " + an::number_text(v->get<double>()) +
                                      "); the candidate sets them to one value"};
        value = v->get<double>();
    }
    return {value, ""};
}

// The table's rows named by --candidates (all when none is named), in the table's order; an unknown or repeated name
// is refused with the known ones listed.
std::vector<an::DemEffectCandidate> chosen_candidates(const std::vector<std::string>& names) {
    const auto& table = an::dem_effect_candidates();
    std::string known;
    for (const auto& c : table) known += (known.empty() ? "" : ", ") + c.name;
    std::set<std::string> wanted;
    for (const auto& n : names)
        if (!wanted.insert(n).second)
            throw UserError("--candidates: '" + an::shortened_text(n) + "' named twice");
    for (const auto& n : wanted)
        if (std::none_of(table.begin(), table.end(), [&](const auto& c) { return c.name == n; }))
            throw UserError("--candidates: no DEM effect '" + an::shortened_text(n) + "' (known: " + known + ")");
    std::vector<an::DemEffectCandidate> out;
    for (const auto& c : table)
        if (wanted.empty() || wanted.count(c.name)) out.push_back(c);
    return out;
}

class SiloDemCampaign {
public:
    SiloDemCampaign(const SiloDemArgs& a, const an::SiloMeasurements& data, json declared)
        : args_(a), data_(data), dir_(a.campaign), declared_(std::move(declared)) {}

    // Mean rate [g/s] over the prediction seeds per condition, for each material.
    std::vector<std::vector<double>> rates(const std::vector<json>& materials) {
        std::vector<std::string> hashes;
        std::vector<SiloRunPlan> plans;
        for (const json& m : materials) {
            const std::string text = m.dump(1) + "\n";
            const std::string hash = orchestrator::sha256_hex(text).substr(0, 16);
            const fs::path file = dir_ / "materials" / (hash + ".json");
            if (!fs::exists(file)) {
                fs::create_directories(file.parent_path());
                orchestrator::write_text_file_atomically(file, text);
            }
            hashes.push_back(hash);
            for (std::size_t c = 0; c < data_.conditions.size(); ++c)
                for (int k = 0; k < args_.seeds; ++k) plans.push_back(plan(hash, file, c, args_.first_seed + k));
        }
        const auto start = std::chrono::steady_clock::now();
        const SiloCampaignOutcome o = run_silo_campaign(dir_, plans, args_.jobs, "diagnose",
                                                            {args_.executor, args_.partition});
        wall_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        cpu_seconds_ += o.cpu_seconds;
        runs_started_ += o.started;
        for (const auto& p : plans) runs_used_.insert(p.name);
        if (o.stopped) throw CampaignStopped{};
        std::vector<std::vector<double>> out;
        for (const std::string& hash : hashes) {
            std::vector<double> per_condition;
            for (std::size_t c = 0; c < data_.conditions.size(); ++c) {
                double sum = 0;
                for (int k = 0; k < args_.seeds; ++k) {
                    const std::string name = run_name(hash, c, args_.first_seed + k);
                    const auto summary = silo_run_summary(dir_, name);
                    if (!summary)
                        throw std::runtime_error("run " + name + " failed (see its log in " +
                                                 (dir_ / "runs" / name).string() +
                                                 "); a failed run is not retried: remove its folder to run it again");
                    // a run that ended without a steady discharge (an arch, a jam) predicts no flow: NaN, which the
                    // diagnosis reads as "this value stops the flow" (analytics/dem_diagnosis.hpp)
                    const double rate = summary->optional_number("rate/rate_kg_s").value_or(NAN) * 1e3;
                    sum += rate > 0 ? rate : NAN;
                }
                per_condition.push_back(sum / args_.seeds);
            }
            out.push_back(per_condition);
        }
        return out;
    }

    json material_with(const an::DemEffectCandidate& c, double value) const {
        json m = declared_;
        for (const auto& f : c.fields) {
            // a missing field at its absent value is left out: the declared material itself (and its runs reused)
            if (!field_at(declared_, f) && c.absent && value == *c.absent) continue;
            const auto dot = f.find('.');
            m[f.substr(0, dot)][f.substr(dot + 1)] = value;
        }
        return m;
    }

    // `demcal silo --check` of every condition with the declared material file: nothing written.
    // A refusal is named by the data's lines of that condition, whose values made the run (outlet_m = 30, in mm by
    // mistake, was reported as the geometry file's D_m at fault, by a run's name).
    void check_settings() const {
        for (std::size_t c = 0; c < data_.conditions.size(); ++c) {
            try {
                check_silo_runs({plan("check", args_.material, c, args_.first_seed)});
            } catch (const UserError& e) {
                std::string lines;
                for (std::size_t r = 0; r < data_.rows(); ++r)
                    if (data_.condition_of_row[r] == c) lines += (lines.empty() ? "" : ", ") + ("line " + std::to_string(data_.lines[r]));
                std::string why = e.what();
                if (const auto colon = why.find(": "); why.rfind("run ", 0) == 0 && colon != std::string::npos)
                    why.erase(0, colon + 2);  // (the run's name: the condition is named here by its data)
                throw UserError("--data = '" + an::shortened_text(data_.source, 200) + "', " + lines + " (" +
                                condition_text(data_.conditions[c]) + "): the silo run of this condition is refused: " +
                                why);
            }
        }
    }

    double wall_seconds() const { return wall_seconds_; }
    double cpu_seconds() const { return cpu_seconds_; }
    std::size_t runs_started() const { return runs_started_; }
    std::size_t runs_used() const { return runs_used_.size(); }

private:
    std::string run_name(const std::string& hash, std::size_t c, long long seed) const {
        return hash + "_" + data_.conditions[c].label() + "_seed" + std::to_string(seed);
    }
    SiloRunPlan plan(const std::string& hash, const fs::path& material, std::size_t c, long long seed) const {
        std::vector<std::string> a = condition_options(data_.conditions[c]);
        a.insert(a.end(), {"--seed", std::to_string(seed), "--material", fs::absolute(material).string()});
        a.insert(a.end(), args_.silo_args.begin(), args_.silo_args.end());
        return {run_name(hash, c, seed), a};
    }

    const SiloDemArgs& args_;
    const an::SiloMeasurements& data_;
    fs::path dir_;
    json declared_;
    double wall_seconds_ = 0, cpu_seconds_ = 0;
    std::size_t runs_started_ = 0;
    std::set<std::string> runs_used_;
};

std::string sci(double v) {
    if (!std::isfinite(v)) return "n/a";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

std::string percent(double log_rmse) { return sci(100 * log_rmse) + " %"; }

std::string interval_text(const an::DemCandidateResult& c) {
    return "[" + sci(c.interval_low) + (c.interval_at_lower_bound ? " (bound)" : "") + ", " + sci(c.interval_high) +
           (c.interval_at_upper_bound ? " (bound)" : "") + "]";
}


// Residuals [%] per measured row against the hopper angle, before and after (the effect named in the title).
void plot_residuals(const an::SiloMeasurements& data, const an::DemDiagnosis& r, const fs::path& dat,
                    const fs::path& before, const fs::path& after) {
    std::ostringstream rows;
    rows << "# line theta_deg measured_g_s declared_g_s after_g_s residual_before_pct residual_after_pct\n";
    for (std::size_t i = 0; i < data.rows(); ++i) {
        const std::size_t c = data.condition_of_row[i];
        const double d = r.rates_declared[c], a = r.rates_after[c], y = data.rate_g_s[i];
        rows << data.lines[i] << " " << data.conditions[c].theta_deg << " " << y << " " << d << " " << a << " "
             << 100 * (y - d) / d << " " << 100 * (y - a) / a << "\n";
    }
    write_result_file(dat, rows.str());
    const std::string effect =
        r.effect >= 0 ? r.candidates[std::size_t(r.effect)].spec.name + " = " +
                            sci(r.candidates[std::size_t(r.effect)].fitted)
                      : std::string("no effect named");
    for (int which = 0; which < 2; ++which) {
        std::ostringstream g;
        g << "set grid\nset xrange [0:90]\nset xlabel 'hopper half angle theta [deg]'\nset ylabel 'residual (measured - kernel) [%]'\n"
          << "set title '" << (which == 0 ? "silo-dem residuals, declared material" : "silo-dem residuals after: " + effect)
          << "' noenhanced\nset key top right\nplot " << gnuplot_quote(dat) << " using 2:" << (which == 0 ? 6 : 7)
          << " with points pt 7 ps 1 title 'measured runs', 0 lt -1 notitle\n";
        render_gnuplot(which == 0 ? before : after, g.str());
    }
}

std::string markdown(const SiloDemArgs& a, const an::SiloMeasurements& data, const an::DemDiagnosis& r,
                     const SiloDemCampaign& campaign, const std::string& plot_before, const std::string& plot_after) {
    std::ostringstream md;
    md << "# diagnose: silo-dem on " << a.data << "\n\n"
       << "Material declared: `" << a.material << "`; kernel runs: `demcal silo` with";
    for (const auto& s : a.silo_args) md << " " << s;
    md << ", " << r.prediction_seeds << " seed(s) per condition; campaign `" << a.campaign << "`.\n\n"
       << r.n << " rows, " << r.conditions << " conditions; measured repeat scatter (noise scale) "
       << percent(r.noise_sd) << " of the rate (" << r.df_pure_error << " dof).\n\n"
       << "| | RMSE (log rate) | CV RMSE (leave one condition out) | RMSE [g/s] | lack of fit p |\n|---|---|---|---|---|\n"
       << "| before (declared material) | " << percent(r.rmse_before) << " | " << percent(r.rmse_before) << " | "
       << sci(r.rmse_before_g_s) << " | " << sci(r.lack_of_fit_p_before) << " |\n"
       << "| after | " << percent(r.rmse_after) << " | " << percent(r.cv_rmse_after) << " | " << sci(r.rmse_after_g_s)
       << " | " << sci(r.lack_of_fit_p_after) << " |\n\n## DEM effect\n\n";
    if (r.effect >= 0) {
        const auto& e = r.candidates[std::size_t(r.effect)];
        md << "**" << e.spec.name << "** (";
        for (std::size_t k = 0; k < e.spec.fields.size(); ++k) md << (k ? ", " : "") << "`" << e.spec.fields[k] << "`";
        md << "): declared " << sci(e.declared) << ", fitted **" << sci(e.fitted) << "**, 95 % interval " << interval_text(e) << "; F = " << sci(e.f_statistic) << ", Holm p = " << sci(e.p_holm)
           << "; CV RMSE " << percent(e.cv_rmse_declared) << " -> " << percent(e.cv_rmse) << ". " << e.spec.mechanism
           << ".\n\n";
    } else {
        md << "None: no candidate was significant after Holm's correction (alpha " << sci(a.alpha)
           << ") and cut the CV RMSE by " << sci(100 * a.min_cv_gain) << " %.\n\n";
    }
    md << "## Candidates\n\n| candidate | fields | bounds (scale) | declared | fitted | interval | runs at | F | Holm p | "
          "CV RMSE declared -> fitted | named |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& c : r.candidates) {
        std::string fields;
        for (const auto& f : c.spec.fields) fields += (fields.empty() ? "" : ", ") + f;
        md << "| " << c.spec.name << " | " << fields << " | " << sci(c.spec.lower) << "-" << sci(c.spec.upper) << " ("
           << an::to_string(c.spec.scale) << ") | ";
        if (!c.available) {
            md << "not tried: " << c.unavailable << " | | | | | | | |\n";
            continue;
        }
        std::string at;
        for (double v : c.evaluated) at += (at.empty() ? "" : " ") + sci(v);
        md << sci(c.declared) << " | " << sci(c.fitted) << " | " << interval_text(c) << " | " << at << " | "
           << sci(c.f_statistic) << " | " << sci(c.p_holm) << " | " << percent(c.cv_rmse_declared) << " -> "
           << percent(c.cv_rmse) << " | " << (c.accepted ? "yes" : "") << " |\n";
    }
    md << "\n## Conditions\n\n| condition | measured mean [g/s] (n) | declared [g/s] | after [g/s] |\n|---|---|---|---|\n";
    for (std::size_t c = 0; c < data.conditions.size(); ++c) {
        double sum = 0;
        int n = 0;
        for (std::size_t i = 0; i < data.rows(); ++i)
            if (data.condition_of_row[i] == c) sum += data.rate_g_s[i], ++n;
        md << "| " << data.conditions[c].label() << " | " << sci(sum / n) << " (" << n << ") | "
           << sci(r.rates_declared[c]) << " | " << sci(r.rates_after[c]) << " |\n";
    }
    md << "\nKernel runs: " << campaign.runs_used() << " used, " << campaign.runs_started()
       << " run by this command (the rest from the campaign's cache); " << duration_text(campaign.wall_seconds())
       << " wall, " << duration_text(campaign.cpu_seconds()) << " CPU of the runs.\n";
    for (const auto& w : r.warnings) md << "\nWarning: " << w << "\n";
    if (!plot_before.empty()) md << "\n## Residuals\n\n![before](" << plot_before << ")\n\n![after](" << plot_after << ")\n";
    return md.str();
}

// The most kernel runs the search can take: every condition and seed for the declared material, then for each
// candidate that can be tried its bracket and refinement values (fewer when the campaign's cache holds some, or the
// refinement stops early). Refused by name (--max-runs) before the campaign folder exists.
void check_planned_runs(const SiloDemArgs& a, const an::SiloMeasurements& data, const json& declared,
                        const std::vector<an::DemEffectCandidate>& candidates) {
    std::size_t tried = 0;
    for (const auto& spec : candidates) tried += declared_value(declared, spec).second.empty() ? 1 : 0;
    const double per_material = static_cast<double>(data.conditions.size()) * a.seeds;
    const double materials = 1.0 + static_cast<double>(tried) * (a.grid_points + a.refine_steps);
    orchestrator::check_run_count(per_material * materials, a.max_runs,
                                  "diagnose silo-dem: " + std::to_string(data.conditions.size()) + " conditions x " +
                                      std::to_string(a.seeds) + " seeds x (1 declared + " + std::to_string(tried) +
                                      " candidates x (" + std::to_string(a.grid_points) + " grid points + " +
                                      std::to_string(a.refine_steps) + " refine steps)) materials");
}

// What the diagnosis starts from, read and checked before any run (issue 23: outputs first): the measurements, the
// declared material, the candidates to try.
struct SiloDemInputs {
    an::SiloMeasurements data;
    json declared;
    std::vector<an::DemEffectCandidate> candidates;
};

SiloDemInputs read_silo_dem_inputs(const SiloDemArgs& a) {
    SiloDemInputs in;
    if (a.material.empty()) throw UserError("--material: silo-dem needs the declared silo material (a JSON file)");
    // outputs first (issue 23): a path that cannot be written is refused before any run
    const std::string json_file = names_standard_output(a.json_out) ? "" : a.json_out;  // (--json -: stdout)
    check_output_file_in_new_folders(json_file, "--json");
    check_output_file_in_new_folders(a.report_out, "--report");
    std::vector<NamedPath> inputs = silo_campaign_inputs(a.silo_args, a.campaign);
    inputs.insert(inputs.end(), {{a.data, "--data"}, {a.material, "--material"}});
    check_paths_apart(inputs, {{json_file, "--json"}, {a.report_out, "--report"}, {a.campaign, "--campaign"}});
    if (fs::exists(a.campaign) && !fs::is_directory(a.campaign))
        throw UserError("--campaign = '" + a.campaign + "' is a file; give a folder");
    check_output_file_in_new_folders((fs::path(a.campaign) / "campaign.json").string(), "--campaign");
    an::SiloMeasurements& data = in.data;
    try {
        data = an::read_silo_measurements(a.data);
    } catch (const std::invalid_argument& e) {
        throw UserError(with_data_option(e.what()));
    }
    std::vector<std::string> owned = kOwnedSiloOptions;
    for (const auto& g : kGeometryColumns)
        if (std::isfinite(data.conditions.front().*g.value)) owned.push_back(g.option);
    refuse_owned_silo_options(a.silo_args, owned, "demcal diagnose --model silo-dem (or a column of the data)");
    if (data.conditions.size() < 3 || data.rows() <= data.conditions.size())
        throw UserError(a.data + ": " + std::to_string(data.rows()) + " rows in " +
                        std::to_string(data.conditions.size()) +
                        " conditions: silo-dem needs at least 3 conditions (leave-one-out) and repeats of one at least "
                        "(the noise scale)");
    try {  // before any run: the repeats' scatter was found missing after the kernel had run (a campaign written)
        an::check_diagnosable_data(data);
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    in.declared = read_json_file(a.material, "--material");
    const auto defects = an::candidate_table_defects(an::dem_effect_candidates());
    if (!defects.empty()) throw std::logic_error("the DEM candidate table: " + defects.front());
    in.candidates = chosen_candidates(a.candidates);
    check_planned_runs(a, data, in.declared, in.candidates);
    return in;
}

// Each candidate's declared value and how to predict the rates at others: materials run in the campaign.
std::vector<an::DemCandidateSetup> candidate_setups(SiloDemCampaign& campaign, const json& declared,
                                                    const std::vector<an::DemEffectCandidate>& candidates) {
    std::vector<an::DemCandidateSetup> setups;
    for (const auto& spec : candidates) {
        an::DemCandidateSetup s;
        s.spec = spec;
        std::tie(s.declared, s.unavailable) = declared_value(declared, spec);
        s.predict = [&campaign, spec](const std::vector<double>& values) {
            std::vector<json> materials;
            for (double v : values) materials.push_back(campaign.material_with(spec, v));
            std::cout << "  " << spec.name << " at";
            for (double v : values) std::cout << " " << v;
            std::cout << std::endl;
            return campaign.rates(materials);
        };
        setups.push_back(s);
    }
    return setups;
}

// The diagnosis in a few lines on stdout.
void print_diagnosis(const an::DemDiagnosis& r, const SiloDemCampaign& campaign) {
    std::cout << "model silo-dem: " << r.n << " rows, " << r.conditions << " conditions, repeat scatter "
              << percent(r.noise_sd) << "\nbefore: RMSE " << percent(r.rmse_before) << " (" << sci(r.rmse_before_g_s)
              << " g/s), lack of fit p = " << sci(r.lack_of_fit_p_before) << "\n";
    for (const auto& c : r.candidates) {
        if (!c.available) {
            std::cout << "  " << c.spec.name << ": not tried (" << c.unavailable << ")\n";
            continue;
        }
        std::cout << "  " << c.spec.name << ": declared " << sci(c.declared) << ", fitted " << sci(c.fitted) << " "
                  << interval_text(c) << ", F = " << sci(c.f_statistic) << ", Holm p = " << sci(c.p_holm)
                  << ", CV RMSE " << percent(c.cv_rmse_declared) << " -> " << percent(c.cv_rmse)
                  << (c.accepted ? "  <- named" : "") << "\n";
    }
    if (r.effect >= 0) {
        const auto& e = r.candidates[std::size_t(r.effect)];
        std::cout << "  + DEM effect: " << e.spec.name << " = " << sci(e.fitted) << " (95 % interval "
                  << interval_text(e) << ", declared " << sci(e.declared) << "), CV RMSE " << percent(r.rmse_before)
                  << " -> " << percent(r.cv_rmse_after) << "\n";
    } else {
        std::cout << "  no DEM effect named: nothing significant and better out of sample\n";
    }
    std::cout << "after:  RMSE " << percent(r.rmse_after) << " (" << sci(r.rmse_after_g_s) << " g/s), CV RMSE "
              << percent(r.cv_rmse_after) << "\n"
              << "kernel runs: " << campaign.runs_used() << " used, " << campaign.runs_started() << " run now, "
              << duration_text(campaign.wall_seconds()) << " wall, " << duration_text(campaign.cpu_seconds())
              << " CPU\n";
    for (const auto& w : r.warnings) std::cout << "warning: " << w << "\n";
}

// --json and --report (with its residual plots), whichever were asked for.
void write_diagnosis_outputs(const SiloDemArgs& a, const an::SiloMeasurements& data, const an::DemDiagnosis& r,
                             const SiloDemCampaign& campaign) {
    json j = r.to_json(data);
    j["data"] = a.data;
    j["material"] = a.material;
    j["campaign"] = a.campaign;
    j["silo_args"] = a.silo_args;
    j["runs"] = {{"used", campaign.runs_used()}, {"run_now", campaign.runs_started()},
                 {"wall_s", campaign.wall_seconds()}, {"cpu_s", campaign.cpu_seconds()}};
    // a JSON file first; on standard output last, once every file is whole (a pipe cannot take it back)
    const bool json_to_stdout = names_standard_output(a.json_out);
    if (!a.json_out.empty() && !json_to_stdout) write_json_result(a.json_out, j.dump(2) + "\n");
    if (!a.report_out.empty()) {
        const fs::path report(a.report_out);
        std::string before_name, after_name;
        if (!a.no_plots) {
            const std::string stem = report.stem().string();
            before_name = stem + "_residuals_before.png";
            after_name = stem + "_residuals_after.png";
            const fs::path dir = report.parent_path();
            try {
                plot_residuals(data, r, dir / (stem + "_residuals.dat"), dir / before_name, dir / after_name);
            } catch (const std::exception& e) {
                std::cerr << "demcal diagnose: warning: the plots were not drawn (" << e.what() << ")\n";
                before_name.clear();
            }
        }
        write_result_file(report, markdown(a, data, r, campaign, before_name, after_name));
    }
    if (json_to_stdout) write_json_result(a.json_out, j.dump(2) + "\n");
}

}  // namespace

std::string default_silo_dem_campaign(const std::string& data_path) {
    return "silo_dem_" + fs::path(data_path).stem().string();
}

int run_silo_dem_diagnosis(const SiloDemArgs& input) {
    SiloDemArgs a = input;
    if (a.campaign.empty()) a.campaign = default_silo_dem_campaign(a.data);
    const SiloDemInputs in = read_silo_dem_inputs(a);
    const an::SiloMeasurements& data = in.data;
    SiloDemCampaign campaign(a, data, in.declared);
    campaign.check_settings();  // silo's own checks of every condition and the material, nothing written
    // (the materials are files of the campaign named by their digest; a --geometry after -- is the user's file)
    const json settings{{"command", "diagnose --model silo-dem"}, {"silo_args", a.silo_args},
                        {"first_seed", a.first_seed}, {"prediction_seeds", a.seeds},
                        {kInputFileDigestsKey, silo_input_file_digests(a.silo_args)}};
    // runs are named by material, condition and seed, so more (or other) prediction seeds reuse the runs already made:
    // the design for separating a rival asks for exactly that (--seeds m)
    open_silo_campaign(a.campaign, settings, "diagnose silo-dem", {"first_seed", "prediction_seeds"});

    an::DemDiagnoseOptions options;
    options.grid_points = a.grid_points;
    options.refine_steps = a.refine_steps;
    options.prediction_seeds = a.seeds;
    options.alpha = a.alpha;
    options.min_cv_gain = a.min_cv_gain;
    const std::vector<an::DemCandidateSetup> setups = candidate_setups(campaign, in.declared, in.candidates);
    an::DemDiagnosis r;
    try {
        std::cout << "declared material (" << a.material << "): " << data.conditions.size() << " conditions x "
                  << a.seeds << " seed(s)" << std::endl;
        const auto declared_rates = campaign.rates({in.declared}).front();
        // measured rates of another unit or silo: no candidate's runs could explain them (held-back suite)
        if (const std::string mismatch = an::rate_scale_mismatch(data, declared_rates); !mismatch.empty()) {
            std::cout << "not determined: " << mismatch << "\n"
                      << "the diagnosis is not determined by these data (exit 1); no candidate was run\n";
            return 1;
        }
        r = an::diagnose_dem(data, declared_rates, setups, options);
    } catch (const CampaignStopped&) {
        std::cout << "stopped; the same command continues the campaign in " << a.campaign << " (finished runs kept)\n";
        return kExitResumeLater;
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }

    print_diagnosis(r, campaign);
    write_diagnosis_outputs(a, data, r, campaign);
    return 0;
}

}  // namespace demcal
