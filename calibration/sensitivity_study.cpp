#include "calibration/sensitivity_study.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"  // json_value_text
#include "orchestrator/run_identity.hpp"  // sha256_hex, read_text_file
#include "orchestrator/shear_campaign.hpp"  // to_string(ShearEngine)
#include "orchestrator/shear_params.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace demcal::calibration {

const analytics::ResponseShapeResult& ParameterSensitivity::response(const std::string& quantity) const {
    if (quantity == "mu_b") return mu_b;
    if (quantity == "tau_c") return tau_c;
    throw std::invalid_argument("quantity '" + quantity + "' is not one of mu_b, tau_c");
}

const ParameterSensitivity* SensitivityStudy::find(const std::string& name) const {
    for (const auto& p : parameters)
        if (p.name == name) return &p;
    return nullptr;
}

namespace {

using analytics::number_text;

// Inside the parameter's admissible range, with open ends kept strictly inside.
bool admissible(const orchestrator::ParamSpec& s, double v) {
    const bool above_min = s.min_exclusive ? v > s.min : v >= s.min;
    const bool below_max = s.max_exclusive ? v < s.max : v <= s.max;
    return std::isfinite(v) && above_min && below_max;
}

// Whether `base` with `name` = v is a valid run material (its range, and the box at least 4 particle lengths).
bool valid_level(const nlohmann::json& base, const std::string& name, double v) {
    nlohmann::json material = base;
    material[name] = v;
    try {
        orchestrator::validate_material(material);
        return true;
    } catch (const std::invalid_argument&) {
        return false;
    }
}

// `end` when valid; else the farthest valid value from the (valid) base towards it, found by bisection, kept 2 % of
// the way inside and rounded as the levels are (6 significant digits), stepping back towards the base while the
// rounded value is invalid (a base at the limit itself).
double farthest_valid(const nlohmann::json& base, const std::string& name, double base_value, double end) {
    if (end == base_value || valid_level(base, name, end) || !valid_level(base, name, base_value)) return end;
    double good = base_value, bad = end;
    for (int i = 0; i < 50; ++i) {
        const double mid = 0.5 * (good + bad);
        (valid_level(base, name, mid) ? good : bad) = mid;
    }
    double inside = base_value + 0.98 * (good - base_value);
    for (int i = 0; i < 60 && !valid_level(base, name, round_significant(inside)); ++i)
        inside = base_value + 0.5 * (inside - base_value);
    return valid_level(base, name, round_significant(inside)) ? round_significant(inside) : base_value;
}

}  // namespace

std::vector<double> sensitivity_levels(const nlohmann::json& base, const std::string& name,
                                       const SensitivityOptions& options) {
    orchestrator::require_micromechanical_param(name, "params");
    if (options.levels < 3)
        throw std::invalid_argument("levels = " + std::to_string(options.levels) + " must be >= 3 to tell a shape");
    if (options.levels > kMaxLevels)
        throw std::invalid_argument("levels = " + std::to_string(options.levels) + " must be at most " +
                                    std::to_string(kMaxLevels) + " (1 % of the span apart)");
    if (!(options.relative_span > 0 && options.relative_span < 1))
        throw std::invalid_argument("span = " + number_text(options.relative_span) + " must be in (0, 1)");
    const auto& spec = *orchestrator::find_shear_param(name);
    const double b = base.at(name).get<double>();
    double lo, hi;
    if (auto it = options.ranges.find(name); it != options.ranges.end()) {
        std::tie(lo, hi) = it->second;
        if (!(lo < hi))
            throw std::invalid_argument("range of " + name + " = " + number_text(lo) + ":" + number_text(hi) +
                                        " must have low < high");
    } else {
        if (b == 0)
            throw std::invalid_argument("range of " + name + ": the base value is 0, so a relative span gives no range; "
                                        "give one with --range " + name + "=LOW:HIGH");
        const double half = std::fabs(b) * options.relative_span;
        lo = b - half;
        hi = b + half;
        // Slide the window into the admissible range (e.g. particle_form >= 1: a sphere base goes 1 .. 1 + 2 span).
        const double margin = 1e-3 * (hi - lo);
        if (!admissible(spec, lo)) {
            const double shift = spec.min + (spec.min_exclusive ? margin : 0) - lo;
            lo += shift, hi += shift;
        }
        if (!admissible(spec, hi)) hi = spec.max - (spec.max_exclusive ? margin : 0);
        // and inside what the rest of the material allows (particle_form and particle_radius against the box size)
        lo = farthest_valid(base, name, b, lo);
        hi = farthest_valid(base, name, b, hi);
        if (!(lo < hi))
            throw std::invalid_argument("range of " + name + ": the material allows no value but its base " +
                                        number_text(b) + " (its box); give one with --range " + name + "=LOW:HIGH");
    }
    if (!admissible(spec, lo) || !admissible(spec, hi))
        throw std::invalid_argument("range of " + name + " = " + number_text(lo) + ":" + number_text(hi) +
                                    " leaves its admissible range " + (spec.min_exclusive ? "(" : "[") +
                                    number_text(spec.min) + ", " + number_text(spec.max) +
                                    (spec.max_exclusive ? ")" : "]") +
                                    (std::string(spec.unit).empty() || std::string(spec.unit) == "-"  // dimensionless
                                         ? std::string()
                                         : " " + std::string(spec.unit)));
    std::vector<double> values;
    for (int i = 0; i < options.levels; ++i)
        values.push_back(round_significant(lo + (hi - lo) * i / (options.levels - 1)));
    // The base value itself, when inside, replaces the nearest level: its runs are shared by every parameter.
    if (b > lo && b < hi) {
        auto nearest = std::min_element(values.begin(), values.end(),
                                        [b](double x, double y) { return std::fabs(x - b) < std::fabs(y - b); });
        if (std::fabs(*nearest - b) < 0.25 * (hi - lo) / (options.levels - 1)) *nearest = b;
    }
    // Rounded to 6 significant digits, levels closer than that are one material: --span 1e-7 ran nine identical
    // lines and failed only at the end ("needs at least 3 distinct levels")
    for (std::size_t k = 1; k < values.size(); ++k)
        if (!(values[k] > values[k - 1]))
            throw std::invalid_argument("range of " + name + " = " + number_text(lo, 12) + ":" + number_text(hi, 12) + ": its " +
                                        std::to_string(options.levels) + " levels are not distinct at 6 significant "
                                        "digits (" + number_text(values[k - 1]) + ", " + number_text(values[k]) +
                                        "): widen it (--span, --range) or give fewer --levels");
    return values;
}

void fit_responses(ParameterSensitivity& p, const analytics::ResponseShapeOptions& shape) {
    std::vector<double> x, mu, se_mu, tau, se_tau;
    for (const auto& l : p.levels) {
        x.push_back(l.value);
        mu.push_back(l.mu_b);
        tau.push_back(l.tau_c);
        // A failure line through collinear points has a zero standard error; keep its weight finite.
        se_mu.push_back(std::max(l.se_mu_b, 1e-9 * std::max(1.0, std::fabs(l.mu_b))));
        se_tau.push_back(std::max(l.se_tau_c, 1e-9 * std::max(1.0, std::fabs(l.tau_c))));
    }
    p.mu_b = analytics::classify_response(x, mu, se_mu, p.base_value, shape);
    p.tau_c = analytics::classify_response(x, tau, se_tau, p.base_value, shape);
}

std::vector<std::pair<std::string, std::vector<std::pair<double, nlohmann::json>>>>
sensitivity_plan(const nlohmann::json& base, const SensitivityOptions& options) {
    if (!(options.shape.alpha > 0 && options.shape.alpha < 1))
        throw std::invalid_argument("alpha = " + number_text(options.shape.alpha) + " must be in (0, 1)");
    std::vector<std::pair<std::string, std::vector<std::pair<double, nlohmann::json>>>> plan;
    for (const auto& name : options.params.empty() ? orchestrator::micromechanical_param_names() : options.params) {
        std::vector<std::pair<double, nlohmann::json>> levels;
        for (double v : sensitivity_levels(base, name, options)) {
            nlohmann::json material = base;
            material[name] = v;
            orchestrator::validate_material(material, "sensitivity level " + name + " = " + number_text(v));
            levels.emplace_back(v, std::move(material));
        }
        plan.emplace_back(name, std::move(levels));
    }
    return plan;
}

SensitivityStudy run_sensitivity_study(const nlohmann::json& base, const FailureLineEvaluator& evaluate,
                                       const SensitivityOptions& options, const SensitivityProgress& progress) {
    SensitivityStudy study;
    study.base_material = base;
    study.options = options;
    if (study.options.params.empty()) study.options.params = orchestrator::micromechanical_param_names();
    for (const auto& [name, levels] : sensitivity_plan(base, study.options)) {  // checked before the first run
        ParameterSensitivity p;
        p.name = name;
        p.base_value = base.at(p.name).get<double>();
        for (const auto& [v, material] : levels) {
            const auto ev = evaluate(material);
            const auto& line = line_of(ev, options.line);
            SensitivityLevel l{v,
                               line.mu_b,
                               line.se_mu_b,
                               macro_half_width(line, "mu_b"),
                               line.tau_c,
                               line.se_tau_c,
                               macro_half_width(line, "tau_c"),
                               ev.simulations_run,
                               ev.simulations_reused,
                               ev.cpu_s};
            study.evaluations++;
            study.simulations_run += ev.simulations_run;
            study.simulations_reused += ev.simulations_reused;
            study.cpu_s += ev.cpu_s;
            p.levels.push_back(l);
            if (progress) progress(p.name, l);
        }
        fit_responses(p, options.shape);
        study.parameters.push_back(std::move(p));
    }
    return study;
}

StudyCampaign StudyCampaign::of(const CampaignSettings& c) {
    StudyCampaign out{orchestrator::to_string(c.engine), c.normal_stresses, "", c.replicates, c.base_seed};
    std::sort(out.normal_stresses.begin(), out.normal_stresses.end());
    if (!c.template_path.empty()) out.template_sha256 = orchestrator::sha256_hex(orchestrator::read_text_file(c.template_path));
    // a --template that is the stock script, byte for byte, is the stock script (probe 62: a study on one was
    // refused for a calibration on the other)
    if (!out.template_sha256.empty()) {
        std::error_code ec;
        const auto stock = orchestrator::default_shear_template();
        if (std::filesystem::is_regular_file(stock, ec) &&
            out.template_sha256 == orchestrator::sha256_hex(orchestrator::read_text_file(stock)))
            out.template_sha256.clear();
    }
    return out;
}

std::string StudyCampaign::difference_from(const StudyCampaign& here) const {
    auto stresses = [](const std::vector<double>& v) {
        std::string t;
        for (double x : v) {
            if (!t.empty()) t += ",";
            t += analytics::number_text(x);
        }
        return t;
    };
    if (engine != here.engine) return "its lines ran on --engine " + engine + ", this calibration on " + here.engine;
    if (normal_stresses != here.normal_stresses)
        return "its lines ran at --normal-stress " + stresses(normal_stresses) + " Pa, this calibration's at " +
               stresses(here.normal_stresses) + " Pa";
    if (template_sha256 != here.template_sha256)
        return std::string("its lines ran on ") +
               (template_sha256.empty() ? "the stock YADE script" : "a --template script of SHA-256 " + template_sha256) +
               ", this calibration on " +
               (here.template_sha256.empty() ? "the stock script" : "a --template of SHA-256 " + here.template_sha256);
    return "";
}

std::string StudyCampaign::packing_difference_from(const StudyCampaign& here) const {
    if (!replicates || !base_seed || !here.replicates || !here.base_seed) return "";
    if (*replicates == *here.replicates && *base_seed == *here.base_seed) return "";
    const auto packings = [](int r, long seed) {
        return std::to_string(r) + " packing(s) per stress from seed " + std::to_string(seed);
    };
    return "its lines sheared " + packings(*replicates, *base_seed) + " (--replicates, --seed), this calibration's " +
           packings(*here.replicates, *here.base_seed);
}

nlohmann::json SensitivityStudy::to_json() const {
    nlohmann::json j = {{"schema", "demcal.sensitivity/1"},
                        {"base_material", base_material},
                        {"levels", options.levels},
                        {"relative_span", options.relative_span},
                        {"line", to_string(options.line)},
                        {"criterion", analytics::to_string(options.shape.criterion)},
                        {"alpha", options.shape.alpha},
                        {"evaluations", evaluations},
                        {"simulations_run", simulations_run},
                        {"simulations_reused", simulations_reused},
                        {"cpu_s", cpu_s},
                        {"parameters", nlohmann::json::array()}};
    if (campaign) {
        j["campaign"] = {{"engine", campaign->engine},
                         {"normal_stresses", campaign->normal_stresses},
                         {"template_sha256", campaign->template_sha256}};
        if (campaign->replicates) j["campaign"]["replicates"] = *campaign->replicates;
        if (campaign->base_seed) j["campaign"]["base_seed"] = *campaign->base_seed;
    }
    for (const auto& p : parameters) {
        nlohmann::json pj = {{"name", p.name}, {"base_value", p.base_value}, {"levels", nlohmann::json::array()}};
        for (const auto& l : p.levels)
            pj["levels"].push_back({{"value", l.value},
                                    {"mu_b", l.mu_b},
                                    {"se_mu_b", l.se_mu_b},
                                    {"mu_b_half_width", l.mu_b_half_width},
                                    {"tau_c", l.tau_c},
                                    {"se_tau_c", l.se_tau_c},
                                    {"tau_c_half_width", l.tau_c_half_width},
                                    {"simulations_run", l.simulations_run},
                                    {"simulations_reused", l.simulations_reused},
                                    {"cpu_s", l.cpu_s}});
        pj["mu_b"] = p.mu_b.to_json();
        pj["tau_c"] = p.tau_c.to_json();
        j["parameters"].push_back(pj);
    }
    return j;
}

namespace {
// The reader of a stored study (SensitivityStudy::from_json): every field's type and range, named by its path in the
// file ("parameters[1].levels[3].se_mu_b"), the value shortened; a library type error named no field.
struct StudyFieldReader {
    [[noreturn]] static void refuse(const std::string& path, const nlohmann::json& v, const std::string& why) {
        throw std::invalid_argument(path + " = " + analytics::json_value_text(v) + ": " + why);
    }
    static const nlohmann::json& at(const nlohmann::json& j, const std::string& key, const std::string& where) {
        if (!j.is_object()) refuse(where.empty() ? "the file" : where, j, "must be a JSON object");
        const auto it = j.find(key);
        if (it == j.end()) throw std::invalid_argument((where.empty() ? "" : where + ".") + key + " is missing");
        return *it;
    }
    static std::string path(const std::string& where, const std::string& key) {
        return where.empty() ? key : where + "." + key;
    }
    static double number(const nlohmann::json& j, const std::string& key, const std::string& where, double lo,
                         double hi, const char* range) {
        const nlohmann::json& v = at(j, key, where);
        if (!v.is_number()) refuse(path(where, key), v, "must be a number");
        const double x = v.get<double>();
        if (!(x >= lo && x <= hi)) refuse(path(where, key), v, std::string("must lie in ") + range);
        return x;
    }
    static double optional_number(const nlohmann::json& j, const std::string& key, const std::string& where) {
        return j.contains(key) ? number(j, key, where, 0, analytics::kLargestPlausibleNumber, "[0, 1e100]") : 0.0;
    }
    // A count: 3 or 3.0 (JSON has one number type; a tool that rewrote the file may print 3.0), not 3.5.
    static long whole_number(const nlohmann::json& j, const std::string& key, const std::string& where, double lo,
                             double hi, const char* range) {
        const double x = number(j, key, where, lo, hi, range);
        if (x != std::floor(x)) refuse(path(where, key), j.at(key), "must be a whole number");
        return static_cast<long>(x);
    }
    static int optional_count(const nlohmann::json& j, const std::string& key, const std::string& where) {
        return j.contains(key) ? static_cast<int>(whole_number(j, key, where, 0, 1e9, "[0, 1e9]")) : 0;
    }
    static std::string text(const nlohmann::json& j, const std::string& key, const std::string& where) {
        const nlohmann::json& v = at(j, key, where);
        if (!v.is_string() || v.get<std::string>().size() > 200) refuse(path(where, key), v, "must be a short text");
        return v.get<std::string>();
    }
    // A key the writer (SensitivityStudy::to_json) never writes is an edit or another file's field: refused by name.
    // A "_" key is a comment, text, as in demcal's other JSON inputs (probe 62: "_comment" was refused).
    static void only_known_keys(const nlohmann::json& j, std::initializer_list<const char*> known,
                                const std::string& where) {
        if (!j.is_object()) return;  // at() refuses it with its path
        for (const auto& [key, value] : j.items()) {
            if (key.rfind('_', 0) == 0) {
                if (!value.is_string()) refuse(path(where, analytics::shortened_text(key)), value, "a comment must be text");
                continue;
            }
            if (std::none_of(known.begin(), known.end(), [&key](const char* k) { return key == k; }))
                refuse(path(where, analytics::shortened_text(key)), value,
                       "unknown key (not written by a sensitivity study)");
        }
    }
    static const nlohmann::json& array(const nlohmann::json& j, const std::string& key, const std::string& where,
                                       std::size_t min_size) {
        const nlohmann::json& v = at(j, key, where);
        if (!v.is_array() || v.size() < min_size)
            refuse(path(where, key), v, "must be an array of at least " + std::to_string(min_size) + " entries");
        return v;
    }
};
}  // namespace

namespace {
using R = StudyFieldReader;
constexpr double big = analytics::kLargestPlausibleNumber;

// The study's own settings and counts (everything but its parameters).
void read_study_settings(const nlohmann::json& j, SensitivityStudy& s) {
    s.base_material = R::at(j, "base_material", "");
    if (!s.base_material.is_object()) R::refuse("base_material", s.base_material, "must be a JSON object");
    s.options.levels = static_cast<int>(R::whole_number(j, "levels", "", 3, kMaxLevels, "[3, 101]"));
    s.options.relative_span = R::number(j, "relative_span", "", 1e-6, 0.999, "(0, 1)");
    s.options.line = line_kind_from_string(R::text(j, "line", ""));
    s.options.shape.criterion = analytics::shape_criterion_from_string(R::text(j, "criterion", ""));
    s.options.shape.alpha = R::number(j, "alpha", "", 1e-6, 0.5, "[1e-6, 0.5]");
    s.evaluations = R::optional_count(j, "evaluations", "");
    s.simulations_run = R::optional_count(j, "simulations_run", "");
    s.simulations_reused = R::optional_count(j, "simulations_reused", "");
    s.cpu_s = R::optional_number(j, "cpu_s", "");
}

// The campaign the study ran on (its "campaign" object).
StudyCampaign read_study_campaign(const nlohmann::json& c) {
    R::only_known_keys(c, {"engine", "normal_stresses", "template_sha256", "replicates", "base_seed"}, "campaign");
    StudyCampaign out;
    out.engine = R::text(c, "engine", "campaign");
    if (out.engine != "yade" && out.engine != "kernel")
        R::refuse("campaign.engine", c.at("engine"), "must be yade or kernel");
    const nlohmann::json& stresses = R::array(c, "normal_stresses", "campaign", 1);
    for (std::size_t i = 0; i < stresses.size(); ++i) {
        const std::string where = "campaign.normal_stresses[" + std::to_string(i) + "]";
        if (!stresses[i].is_number()) R::refuse(where, stresses[i], "must be a number");
        const double x = stresses[i].get<double>();
        if (!(x > 0 && x <= big)) R::refuse(where, stresses[i], "must lie in (0, 1e100] Pa");
        out.normal_stresses.push_back(x);
    }
    std::sort(out.normal_stresses.begin(), out.normal_stresses.end());
    out.template_sha256 = R::text(c, "template_sha256", "campaign");
    // (absent in a study written before stop 62)
    if (c.contains("replicates")) {
        const std::string range = "[1, " + std::to_string(orchestrator::kMaxReplicates) + "]";
        out.replicates = static_cast<int>(
            R::whole_number(c, "replicates", "campaign", 1, orchestrator::kMaxReplicates, range.c_str()));
    }
    if (c.contains("base_seed"))
        out.base_seed = R::whole_number(c, "base_seed", "campaign", 0, 2147483647.0, "[0, 2147483647]");
    return out;
}

// One level's failure line; `lw` names it in a refusal.
SensitivityLevel read_study_level(const nlohmann::json& lj, const std::string& lw) {
    R::only_known_keys(lj,
                       {"value", "mu_b", "se_mu_b", "mu_b_half_width", "tau_c", "se_tau_c", "tau_c_half_width",
                        "simulations_run", "simulations_reused", "cpu_s"},
                       lw);
    // a braced list is evaluated left to right: the fields are checked in this order. A line's mu_b and tau_c are a
    // shear box's (|mu_b| up to tan 89.4 deg, |tau_c| up to the largest Young modulus a material may have): an edited
    // tau_c of 1e50 Pa was read and the calibration told the study's ranges were too narrow (probe 63)
    return {R::number(lj, "value", lw, -big, big, "[-1e100, 1e100]"),
            R::number(lj, "mu_b", lw, -100, 100, "[-100, 100]"),
            R::number(lj, "se_mu_b", lw, 0, big, "[0, 1e100]"),
            R::optional_number(lj, "mu_b_half_width", lw),
            R::number(lj, "tau_c", lw, -1e12, 1e12, "[-1e12, 1e12] Pa"),
            R::number(lj, "se_tau_c", lw, 0, big, "[0, 1e100]"),
            R::optional_number(lj, "tau_c_half_width", lw),
            R::optional_count(lj, "simulations_run", lw),
            R::optional_count(lj, "simulations_reused", lw),
            R::optional_number(lj, "cpu_s", lw)};
}

// The parameter's name: a micromechanical one, not named before in the study.
std::string read_parameter_name(const nlohmann::json& pj, const std::string& where, const SensitivityStudy& s) {
    std::string name = R::text(pj, "name", where);
    const auto known = orchestrator::micromechanical_param_names();
    if (std::find(known.begin(), known.end(), name) == known.end())
        R::refuse(where + ".name", pj.at("name"), "not a micromechanical parameter of the shear box");
    if (std::find(s.options.params.begin(), s.options.params.end(), name) != s.options.params.end())
        R::refuse(where + ".name", pj.at("name"), "named by an earlier parameter too");
    return name;
}

// The base material is the centre of every parameter's levels: an edited one no longer matches the runs.
void check_base_value(const SensitivityStudy& s, const ParameterSensitivity& p, const std::string& where) {
    const auto base = s.base_material.find(p.name);
    if (base == s.base_material.end() || !base->is_number() || base->get<double>() != p.base_value)
        throw std::invalid_argument("base_material." + p.name + " = " +
                                    (base == s.base_material.end() ? std::string("<missing>")
                                                                   : analytics::json_value_text(*base)) +
                                    ": differs from " + where + ".base_value = " +
                                    analytics::number_text(p.base_value) + " (the value the study varied around)");
}

// One varied parameter: its name, base value and levels (as many as the study's, ascending), its responses fitted.
ParameterSensitivity read_study_parameter(const nlohmann::json& pj, const std::string& where, SensitivityStudy& s) {
    R::only_known_keys(pj, {"name", "base_value", "levels", "mu_b", "tau_c"}, where);
    ParameterSensitivity p;
    p.name = read_parameter_name(pj, where, s);
    p.base_value = R::number(pj, "base_value", where, -big, big, "[-1e100, 1e100]");
    check_base_value(s, p, where);
    s.options.params.push_back(p.name);
    const nlohmann::json& levels = R::array(pj, "levels", where, 3);
    if (levels.size() != static_cast<std::size_t>(s.options.levels))
        throw std::invalid_argument(where + ".levels has " + std::to_string(levels.size()) +
                                    " entries, the study's levels = " + std::to_string(s.options.levels) +
                                    ": every parameter is run at the same number of levels");
    for (std::size_t k = 0; k < levels.size(); ++k) {
        const std::string lw = where + ".levels[" + std::to_string(k) + "]";
        p.levels.push_back(read_study_level(levels[k], lw));
        // the material the level ran: within the field's own limits (a friction level of 1e99 was read, probe 63)
        nlohmann::json level_material = s.base_material;
        level_material[p.name] = p.levels[k].value;
        orchestrator::validate_material(level_material, lw + " (base_material with " + p.name + " = its value)");
        if (k > 0 && !(p.levels[k].value > p.levels[k - 1].value))
            R::refuse(lw + ".value", levels[k].at("value"),
                      "not above the level before it (" + analytics::number_text(p.levels[k - 1].value) +
                          "): a study's levels ascend");
    }
    fit_responses(p, s.options.shape);
    return p;
}
}  // namespace

SensitivityStudy SensitivityStudy::from_json(const nlohmann::json& j) {
    if (!j.is_object() || !j.contains("schema") || j["schema"] != "demcal.sensitivity/1")
        throw std::invalid_argument("schema = " +
                                    (j.is_object() && j.contains("schema") ? analytics::json_value_text(j["schema"])
                                                                           : std::string("<missing>")) +
                                    " is not demcal.sensitivity/1");
    R::only_known_keys(j,
                       {"schema", "base_material", "levels", "relative_span", "line", "criterion", "alpha",
                        "evaluations", "simulations_run", "simulations_reused", "cpu_s", "parameters", "campaign"},
                       "");
    SensitivityStudy s;
    read_study_settings(j, s);
    if (j.contains("campaign")) s.campaign = read_study_campaign(R::at(j, "campaign", ""));
    const nlohmann::json& parameters = R::array(j, "parameters", "", 1);
    for (std::size_t i = 0; i < parameters.size(); ++i)
        s.parameters.push_back(read_study_parameter(parameters[i], "parameters[" + std::to_string(i) + "]", s));
    return s;
}

namespace {
// "linear (+1.2e-3 /unit, p = 0.001)" style cell of the table.
std::string shape_cell(const analytics::ResponseShapeResult& r) {
    std::ostringstream o;
    o << std::setprecision(3);
    o << analytics::to_string(r.shape);
    const auto& f = r.selected();
    if (f.degree >= 1)
        o << " slope " << f.coefficients[1].value << " (p=" << std::setprecision(2) << f.coefficients[1].p_value << ")"
          << std::setprecision(3);
    if (f.degree >= 2)
        o << " curv " << f.coefficients[2].value << " (p=" << std::setprecision(2) << f.coefficients[2].p_value << ")";
    if (f.degree == 0) {
        const auto& t = r.linear_vs_constant;
        o << " (slope p=" << std::setprecision(2) << t.p_value << ")";
    }
    return o.str();
}
}  // namespace

std::string SensitivityStudy::table() const {
    std::ostringstream o;
    o << "Sensitivity of the " << to_string(options.line) << " failure line (" << analytics::to_string(options.shape.criterion)
      << ", alpha " << options.shape.alpha << "; slopes per unit of the parameter at its base value)\n";
    o << std::left << std::setw(22) << "parameter" << std::setw(26) << "range" << std::setw(52) << "change of cohesion tau_c [Pa]"
      << "change of internal friction mu_b [-]\n";
    for (const auto& p : parameters) {
        std::ostringstream range;
        range << std::setprecision(4) << p.low() << " .. " << p.high();
        o << std::left << std::setw(22) << p.name << std::setw(26) << range.str() << std::setw(52) << shape_cell(p.tau_c)
          << shape_cell(p.mu_b) << "\n";
    }
    return o.str();
}

}  // namespace demcal::calibration
