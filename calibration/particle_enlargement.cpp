#include "calibration/particle_enlargement.hpp"

#include "analytics/number_text.hpp"
#include "orchestrator/shear_params.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace demcal::calibration {

namespace {

using analytics::number_text;

std::string num(double v) { return number_text(v, 4); }

// What poisson_ratio is in YADE's linear laws, the engine's only reading so far (the long form: poisson_meaning()).
constexpr const char* kPoissonLabel = "nu = ks/kn";

double mean(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? NAN : s / v.size();
}

double sample_sd(const std::vector<double>& v) {
    if (v.size() < 2) return 0;
    const double m = mean(v);
    double s = 0;
    for (double x : v) s += (x - m) * (x - m);
    return std::sqrt(s / (v.size() - 1));
}

// The one meaning of poisson_ratio, from the parameter table (YADE's linear laws: ks/kn).
std::string poisson_meaning() { return orchestrator::find_shear_param("poisson_ratio")->meaning; }

SensitivityOptions study_options(const EnlargementOptions& o) {
    SensitivityOptions s = o.study;
    s.params = enlargement_controls();
    s.line = o.line;
    return s;
}

// Search bounds at one radius: the studied range of each control, or the --bounds override.
std::vector<ControlParameter> controls_at(const nlohmann::json& material, const EnlargementOptions& o) {
    std::vector<ControlParameter> controls;
    for (const auto& name : enlargement_controls()) {
        ControlParameter c{name, 0, 0};
        if (auto b = o.bounds.find(name); b != o.bounds.end()) {
            std::tie(c.low, c.high) = b->second;
        } else {
            const auto levels = sensitivity_levels(material, name, study_options(o));
            c.low = levels.front();
            c.high = levels.back();
        }
        controls.push_back(c);
    }
    return controls;
}

void check_radii(const std::vector<double>& radii) {
    if (radii.size() < 3)
        throw std::invalid_argument("radii: " + std::to_string(radii.size()) +
                                    " given, need at least 3 (a law of 2 constants with an interval needs 1 degree of "
                                    "freedom)");
    for (std::size_t i = 0; i < radii.size(); ++i) {
        if (!(radii[i] > 0) || !std::isfinite(radii[i]))
            throw std::invalid_argument("radii: radius " + std::to_string(i + 1) + " = " + num(radii[i]) +
                                        " m must be a positive number");
        if (i > 0 && !(radii[i] > radii[i - 1]))
            throw std::invalid_argument("radii: radius " + std::to_string(i + 1) + " = " + num(radii[i]) +
                                        " m after " + num(radii[i - 1]) +
                                        " m; the radii must increase (the first is the reference)");
    }
    analytics::check_radius_spacing(radii, "radii");
}

// Every evaluation of the study goes through here: counts, and CPU of each distinct failure line once.
class CountingEvaluator {
public:
    CountingEvaluator(const FailureLineEvaluator& evaluate, EnlargementStudy& study)
        : evaluate_(evaluate), study_(study) {}
    FailureLineEvaluation operator()(const nlohmann::json& material) {
        auto ev = evaluate_(material);
        ++study_.evaluations;
        study_.simulations_run += ev.simulations_run;
        study_.simulations_reused += ev.simulations_reused;
        if (counted_.insert(material.dump()).second) {
            study_.cpu_s += ev.cpu_s;
            study_.simulations_failed += ev.simulations_failed;
            study_.replacement_rounds += ev.replacement_rounds;
        }
        return ev;
    }
    FailureLineEvaluator as_function() {
        return [this](const nlohmann::json& m) { return (*this)(m); };
    }

private:
    const FailureLineEvaluator& evaluate_;
    EnlargementStudy& study_;
    std::set<std::string> counted_;
};

void say(const EnlargementProgress& progress, const std::string& line) {
    if (progress) progress(line);
}

std::string line_text(const analytics::FailureLine& l) {
    std::ostringstream o;
    o.precision(4);
    o << "mu_b " << l.mu_b << " +/- " << l.se_mu_b << ", tau_c " << l.tau_c << " +/- " << l.se_tau_c << " Pa (+/- 1 SE)";
    return o.str();
}

RadiusBase evaluate_base(const nlohmann::json& base, double r, const FailureLineEvaluator& evaluate, LineKind kind) {
    RadiusBase b;
    b.radius = r;
    const auto material = material_at_radius(base, r);
    b.box = box_ratio(material);
    const auto ev = evaluate(material);
    b.line = line_of(ev, kind);
    b.cost = run_cost(ev);
    return b;
}

// Point uncertainties for a weighted fit, or none when one of them is not usable (an exact line has SE 0).
std::vector<double> usable_sigmas(const std::vector<double>& se) {
    for (double s : se)
        if (!(s > 0) || !std::isfinite(s)) return {};
    return se;
}

// cost(r) = C r^-D; a fit that fails or is not determined is listed in the study's problems.
std::optional<analytics::ScalingLawFit> fit_cost_law(const std::string& name, const std::vector<double>& r,
                                                     const std::vector<double>& cost, EnlargementStudy& s) {
    try {
        // Costs scatter in proportion to themselves (timings on a shared machine): each point weighs 1 / y^2.
        auto law = analytics::fit_power_law(r, cost, cost, s.options.confidence);
        if (!law.determined()) s.problems.push_back(name + " = C r^-D: " + law.undetermined);
        return law;
    } catch (const std::invalid_argument& e) {
        s.problems.push_back(name + " = C r^-D not fitted: " + e.what());
        return std::nullopt;
    }
}

// mu_b(r) and tau_c(r) of the base parameters, weighted by their lines' standard errors.
void fit_trends(EnlargementStudy& s) {
    std::vector<double> radii, mu, se_mu, tau, se_tau;
    for (const auto& b : s.bases) {
        radii.push_back(b.radius);
        mu.push_back(b.line.mu_b), se_mu.push_back(b.line.se_mu_b);
        tau.push_back(b.line.tau_c), se_tau.push_back(b.line.se_tau_c);
    }
    s.mu_b_trend = analytics::classify_response(radii, mu, usable_sigmas(se_mu), radii.front(), s.options.trend);
    s.tau_c_trend = analytics::classify_response(radii, tau, usable_sigmas(se_tau), radii.front(), s.options.trend);
}

// CPU time and work (particles x steps) per run against r, over the radii that measured them.
void fit_costs(EnlargementStudy& s) {
    std::vector<double> r_cpu, cpu, r_work, work;
    for (const auto& b : s.bases) {
        if (b.cost.runs > 0 && b.cost.cpu_s > 0) r_cpu.push_back(b.radius), cpu.push_back(b.cost.cpu_s);
        if (b.cost.particle_steps > 0) r_work.push_back(b.radius), work.push_back(b.cost.particle_steps);
    }
    s.cpu_law = fit_cost_law("CPU per run", r_cpu, cpu, s);
    s.work_law = fit_cost_law("particle-steps per run", r_work, work, s);
}

std::vector<MacroTarget> reference_targets(const analytics::FailureLine& reference, bool point_targets) {
    std::vector<MacroTarget> targets;
    // The reference is itself a simulated line: a difference inside its own interval cannot be resolved, so by
    // default that interval widens the acceptance (as for a measured line).
    for (const auto& q : macro_quantities())
        targets.push_back({q, macro_value(reference, q),
                           point_targets ? std::nullopt : std::optional<double>(macro_half_width(reference, q))});
    return targets;
}

// Why the reference line cannot serve as the calibrations' target ("" when it can): a slope that is no bulk friction,
// or (when its interval widens the acceptance) an interval on mu_b that holds 0, which every line falls inside: each
// radius was then "converged" at its start, and E(r) fitted through calibrations that never moved (probe 59).
std::string reference_cannot_be_a_target(const analytics::FailureLine& reference, const EnlargementOptions& o) {
    const double mu = macro_value(reference, "mu_b"), half = macro_half_width(reference, "mu_b");
    if (!(mu > 0)) return "mu_b = " + num(mu) + " is no bulk friction (noise at this box and these stresses)";
    if (!o.point_targets && !(half < mu))
        return "mu_b = " + num(mu) + " +/- " + num(half) + " (95 %): an interval that holds 0 accepts every line, so "
               "no calibration to it means anything; add --replicates or normal stresses (or a larger box), or pass "
               "--point-targets to aim at its values within --tol";
    return "";
}

// A calibration accepted by an interval (the reference's or its own simulated one) rather than within the tolerance
// of the reference's values: says how far off it is ("" when within the tolerance, or not converged).
std::string accepted_off_tolerance(const RadiusCalibration& c, const std::vector<MacroTarget>& targets) {
    if (!c.converged() || c.result.best < 0) return "";
    const auto& it = c.result.iterations[static_cast<std::size_t>(c.result.best)];
    if (it.accepted_by == "tolerance") return "";
    std::ostringstream o;
    o.precision(3);
    o << "accepted within the " << it.accepted_by << ", not the tolerance:";
    for (const auto& t : targets) {
        const double v = t.quantity == "mu_b" ? it.mu_b : it.tau_c;
        o << " " << t.quantity << " " << v << " against " << t.value;
        if (t.value != 0) o << " (" << 100 * (v - t.value) / std::fabs(t.value) << " %)";
    }
    o << "; add --replicates or normal stresses, or pass --strict --point-targets";
    return o.str();
}

// Whether the base material at this radius already restores the reference line: the loop's own acceptance rule on a
// budget of one evaluation (the start, already run in step 1).
CalibrationResult start_if_accepted(const nlohmann::json& material, const std::vector<MacroTarget>& targets,
                                    const std::vector<ControlParameter>& controls, const FailureLineEvaluator& evaluate,
                                    CalibrationOptions search) {
    search.method = SearchMethod::coordinate;
    search.max_evaluations = 1;
    return calibrate(material, targets, controls, nullptr, evaluate, search);
}

RadiusCalibration calibrate_radius(const nlohmann::json& base, double r, const std::vector<MacroTarget>& targets,
                                   const FailureLineEvaluator& evaluate, const EnlargementOptions& o,
                                   const EnlargementProgress& progress) {
    RadiusCalibration c;
    c.radius = r;
    const auto material = material_at_radius(base, r);
    const auto controls = controls_at(material, o);
    CalibrationOptions search = o.calibration;
    search.tolerance = o.tolerance;  // one tolerance for the search and the verification
    search.line = o.line;
    auto report = [&](const CalibrationIteration& it) {
        std::ostringstream line;
        line.precision(4);
        line << "    #" << it.evaluation << " E " << it.values.at("young_modulus") << " Pa, nu "
             << it.values.at("poisson_ratio") << ": mu_b " << it.mu_b << ", tau_c " << it.tau_c << " Pa"
             << (it.accepted ? " accepted (" + it.accepted_by + ")" : "");
        say(progress, line.str());
    };
    c.result = start_if_accepted(material, targets, controls, evaluate, search);
    if (c.result.status == CalibrationStatus::converged) {
        // nothing to calibrate: the study of E and nu would cost its runs for no search
        c.result.method = search.method;
        c.result.iterations.front().phase = "start";
        report(c.result.iterations.front());
    } else {
        c.study = run_sensitivity_study(material, evaluate, study_options(o),
                                        [&](const std::string& param, const SensitivityLevel& l) {
                                            std::ostringstream line;
                                            line.precision(4);
                                            line << "    study " << param << " = " << l.value << ": mu_b " << l.mu_b
                                                 << ", tau_c " << l.tau_c << " Pa";
                                            say(progress, line.str());
                                        });
        c.result = calibrate(material, targets, controls, &c.study, evaluate, search, report);
    }
    c.young_modulus = c.result.material.at("young_modulus").get<double>();
    c.poisson_ratio = c.result.material.at("poisson_ratio").get<double>();
    return c;
}

void fit_laws(EnlargementStudy& s) {
    // The reference radius keeps the base material by definition: it is the first point of both laws.
    auto& r = s.law_radii;
    auto& e = s.law_young_moduli;
    auto& nu = s.law_poisson_ratios;
    r = {s.bases.front().radius};
    e = {s.base_material.at("young_modulus").get<double>()};
    nu = {s.base_material.at("poisson_ratio").get<double>()};
    for (const auto& c : s.calibrations) {
        if (!c.converged()) {
            s.problems.push_back("calibration at r = " + num(c.radius) + " m " + to_string(c.result.status) + ": " +
                                 c.result.message);
            if (!s.options.fit_unconverged) continue;
        }
        r.push_back(c.radius), e.push_back(c.young_modulus), nu.push_back(c.poisson_ratio);
    }
    if (r.size() < 3) {
        s.problems.push_back("E(r) and nu(r) not fitted: " + std::to_string(r.size()) +
                             " radii with a calibrated material (the reference included), 3 needed");
        return;
    }
    s.young_law = analytics::fit_linear_law(r, e, {}, s.options.confidence);
    if (!s.young_law->determined()) s.problems.push_back("E(r) = A r + B: " + s.young_law->undetermined);
    s.poisson_law = analytics::fit_power_law(r, nu, {}, s.options.confidence);
    if (!s.poisson_law->determined()) s.problems.push_back("nu(r) = C r^-D: " + s.poisson_law->undetermined);
}

RadiusVerification verify_radius(const EnlargementStudy& s, double r, const FailureLineEvaluator& evaluate) {
    RadiusVerification v;
    v.radius = r;
    v.young_modulus = round_significant((*s.young_law)(r));
    v.poisson_ratio = round_significant((*s.poisson_law)(r));
    nlohmann::json material = s.base_material;
    material["particle_radius"] = r;
    material["young_modulus"] = v.young_modulus;
    material["poisson_ratio"] = v.poisson_ratio;
    try {
        material = orchestrator::validate_material(material, "laws at r = " + num(r) + " m");
    } catch (const std::invalid_argument& e) {  // e.g. nu beyond 0.5 or E below 0: a finding, not bad input
        v.not_run_because = e.what();
        return v;
    }
    v.box = box_ratio(material);
    const auto ev = evaluate(material);
    v.line = line_of(ev, s.options.line);
    v.cost = run_cost(ev);
    const auto& ref = s.bases.front();
    v.mu_b_deviation = (v.line.mu_b - ref.line.mu_b) / std::fabs(ref.line.mu_b);
    v.tau_c_deviation = (v.line.tau_c - ref.line.tau_c) / std::fabs(ref.line.tau_c);
    v.within_tolerance = std::fabs(v.mu_b_deviation) <= s.options.tolerance &&
                         std::fabs(v.tau_c_deviation) <= s.options.tolerance;
    if (ref.cost.cpu_s > 0 && v.cost.runs > 0) v.cost_saved = 1 - v.cost.cpu_s / ref.cost.cpu_s;
    return v;
}

nlohmann::json optional_json(const auto& fit) { return fit ? fit->to_json() : nlohmann::json(nullptr); }

nlohmann::json line_json(const analytics::FailureLine& l) {
    return {{"mu_b", l.mu_b},           {"se_mu_b", l.se_mu_b},     {"mu_b_low", l.mu_b_low},
            {"mu_b_high", l.mu_b_high}, {"tau_c", l.tau_c},         {"se_tau_c", l.se_tau_c},
            {"tau_c_low", l.tau_c_low}, {"tau_c_high", l.tau_c_high}, {"r_squared", l.r_squared}, {"n", l.n}};
}

// The laws in the seed's units (E in MPa, r in mm), to compare with eqs. 3.1-3.2 (A = 91.52, B = 148.86;
// C = 0.2344, D = 1.282).
nlohmann::json seed_units(const std::optional<analytics::ScalingLawFit>& young,
                          const std::optional<analytics::ScalingLawFit>& poisson) {
    nlohmann::json j = nlohmann::json::object();
    if (young) j["A_MPa_per_mm"] = young->params[0].value * 1e-9, j["B_MPa"] = young->params[1].value * 1e-6;
    if (poisson) {
        const double d = poisson->params[1].value;  // C_mm = C_m (1e-3)^-D
        j["C_mm"] = poisson->params[0].value * std::pow(1e-3, -d), j["D"] = d;
    }
    return j;
}

}  // namespace

std::string BoxRatio::warning() const {
    if (adequate()) return {};
    std::ostringstream o;
    o.precision(3);
    o << "the box is";
    if (across < min_across)
        o << " " << across << " particle lengths across (ASTM D3080: at least " << min_across << ")";
    if (across < min_across && height < min_height) o << " and";
    if (height < min_height) o << " " << height << " high (ASTM D3080: at least " << min_height << ")";
    o << "; the failure line may measure the box (the seed's cohesion drift at 5 and 7 mm)";
    return o.str();
}

nlohmann::json BoxRatio::to_json() const {
    return {{"across", across}, {"height", height}, {"min_across", min_across}, {"min_height", min_height},
            {"adequate", adequate()}};
}

BoxRatio box_ratio(const nlohmann::json& m) {
    const double len = orchestrator::max_particle_length(m);
    BoxRatio b;
    b.across = std::min(m.at("box_length").get<double>(), m.at("box_width").get<double>()) / len;
    b.height = m.at("box_height").get<double>() / len;
    return b;
}

nlohmann::json RunCost::to_json() const {
    return {{"runs", runs},           {"cpu_s_per_run", cpu_s}, {"cpu_s_sd", cpu_sd},
            {"wall_s_per_run", wall_s}, {"particles", particles}, {"steps", steps},
            {"timestep_s", timestep_s}, {"particle_steps", particle_steps}};
}

RunCost run_cost(const FailureLineEvaluation& ev) {
    std::vector<double> cpu, wall, particles, steps, dt, work;
    for (const auto& r : ev.outcome.runs) {
        if (r.state != orchestrator::RunState::done) continue;
        if (r.cpu_s > 0) cpu.push_back(r.cpu_s), wall.push_back(r.wall_s);
        particles.push_back(r.result.value("particle_count", NAN));
        steps.push_back(r.result.value("steps", NAN));
        dt.push_back(r.result.value("timestep", NAN));
        work.push_back(particles.back() * steps.back());
    }
    RunCost c;
    c.runs = static_cast<int>(cpu.size());
    c.cpu_s = mean(cpu), c.cpu_sd = sample_sd(cpu), c.wall_s = mean(wall);
    c.particles = mean(particles), c.steps = mean(steps), c.timestep_s = mean(dt), c.particle_steps = mean(work);
    return c;
}

const std::vector<std::string>& enlargement_controls() {
    static const std::vector<std::string> names{"young_modulus", "poisson_ratio"};
    return names;
}

nlohmann::json material_at_radius(const nlohmann::json& base, double radius) {
    nlohmann::json m = base;
    m["particle_radius"] = radius;
    return orchestrator::validate_material(m, "radii = " + num(radius) + " m");
}

void check_enlargement(const nlohmann::json& base, const EnlargementOptions& o) {
    check_radii(o.radii);
    if (!(o.tolerance > 0 && o.tolerance < 1))
        throw std::invalid_argument("tol = " + num(o.tolerance) + " must be in (0, 1) (a relative distance)");
    if (!(o.confidence > 0 && o.confidence < 1))
        throw std::invalid_argument("confidence = " + num(o.confidence) + " must be in (0, 1)");
    if (!(o.trend.alpha > 0 && o.trend.alpha < 1))
        throw std::invalid_argument("alpha = " + num(o.trend.alpha) + " must be in (0, 1)");
    check_calibration_options(o.calibration);
    const auto is_control = [](const std::string& name) {
        const auto& c = enlargement_controls();
        return std::find(c.begin(), c.end(), name) != c.end();
    };
    for (const auto& [option, ranges] : {std::pair{"bounds", &o.bounds}, std::pair{"range", &o.study.ranges}})
        for (const auto& [name, range] : *ranges)
            if (!is_control(name))  // a range of another parameter would be ignored without a word
                throw std::invalid_argument(std::string(option) + ": '" + name +
                                            "' is not a control of the study (young_modulus, poisson_ratio)");
    for (double r : o.radii) {
        const auto material = material_at_radius(base, r);
        if (r == o.radii.front()) continue;  // the reference is not calibrated
        sensitivity_plan(material, study_options(o));
        for (const auto& c : controls_at(material, o)) check_control(material, c);
    }
}

double planned_failure_lines(const EnlargementOptions& o) {
    const double n = static_cast<double>(o.radii.size());
    const double study = static_cast<double>(enlargement_controls().size()) * o.study.levels;
    // base lines + per calibrated radius (study + search budget) + the verification at every radius
    return n + (n - 1) * (study + static_cast<double>(o.calibration.max_evaluations)) + n;
}

EnlargementStudy run_enlargement_study(const nlohmann::json& base_in, const FailureLineEvaluator& evaluate_in,
                                       const EnlargementOptions& options, const EnlargementProgress& progress) {
    const nlohmann::json base = orchestrator::validate_material(base_in, "base");
    check_enlargement(base, options);
    EnlargementStudy s;
    s.base_material = base;
    s.options = options;
    CountingEvaluator counting(evaluate_in, s);
    const FailureLineEvaluator evaluate = counting.as_function();

    say(progress, "1. base parameters at " + std::to_string(options.radii.size()) + " radii");
    for (double r : options.radii) {
        s.bases.push_back(evaluate_base(base, r, evaluate, options.line));
        const auto& b = s.bases.back();
        std::ostringstream line;
        line.precision(4);
        line << "  r = " << r << " m: " << line_text(b.line) << "; " << b.cost.particles << " particles, CPU "
             << b.cost.cpu_s << " s per run";
        say(progress, line.str());
        if (!b.box.adequate()) s.warnings.push_back("r = " + num(r) + " m: " + b.box.warning());
    }
    fit_trends(s);
    fit_costs(s);

    if (const std::string why = reference_cannot_be_a_target(s.bases.front().line, options); !why.empty()) {
        s.problems.push_back("r = " + num(options.radii.front()) + " m (the reference): " + why +
                             "; the study stops before the calibrations (step 2)");
        return s;
    }
    const auto targets = reference_targets(s.bases.front().line, options.point_targets);
    say(progress, "2. calibration of young_modulus and poisson_ratio to the reference line (" +
                      line_text(s.bases.front().line) + ")");
    for (std::size_t i = 1; i < options.radii.size(); ++i) {
        say(progress, "  r = " + num(options.radii[i]) + " m:");
        s.calibrations.push_back(calibrate_radius(base, options.radii[i], targets, evaluate, options, progress));
        if (const std::string w = accepted_off_tolerance(s.calibrations.back(), targets); !w.empty())
            s.warnings.push_back("r = " + num(options.radii[i]) + " m: " + w);
    }
    fit_laws(s);
    if (!s.young_law || !s.poisson_law) return s;

    say(progress, "3. verification: the laws' materials at every radius");
    for (double r : options.radii) {
        s.verifications.push_back(verify_radius(s, r, evaluate));
        const auto& v = s.verifications.back();
        std::ostringstream line;
        line.precision(3);
        if (v.not_run_because.empty())
            line << "  r = " << r << " m: " << line_text(v.line) << " (" << 100 * v.mu_b_deviation << " %, "
                 << 100 * v.tau_c_deviation << " % from the reference), cost saved " << 100 * v.cost_saved << " %";
        else
            line << "  r = " << r << " m: not run: " << v.not_run_because;
        say(progress, line.str());
    }
    return s;
}

nlohmann::json EnlargementStudy::to_json() const {
    nlohmann::json radii = nlohmann::json::array();
    for (std::size_t i = 0; i < bases.size(); ++i) {
        const auto& b = bases[i];
        nlohmann::json j = {{"radius", b.radius},
                            {"reference", i == 0},
                            {"box_ratio", b.box.to_json()},
                            {"base_line", line_json(b.line)},
                            {"cost", b.cost.to_json()}};
        if (i > 0 && i - 1 < calibrations.size()) {
            const auto& c = calibrations[i - 1];
            j["calibration"] = {{"status", to_string(c.result.status)},
                                {"message", c.result.message},
                                {"young_modulus", c.young_modulus},
                                {"poisson_ratio", c.poisson_ratio},
                                {"evaluations", c.result.evaluations},
                                {"best", c.result.iterations.at(c.result.best).to_json()},
                                {"study", c.study.parameters.empty() ? nlohmann::json(nullptr) : c.study.to_json()}};
        }
        for (const auto& v : verifications)
            if (v.radius == b.radius) {
                j["verification"] = {{"young_modulus", v.young_modulus}, {"poisson_ratio", v.poisson_ratio}};
                if (!v.not_run_because.empty()) {
                    j["verification"]["not_run_because"] = v.not_run_because;
                    continue;
                }
                const auto& ref = bases.front().line;
                j["verification"].update({{"line", line_json(v.line)},
                                          {"cost", v.cost.to_json()},
                                          {"box_ratio", v.box.to_json()},
                                          {"mu_b_deviation", v.mu_b_deviation},
                                          {"tau_c_deviation", v.tau_c_deviation},
                                          {"within_tolerance", v.within_tolerance},
                                          {"mu_b_in_reference_interval",
                                           ref.mu_b_low <= v.line.mu_b && v.line.mu_b <= ref.mu_b_high},
                                          {"tau_c_in_reference_interval",
                                           ref.tau_c_low <= v.line.tau_c && v.line.tau_c <= ref.tau_c_high},
                                          {"cost_saved", v.cost_saved}});
            }
        radii.push_back(j);
    }
    nlohmann::json cost = {{"law", optional_json(cpu_law)},
                           {"quantity", "CPU seconds per run"},
                           {"work_law", optional_json(work_law)},
                           {"work_quantity", "particles x steps per run (machine-independent; no start-up)"}};
    if (cpu_law) {  // the seed's claim: doubling the radius saved 94.9 % (cost ratio 2^-D)
        const auto& d = cpu_law->params[1];
        cost["saved_by_doubling"] = {{"value", 1 - std::pow(2.0, -d.value)},
                                     {"low", 1 - std::pow(2.0, -d.low)},
                                     {"high", 1 - std::pow(2.0, -d.high)}};
    }
    return {{"base_material", base_material},
            {"radii_m", options.radii},
            {"line", to_string(options.line)},
            {"tolerance", options.tolerance},
            {"confidence", options.confidence},
            {"poisson_ratio_meaning", poisson_meaning()},
            {"per_radius", radii},
            {"cost", cost},
            {"mu_b_trend", optional_json(mu_b_trend)},
            {"tau_c_trend", optional_json(tau_c_trend)},
            {"law_points", {{"radius", law_radii}, {"young_modulus", law_young_moduli},
                            {"poisson_ratio", law_poisson_ratios}}},
            {"young_modulus_law", optional_json(young_law)},
            {"poisson_ratio_law", optional_json(poisson_law)},
            {"laws_in_seed_units", seed_units(young_law, poisson_law)},
            {"problems", problems},
            {"warnings", warnings},
            {"evaluations", evaluations},
            {"simulations_run", simulations_run},
            {"simulations_reused", simulations_reused},
            {"simulations_failed", simulations_failed},
            {"replacement_rounds", replacement_rounds},
            {"cpu_s", cpu_s}};
}

namespace {
std::string law_row(const std::string& name, const std::optional<analytics::ScalingLawFit>& fit) {
    if (!fit) return "| " + name + " | not fitted | | |\n";
    std::ostringstream o;
    o.precision(4);
    o << "| " << name << " | ";
    for (const auto& p : fit->params)
        o << p.name << " = " << p.value << " +/- " << p.std_error << " [" << p.low << ", " << p.high << "]; ";
    o << "| " << fit->r_squared << " | " << (fit->determined() ? "yes" : "no: " + fit->undetermined) << " |\n";
    return o.str();
}

std::string trend_row(const std::string& name, const std::optional<analytics::ResponseShapeResult>& t) {
    if (!t) return "| " + name + " | not fitted | | |\n";
    const auto& f = t->selected();
    std::ostringstream o;
    o.precision(4);
    o << "| " << name << " | " << analytics::to_string(t->shape) << ": " << f.coefficients[0].value << " +/- "
      << f.coefficients[0].std_error << " at the reference";
    if (f.degree >= 1) o << ", slope " << f.coefficients[1].value << " +/- " << f.coefficients[1].std_error << " per m";
    o << " | | F test p = " << t->linear_vs_constant.p_value << " |\n";
    return o.str();
}
}  // namespace

std::string EnlargementStudy::markdown() const {
    std::ostringstream o;
    o.precision(4);
    o << "## Base parameters per radius (" << to_string(options.line) << " line)\n\n"
      << "| r [mm] | box/d across | box/d height | particles | steps | dt [s] | CPU/run [s] | wall/run [s] "
         "| mu_b +/- SE | tau_c +/- SE [Pa] |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& b : bases)
        o << "| " << b.radius * 1e3 << " | " << b.box.across << (b.box.adequate() ? "" : " (!)") << " | "
          << b.box.height << " | " << b.cost.particles << " | " << b.cost.steps << " | " << b.cost.timestep_s << " | "
          << b.cost.cpu_s << " | " << b.cost.wall_s << " | " << b.line.mu_b << " +/- " << b.line.se_mu_b << " | "
          << b.line.tau_c << " +/- " << b.line.se_tau_c << " |\n";
    o << "\n## Calibrated to the reference line\n\n| r [mm] | status | E [Pa] | " << kPoissonLabel
      << " | mu_b | tau_c [Pa] | evaluations |\n|---|---|---|---|---|---|---|\n";
    for (const auto& c : calibrations) {
        const auto& best = c.result.iterations.at(c.result.best);
        o << "| " << c.radius * 1e3 << " | " << to_string(c.result.status) << " | " << c.young_modulus << " | "
          << c.poisson_ratio << " | " << best.mu_b << " | " << best.tau_c << " | " << c.result.evaluations << " |\n";
    }
    if (!verifications.empty()) {
        o << "\n## Verification: the laws' materials\n\n| r [mm] | E [Pa] | " << kPoissonLabel
          << " | mu_b (dev.) | tau_c [Pa] (dev.) | within " << 100 * options.tolerance
          << " % | cost saved |\n|---|---|---|---|---|---|---|\n";
        for (const auto& v : verifications) {
            o << "| " << v.radius * 1e3 << " | " << v.young_modulus << " | " << v.poisson_ratio << " | ";
            if (!v.not_run_because.empty()) {
                o << "not run: " << v.not_run_because << " | | | |\n";
                continue;
            }
            o << v.line.mu_b << " (" << 100 * v.mu_b_deviation << " %) | " << v.line.tau_c << " ("
              << 100 * v.tau_c_deviation << " %) | " << (v.within_tolerance ? "yes" : "no") << " | "
              << 100 * v.cost_saved << " % |\n";
        }
    }
    o << "\n## Laws (r in m; " << 100 * options.confidence
      << " % intervals)\n\n| law | constants | R^2 | determined |\n"
      << "|---|---|---|---|\n"
      << law_row("CPU per run = C r^-D [s]", cpu_law) << law_row("particle-steps per run = C r^-D", work_law)
      << trend_row("mu_b(r)", mu_b_trend)
      << trend_row("tau_c(r) [Pa]", tau_c_trend) << law_row("E(r) = A r + B [Pa]", young_law)
      << law_row(std::string(kPoissonLabel) + "(r) = C r^-D", poisson_law);
    if (!problems.empty()) {
        o << "\n## Not determined\n\n";
        for (const auto& p : problems) o << "- " << p << "\n";
    }
    if (!warnings.empty()) {
        o << "\n## Warnings\n\n";
        for (const auto& w : warnings) o << "- " << w << "\n";
    }
    return o.str();
}

}  // namespace demcal::calibration
