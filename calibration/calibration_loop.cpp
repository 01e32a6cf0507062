#include "calibration/calibration_loop.hpp"

#include "analytics/number_text.hpp"
#include "orchestrator/shear_params.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace demcal::calibration {

SearchMethod search_method_from_string(const std::string& text) {
    if (text == "surrogate") return SearchMethod::surrogate;
    if (text == "coordinate") return SearchMethod::coordinate;
    if (text == "grid") return SearchMethod::grid;
    throw std::invalid_argument("method = '" + text + "' is not one of surrogate, coordinate, grid");
}

std::string to_string(SearchMethod method) {
    switch (method) {
        case SearchMethod::surrogate: return "surrogate";
        case SearchMethod::coordinate: return "coordinate";
        case SearchMethod::grid: return "grid";
    }
    return "?";
}

std::string to_string(CalibrationStatus status) {
    switch (status) {
        case CalibrationStatus::converged: return "converged";
        case CalibrationStatus::unreachable: return "unreachable";
        case CalibrationStatus::not_converged: return "not_converged";
    }
    return "?";
}

nlohmann::json CalibrationIteration::to_json() const {
    return {{"evaluation", evaluation},
            {"phase", phase},
            {"values", values},
            {"mu_b", mu_b},
            {"mu_b_half_width", mu_b_half_width},
            {"tau_c", tau_c},
            {"tau_c_half_width", tau_c_half_width},
            {"mismatch", mismatch},
            {"accepted", accepted},
            {"accepted_by", accepted_by},
            {"simulations_run", simulations_run},
            {"simulations_reused", simulations_reused},
            {"cpu_s", cpu_s}};
}

nlohmann::json CalibrationResult::to_json() const {
    nlohmann::json j = {{"schema", "demcal.calibration/1"},
                        {"status", to_string(status)},
                        {"message", message},
                        {"method", to_string(method)},
                        {"tolerance", tolerance},
                        {"material", material},
                        {"evaluations", evaluations},
                        {"simulations_run", simulations_run},
                        {"simulations_reused", simulations_reused},
                        {"cpu_s", cpu_s},
                        {"best", best >= 0 ? iterations[best].to_json() : nlohmann::json(nullptr)},
                        {"controls", nlohmann::json::array()},
                        {"targets", nlohmann::json::array()},
                        {"iterations", nlohmann::json::array()}};
    for (const auto& c : controls) j["controls"].push_back({{"name", c.name}, {"low", c.low}, {"high", c.high}});
    for (const auto& t : targets)
        j["targets"].push_back({{"quantity", t.quantity},
                                {"value", t.value},
                                {"half_width", t.half_width ? nlohmann::json(*t.half_width) : nlohmann::json(nullptr)},
                                {"acceptance", t.acceptance(tolerance)}});
    for (const auto& it : iterations) j["iterations"].push_back(it.to_json());
    return j;
}

namespace {

std::string num(double v) { return analytics::number_text(v, 5); }

double determinant(std::vector<std::vector<double>> a) {  // Gaussian elimination; matrices here are 1x1 or 2x2
    const std::size_t n = a.size();
    double det = 1;
    for (std::size_t c = 0; c < n; ++c) {
        std::size_t pivot = c;
        for (std::size_t r = c + 1; r < n; ++r)
            if (std::fabs(a[r][c]) > std::fabs(a[pivot][c])) pivot = r;
        if (a[pivot][c] == 0) return 0;
        if (pivot != c) std::swap(a[pivot], a[c]), det = -det;
        det *= a[c][c];
        for (std::size_t r = c + 1; r < n; ++r) {
            const double f = a[r][c] / a[c][c];
            for (std::size_t k = c; k < n; ++k) a[r][k] -= f * a[c][k];
        }
    }
    return det;
}

// Signed change of a response across the studied range of its parameter, in units of the target's acceptance.
double normalized_effect(const ParameterSensitivity& p, const MacroTarget& t, double tolerance) {
    const auto& r = p.response(t.quantity);
    if (r.shape == analytics::ResponseShape::constant) return 0;
    return (r.value(p.high()) - r.value(p.low())) / t.acceptance(tolerance);
}

// Everything one search needs, shared by the three methods.
class Search {
public:
    Search(const nlohmann::json& start, const std::vector<MacroTarget>& targets,
           const std::vector<ControlParameter>& controls, const FailureLineEvaluator& evaluate,
           const CalibrationOptions& options, const IterationCallback& on_iteration, CalibrationResult& result)
        : start_(start), targets_(targets), controls_(controls), evaluate_(evaluate), options_(options),
          on_iteration_(on_iteration), result_(result) {}

    std::size_t dims() const { return controls_.size(); }

    // Scaled coordinate z in [0, 1] of each control <-> parameter value.
    double value_of(std::size_t j, double z) const {
        return round_significant(controls_[j].low + z * (controls_[j].high - controls_[j].low));
    }
    double z_of(std::size_t j, double value) const {
        return (value - controls_[j].low) / (controls_[j].high - controls_[j].low);
    }
    std::vector<double> start_z() const {
        std::vector<double> z;
        for (std::size_t j = 0; j < dims(); ++j) z.push_back(z_of(j, start_.at(controls_[j].name).get<double>()));
        return z;
    }

    nlohmann::json material_at(const std::vector<double>& z) const {
        nlohmann::json m = start_;
        for (std::size_t j = 0; j < dims(); ++j) m[controls_[j].name] = value_of(j, z[j]);
        return m;
    }

    // The actual z of a proposal after rounding its values.
    std::vector<double> snapped(const std::vector<double>& z) const {
        std::vector<double> s;
        for (std::size_t j = 0; j < dims(); ++j) s.push_back(z_of(j, value_of(j, z[j])));
        return s;
    }

    // Simulates the failure line at z (or finds it among this search's evaluations) and records the iteration.
    const CalibrationIteration& evaluate_at(const std::vector<double>& z_in, const std::string& phase) {
        const auto z = snapped(z_in);
        for (std::size_t k = 0; k < points_.size(); ++k)
            if (points_[k] == z) return result_.iterations[k];
        const nlohmann::json material = material_at(z);
        const auto ev = evaluate_(material);
        const auto& line = line_of(ev, options_.line);
        CalibrationIteration it;
        it.evaluation = static_cast<int>(result_.iterations.size()) + 1;
        it.phase = phase;
        for (const auto& c : controls_) it.values[c.name] = material.at(c.name).get<double>();
        it.mu_b = line.mu_b;
        it.mu_b_half_width = macro_half_width(line, "mu_b");
        it.tau_c = line.tau_c;
        it.tau_c_half_width = macro_half_width(line, "tau_c");
        it.simulations_run = ev.simulations_run;
        it.simulations_reused = ev.simulations_reused;
        it.cpu_s = ev.cpu_s;
        // tolerance alone, or widened to a measured target's own interval, or (unless strict) the simulated interval
        bool all_tolerance = true, all_acceptance = true, all_either = true;
        it.mismatch = 0;
        for (const auto& t : targets_) {
            const double off = std::fabs(macro_value(line, t.quantity) - t.value);
            it.mismatch = std::max(it.mismatch, off / t.acceptance(options_.tolerance));
            const bool by_acceptance = off <= t.acceptance(options_.tolerance);
            const bool by_interval = options_.accept_simulated_interval && off <= macro_half_width(line, t.quantity);
            all_tolerance = all_tolerance && off <= options_.tolerance * std::fabs(t.value);
            all_acceptance = all_acceptance && by_acceptance;
            all_either = all_either && (by_acceptance || by_interval);
        }
        it.accepted = all_either;
        it.accepted_by = all_tolerance    ? "tolerance"
                         : all_acceptance ? "target's interval"
                         : all_either     ? "simulated interval"
                                          : "";
        result_.iterations.push_back(it);
        points_.push_back(z);
        values_.push_back(observed(line));
        result_.evaluations++;
        result_.simulations_run += it.simulations_run;
        result_.simulations_reused += it.simulations_reused;
        result_.cpu_s += it.cpu_s;
        if (result_.best < 0 || it.mismatch < result_.iterations[result_.best].mismatch)
            result_.best = static_cast<int>(result_.iterations.size()) - 1;
        if (on_iteration_) on_iteration_(it);
        return result_.iterations.back();
    }

    std::vector<double> observed(const analytics::FailureLine& line) const {
        std::vector<double> y;
        for (const auto& t : targets_) y.push_back(macro_value(line, t.quantity));
        return y;
    }

    bool budget_left() const { return static_cast<int>(result_.iterations.size()) < options_.max_evaluations; }

    // Sum of squared target misses in acceptance units (what the searches minimise).
    double objective(const std::vector<double>& y) const {
        double s = 0;
        for (std::size_t t = 0; t < targets_.size(); ++t) {
            const double d = (y[t] - targets_[t].value) / targets_[t].acceptance(options_.tolerance);
            s += d * d;
        }
        return s;
    }

    const std::vector<std::vector<double>>& points() const { return points_; }
    const std::vector<std::vector<double>>& values() const { return values_; }
    const std::vector<MacroTarget>& targets() const { return targets_; }
    const std::vector<ControlParameter>& controls() const { return controls_; }
    const CalibrationOptions& options() const { return options_; }
    CalibrationResult& result() { return result_; }
    const CalibrationResult& result() const { return result_; }

private:
    nlohmann::json start_;
    std::vector<MacroTarget> targets_;
    std::vector<ControlParameter> controls_;
    const FailureLineEvaluator& evaluate_;
    CalibrationOptions options_;
    const IterationCallback& on_iteration_;
    CalibrationResult& result_;
    std::vector<std::vector<double>> points_;  // z of each evaluation (same order as result_.iterations)
    std::vector<std::vector<double>> values_;  // the targets' simulated values there
};

// ---- surrogate search ----

// The response the surrogate steers by: the study's selected shape, or where that is "constant", the fitted line.
// With three levels the F test of a slope has one residual degree of freedom and calls most real trends constant
// (at 3 mm in examples/scale/ every response of E and nu but one); "constant" says the slope is not significant, not
// that it is zero, and a step along its point estimate is checked by the next evaluation (and the Broyden update).
const analytics::PolynomialFit& steering_fit(const analytics::ResponseShapeResult& r) {
    if (r.shape == analytics::ResponseShape::constant && r.fits.size() > 1) return r.fits[1];
    return r.selected();
}

// Model of the targets' values over the active controls: the latest simulated point plus the study's response
// changes of each control, plus a Broyden-updated linear correction for what the separable study model misses
// (interactions, a different start than the study's base, the study's noise).
class SurrogateModel {
public:
    SurrogateModel(const Search& search, const SensitivityStudy& study, std::vector<std::size_t> active_controls,
                   std::vector<std::size_t> active_targets)
        : search_(search), active_controls_(std::move(active_controls)), active_targets_(std::move(active_targets)) {
        for (std::size_t j : active_controls_) {
            const auto* p = study.find(search.controls()[j].name);
            if (!p)
                throw std::invalid_argument("the sensitivity study has no parameter '" + search.controls()[j].name +
                                            "' (a controlling parameter needs one)");
            responses_.push_back(p);
        }
        correction_.assign(active_targets_.size(), std::vector<double>(active_controls_.size(), 0.0));
    }

    void anchor(const std::vector<double>& z, const std::vector<double>& y) {
        if (has_anchor_) {
            // Broyden: make the model reproduce the step from the old anchor to the new point exactly.
            std::vector<double> dz(active_controls_.size());
            double dz2 = 0;
            for (std::size_t a = 0; a < dz.size(); ++a) {
                dz[a] = z[active_controls_[a]] - anchor_z_[active_controls_[a]];
                dz2 += dz[a] * dz[a];
            }
            if (dz2 > 0) {
                const auto predicted = predict(z);
                for (std::size_t t = 0; t < active_targets_.size(); ++t) {
                    const double miss = y[active_targets_[t]] - predicted[t];
                    for (std::size_t a = 0; a < dz.size(); ++a) correction_[t][a] += miss * dz[a] / dz2;
                }
            }
        }
        anchor_z_ = z;
        anchor_y_ = y;
        has_anchor_ = true;
    }

    // Predicted values of the active targets at z (all controls; inactive ones stay at the anchor).
    std::vector<double> predict(const std::vector<double>& z) const {
        std::vector<double> y;
        for (std::size_t t = 0; t < active_targets_.size(); ++t) {
            const auto& quantity = search_.targets()[active_targets_[t]].quantity;
            double v = anchor_y_[active_targets_[t]];
            for (std::size_t a = 0; a < active_controls_.size(); ++a) {
                const std::size_t j = active_controls_[a];
                const auto& r = responses_[a]->response(quantity);
                const auto& fit = steering_fit(r);
                v += fit.value(search_.value_of(j, z[j]), r.x_ref) - fit.value(search_.value_of(j, anchor_z_[j]), r.x_ref);
                v += correction_[t][a] * (z[j] - anchor_z_[j]);
            }
            y.push_back(v);
        }
        return y;
    }

    double objective(const std::vector<double>& z) const {
        const auto y = predict(z);
        double s = 0;
        for (std::size_t t = 0; t < active_targets_.size(); ++t) {
            const auto& target = search_.targets()[active_targets_[t]];
            const double d = (y[t] - target.value) / target.acceptance(search_.options().tolerance);
            s += d * d;
        }
        return s;
    }

    // Minimises the model's objective over the bounds (NLopt); ties go to the point nearest the anchor.
    std::vector<double> propose() const {
        const unsigned n = static_cast<unsigned>(active_controls_.size());
        struct Context {
            const SurrogateModel* model;
            std::vector<double> z;
        } ctx{this, anchor_z_};
        auto f = [](unsigned n_, const double* x, double*, void* data) -> double {
            auto* c = static_cast<Context*>(data);
            std::vector<double> z = c->model->anchor_z_;
            double distance2 = 0;
            for (unsigned a = 0; a < n_; ++a) {
                const std::size_t j = c->model->active_controls_[a];
                z[j] = x[a];
                distance2 += (x[a] - c->model->anchor_z_[j]) * (x[a] - c->model->anchor_z_[j]);
            }
            return c->model->objective(z) + 1e-6 * distance2;  // a flat valley: stay near what was simulated
        };
        std::vector<double> x(n), lb(n, 0.0), ub(n, 1.0);
        for (unsigned a = 0; a < n; ++a) x[a] = std::clamp(anchor_z_[active_controls_[a]], 0.0, 1.0);
        double fx = f(n, x.data(), nullptr, &ctx);
        // Global pass over the box (the responses may be parabolic: two roots), then a local polish.
        nlopt_opt global = nlopt_create(NLOPT_GN_DIRECT_L, n);
        nlopt_set_lower_bounds(global, lb.data());
        nlopt_set_upper_bounds(global, ub.data());
        nlopt_set_min_objective(global, f, &ctx);
        nlopt_set_maxeval(global, 400 * n);
        std::vector<double> xg = x;
        double fg = 0;
        if (nlopt_optimize(global, xg.data(), &fg) >= 0 && fg < fx) x = xg, fx = fg;
        nlopt_destroy(global);
        nlopt_opt local = nlopt_create(n >= 2 ? NLOPT_LN_BOBYQA : NLOPT_LN_COBYLA, n);
        nlopt_set_lower_bounds(local, lb.data());
        nlopt_set_upper_bounds(local, ub.data());
        nlopt_set_min_objective(local, f, &ctx);
        nlopt_set_xtol_abs1(local, 1e-9);
        nlopt_set_maxeval(local, 2000);
        nlopt_set_initial_step1(local, 0.05);
        std::vector<double> xl = x;
        double fl = 0;
        if (nlopt_optimize(local, xl.data(), &fl) >= 0 && fl <= fx) x = xl;
        nlopt_destroy(local);
        std::vector<double> z = anchor_z_;
        for (unsigned a = 0; a < n; ++a) z[active_controls_[a]] = std::clamp(x[a], 0.0, 1.0);
        return z;
    }

    // Where the model's local linearisation at the anchor meets every target, bounds ignored (one or two controls
    // for as many targets), and the angle between the controls' effects in units of each target's acceptance (two
    // controls; near 0: they move the targets alike, and their pair reaches only a narrow band of targets). Empty
    // when the system is not square or is singular. For the message of an unreachable end: what the bounds hide.
    struct UnboundedMatch {
        std::vector<double> values;  // of the active controls
        double effects_angle_deg = -1;
    };
    std::optional<UnboundedMatch> unbounded_match() const {
        const std::size_t n = active_controls_.size();
        if (n != active_targets_.size() || n == 0 || n > 2 || !has_anchor_) return std::nullopt;
        constexpr double h = 0.01;  // in z: 1 % of a control's range
        const auto y0 = predict(anchor_z_);
        std::vector<std::vector<double>> J(n, std::vector<double>(n));  // [target][control], per unit z
        for (std::size_t a = 0; a < n; ++a) {
            auto z = anchor_z_;
            z[active_controls_[a]] += h;
            const auto y = predict(z);
            for (std::size_t t = 0; t < n; ++t) J[t][a] = (y[t] - y0[t]) / h;
        }
        std::vector<double> miss(n), acceptance(n);
        for (std::size_t t = 0; t < n; ++t) {
            const auto& target = search_.targets()[active_targets_[t]];
            miss[t] = target.value - y0[t];
            acceptance[t] = target.acceptance(search_.options().tolerance);
        }
        std::vector<double> dz(n);
        UnboundedMatch m;
        if (n == 1) {
            if (J[0][0] == 0) return std::nullopt;
            dz[0] = miss[0] / J[0][0];
        } else {
            const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
            if (!(std::fabs(det) > 0)) return std::nullopt;
            dz[0] = (miss[0] * J[1][1] - J[0][1] * miss[1]) / det;
            dz[1] = (J[0][0] * miss[1] - miss[0] * J[1][0]) / det;
            const double ax = J[0][0] / acceptance[0], ay = J[1][0] / acceptance[1];
            const double bx = J[0][1] / acceptance[0], by = J[1][1] / acceptance[1];
            const double cosine = (ax * bx + ay * by) / (std::hypot(ax, ay) * std::hypot(bx, by));
            const double angle = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180 / M_PI;
            m.effects_angle_deg = std::min(angle, 180 - angle);  // a line's direction, either sense
        }
        for (std::size_t a = 0; a < n; ++a) {
            const std::size_t j = active_controls_[a];
            m.values.push_back(search_.value_of(j, anchor_z_[j] + dz[a]));
        }
        return m;
    }
    const std::vector<std::size_t>& active_controls() const { return active_controls_; }

private:
    const Search& search_;
    std::vector<std::size_t> active_controls_, active_targets_;
    std::vector<const ParameterSensitivity*> responses_;
    std::vector<std::vector<double>> correction_;  // targets x controls, per unit of z
    std::vector<double> anchor_z_, anchor_y_;
    bool has_anchor_ = false;
};

constexpr double same_point = 1e-6;  // in z: proposals closer than this repeat a simulated point

// Controls sitting on a bound at z, described for the user.
std::string bounds_at(const Search& s, const std::vector<double>& z, const std::vector<std::size_t>& active) {
    std::string text;
    for (std::size_t j : active) {
        const auto& c = s.controls()[j];
        if (z[j] <= same_point) text += (text.empty() ? "" : ", ") + c.name + " at its lower bound " + num(c.low);
        if (z[j] >= 1 - same_point) text += (text.empty() ? "" : ", ") + c.name + " at its upper bound " + num(c.high);
    }
    return text;
}

// An evaluation's simulated value and interval half-width of a macro quantity ("mu_b" or "tau_c").
double value_at(const CalibrationIteration& it, const std::string& quantity) {
    return quantity == "mu_b" ? it.mu_b : it.tau_c;
}
double half_width_at(const CalibrationIteration& it, const std::string& quantity) {
    return quantity == "mu_b" ? it.mu_b_half_width : it.tau_c_half_width;
}

std::string misses_at(const Search& s, const CalibrationIteration& it, const std::vector<std::size_t>& targets) {
    std::string text;
    for (std::size_t t : targets) {
        const auto& target = s.targets()[t];
        const double v = value_at(it, target.quantity);
        if (std::fabs(v - target.value) <= target.acceptance(s.options().tolerance)) continue;
        text += (text.empty() ? "" : "; ") + target.quantity + " = " + num(v) + ", target " + num(target.value) +
                " +/- " + num(target.acceptance(s.options().tolerance));
    }
    return text;
}

// The best evaluation so far and what it misses, for messages.
std::string best_so_far(const Search& s, const std::vector<std::size_t>& targets) {
    const auto& r = s.result();
    return "best so far, evaluation #" + std::to_string(r.best + 1) + ": " + misses_at(s, r.iterations[r.best], targets);
}

// True when no target differs from the simulated line at evaluation k by more than their difference's own interval:
// there the simulation cannot tell the target from what it gave, so a bound reached there is noise, not proof that
// the target is out of reach. A target measured as a line has an interval of its own; the two are independent, so
// the difference's half-width is their root sum of squares (a hidden material next to the bound whose 60-run line
// missed by 12 % against two intervals of 9 % each was called out of reach).
bool target_within_noise_at(const Search& s, std::size_t k, const std::vector<std::size_t>& targets) {
    const auto& it = s.result().iterations[k];
    for (std::size_t t : targets) {
        const auto& target = s.targets()[t];
        const double v = value_at(it, target.quantity), hw = half_width_at(it, target.quantity);
        const double target_hw = target.half_width.value_or(0.0);
        if (!(std::fabs(v - target.value) <= std::hypot(hw, target_hw))) return false;
    }
    return true;
}

// What the model says lies beyond the bounds of an unreachable end (SurrogateModel::unbounded_match), as text.
std::string beyond_bounds(const Search& s, const SurrogateModel& model) {
    const auto m = model.unbounded_match();
    if (!m) return "";
    std::string text = "; the study's model meets the targets at ";
    for (std::size_t a = 0; a < m->values.size(); ++a)
        text += (a ? ", " : "") + s.controls()[model.active_controls()[a]].name + " = " + num(m->values[a]);
    if (m->effects_angle_deg >= 0) {
        text += " (the two controls' effects are " + num(std::round(m->effects_angle_deg)) + " deg apart";
        if (m->effects_angle_deg < 30) text += ": they move the targets nearly alike";
        text += ")";
    }
    return text;
}

// Ends the search at `where`, a bound simulated already at evaluation k: unreachable, unless the target lies within
// the noise of that line and its own (then the bound may have been reached by noise).
void end_at_simulated_bound(Search& s, const std::string& where, std::size_t k, const std::vector<std::size_t>& targets,
                            const std::string& beyond = "") {
    auto& r = s.result();
    if (target_within_noise_at(s, k, targets)) {
        r.status = CalibrationStatus::not_converged;
        r.message = "the model asks for " + where + ", simulated already (evaluation #" + std::to_string(k + 1) +
                    "), where the target lies within the noise of the simulated line (and of the target's own "
                    "line): the responses are too noisy to tell whether the target is in reach (" +
                    best_so_far(s, targets) +
                    "); more packings per stress (--replicates) or a wider --tol";
    } else {
        r.status = CalibrationStatus::unreachable;
        r.message = "target out of reach within the bounds: " + where + " (" + best_so_far(s, targets) + ")" +
                    beyond + "; widen it with --bounds NAME=LOW:HIGH or choose other controlling parameters";
    }
}

// Non-empty (the bounds, described) when the model's best point still misses a target, sits on bounds, and a point
// with the same controls on the same bounds has been simulated already (its index in `simulated`).
std::string pinned_bound_simulated(const Search& s, const SurrogateModel& model, const std::vector<double>& proposal,
                                   const std::vector<std::size_t>& controls, const std::vector<std::size_t>& targets,
                                   std::size_t& simulated) {
    const auto predicted = model.predict(proposal);
    bool misses = false;
    for (std::size_t t = 0; t < targets.size(); ++t) {
        const auto& target = s.targets()[targets[t]];
        misses = misses || std::fabs(predicted[t] - target.value) > target.acceptance(s.options().tolerance);
    }
    std::vector<std::size_t> on_bound;
    for (std::size_t j : controls)
        if (proposal[j] <= same_point || proposal[j] >= 1 - same_point) on_bound.push_back(j);
    if (!misses || on_bound.empty()) return "";
    for (std::size_t k = 0; k < s.points().size(); ++k) {
        bool same = true;
        for (std::size_t j : on_bound) same = same && std::fabs(s.points()[k][j] - proposal[j]) < same_point;
        if (same) {
            simulated = k;
            return bounds_at(s, proposal, on_bound);
        }
    }
    return "";
}

// A step between two simulated evaluations that bracket every target (each target lies strictly between their
// values): the point of their segment where the lines interpolated linearly miss least (in acceptance units). The
// surrogate adds one-at-a-time responses and may call a target out of reach where the parameters interact; two
// evaluations on either side say otherwise. None when no pair brackets every target or the point was simulated.
std::optional<std::vector<double>> bracketing_step(const Search& s, const std::vector<std::size_t>& controls,
                                                   const std::vector<std::size_t>& targets) {
    const auto& its = s.result().iterations;
    const auto& pts = s.points();
    std::optional<std::vector<double>> best;
    double best_miss = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < pts.size(); ++a)
        for (std::size_t b = a + 1; b < pts.size(); ++b) {
            bool brackets = true;
            double num = 0, den = 0;
            for (std::size_t t : targets) {
                const auto& target = s.targets()[t];
                const double ya = value_at(its[a], target.quantity), yb = value_at(its[b], target.quantity);
                const double w = 1.0 / std::pow(target.acceptance(s.options().tolerance), 2);
                brackets = brackets && (ya - target.value) * (yb - target.value) < 0;
                num += w * (target.value - ya) * (yb - ya);
                den += w * (yb - ya) * (yb - ya);
            }
            if (!brackets || !(den > 0)) continue;
            const double lambda = std::clamp(num / den, 0.0, 1.0);
            double miss = 0;
            for (std::size_t t : targets) {
                const auto& target = s.targets()[t];
                const double ya = value_at(its[a], target.quantity), yb = value_at(its[b], target.quantity);
                miss += std::pow((ya + lambda * (yb - ya) - target.value) / target.acceptance(s.options().tolerance), 2);
            }
            std::vector<double> z = pts[b];
            for (std::size_t j : controls) z[j] = pts[a][j] + lambda * (pts[b][j] - pts[a][j]);
            z = s.snapped(z);
            bool simulated = false;
            for (const auto& q : pts) {
                double d = 0;
                for (std::size_t j : controls) d = std::max(d, std::fabs(q[j] - z[j]));
                simulated = simulated || d < same_point;
            }
            if (!simulated && miss < best_miss) best = z, best_miss = miss;
        }
    return best;
}

bool accepted_for(const Search& s, const CalibrationIteration& it, const std::vector<std::size_t>& targets) {
    for (std::size_t t : targets) {
        const auto& target = s.targets()[t];
        const double v = value_at(it, target.quantity), hw = half_width_at(it, target.quantity);
        const double off = std::fabs(v - target.value);
        if (off > target.acceptance(s.options().tolerance) && !(s.options().accept_simulated_interval && off <= hw))
            return false;
    }
    return true;
}

// One surrogate phase over some controls and targets, from the latest point. Returns false with the result's status
// and message set when the phase cannot finish.
bool surrogate_phase(Search& s, const SensitivityStudy& study, const std::vector<std::size_t>& controls,
                     const std::vector<std::size_t>& targets, const std::string& phase, std::vector<double>& z) {
    SurrogateModel model(s, study, controls, targets);
    std::size_t k = s.points().size() - 1;
    model.anchor(s.points()[k], s.values()[k]);
    while (!accepted_for(s, s.result().iterations[k], targets)) {
        const auto proposal = s.snapped(model.propose());
        bool repeats = false;
        std::size_t repeated = 0;
        for (std::size_t q = 0; q < s.points().size() && !repeats; ++q) {
            double d = 0;
            for (std::size_t j : controls) d = std::max(d, std::fabs(s.points()[q][j] - proposal[j]));
            if (d < same_point) repeats = true, repeated = q;
        }
        // Where the surrogate gives up (a simulated point again, or a simulated bound), evaluations that bracket every
        // target still show a way: a secant step between them.
        std::size_t at_bound = 0;
        const auto pinned =
            repeats ? std::string() : pinned_bound_simulated(s, model, proposal, controls, targets, at_bound);
        if ((repeats || !pinned.empty()) && s.budget_left())
            if (const auto step = bracketing_step(s, controls, targets)) {
                s.evaluate_at(*step, phase + " (bracketed)");
                k = s.points().size() - 1;
                model.anchor(s.points()[k], s.values()[k]);
                continue;
            }
        if (repeats) {
            const std::string where = bounds_at(s, proposal, controls);
            auto& r = s.result();
            if (!where.empty()) {
                end_at_simulated_bound(s, where, repeated, targets, beyond_bounds(s, model));
            } else {
                r.status = CalibrationStatus::not_converged;
                r.message = "the search stalled at an already simulated point (" + best_so_far(s, targets) +
                            "); the responses may be too noisy for the tolerance";
            }
            return false;
        }
        // The model finds no point that meets the targets and wants a bound that has already been simulated, and no
        // two evaluations bracket the targets: the simulations confirmed the model there, so more cannot help.
        if (!pinned.empty()) {
            end_at_simulated_bound(s, pinned, at_bound, targets, beyond_bounds(s, model));
            return false;
        }
        if (!s.budget_left()) {
            s.result().status = CalibrationStatus::not_converged;
            s.result().message = "no match within " + std::to_string(s.options().max_evaluations) +
                                 " failure-line evaluations (--max-evaluations); " + best_so_far(s, targets);
            return false;
        }
        s.evaluate_at(proposal, phase);
        k = s.points().size() - 1;
        model.anchor(s.points()[k], s.values()[k]);
    }
    z = s.points()[k];
    return true;
}

void run_surrogate(Search& s, const SensitivityStudy& study) {
    std::vector<double> z = s.start_z();
    s.evaluate_at(z, "start");
    std::vector<std::size_t> all_targets, all_controls;
    for (std::size_t t = 0; t < s.targets().size(); ++t) all_targets.push_back(t);
    for (std::size_t j = 0; j < s.dims(); ++j) all_controls.push_back(j);
    if (!s.options().sequential || s.dims() < 2) {
        if (surrogate_phase(s, study, all_controls, all_targets, "joint", z)) s.result().status = CalibrationStatus::converged;
        return;
    }
    // Seed order: the slope with the first control, then the cohesion with the second; repeated while the second
    // phase moved the first target away again.
    for (int round = 0; round < 3; ++round) {
        for (std::size_t t = 0; t < s.targets().size(); ++t)
            if (!surrogate_phase(s, study, {t}, {t}, s.targets()[t].quantity == "mu_b" ? "slope" : "cohesion", z))
                return;
        if (accepted_for(s, s.result().iterations.back(), all_targets)) {
            s.result().status = CalibrationStatus::converged;
            return;
        }
    }
    s.result().status = CalibrationStatus::not_converged;
    s.result().message = "the sequential phases kept undoing each other; try the joint search (without --sequential)";
}

// ---- baselines ----

void run_coordinate(Search& s) {
    std::vector<double> z = s.start_z();
    double fz = s.objective(s.values()[&s.evaluate_at(z, "coordinate") - &s.result().iterations[0]]);
    double step = 0.25;
    constexpr double min_step = 1.0 / 256;  // below 0.4 % of a range the search has resolved what noise allows
    while (!s.result().iterations[s.result().best].accepted && step >= min_step) {
        bool moved = false;
        for (std::size_t j = 0; j < s.dims() && !moved; ++j)
            for (double dir : {+1.0, -1.0}) {
                auto trial = z;
                trial[j] = std::clamp(z[j] + dir * step, 0.0, 1.0);
                if (trial[j] == z[j]) continue;
                if (!s.budget_left()) break;
                const auto& it = s.evaluate_at(trial, "coordinate");
                const double f = s.objective(s.values()[&it - &s.result().iterations[0]]);
                if (f < fz) {
                    z = s.snapped(trial), fz = f, moved = true;
                    break;
                }
            }
        if (!s.budget_left()) break;
        if (!moved) step /= 2;
    }
    auto& r = s.result();
    if (r.iterations[r.best].accepted) {
        r.status = CalibrationStatus::converged;
    } else {
        r.status = CalibrationStatus::not_converged;
        // why it stopped: the budget (--max-evaluations), or a step below what the noise lets it resolve
        r.message = "coordinate search stopped (step " + num(step) + " of the range, " +
                    std::to_string(r.evaluations) + " evaluations) without a match" +
                    (!s.budget_left() ? std::string(": the evaluation budget (--max-evaluations) is spent; a larger "
                                                    "one lets it go on")
                                      : std::string(": its step fell below 1/256 of the ranges"));
    }
}

void run_grid(Search& s) {
    const int k = s.options().grid_points;
    std::vector<int> index(s.dims(), 0);
    while (true) {
        std::vector<double> z;
        for (int i : index) z.push_back(static_cast<double>(i) / (k - 1));
        s.evaluate_at(z, "grid");
        std::size_t d = 0;
        while (d < index.size() && ++index[d] == k) index[d++] = 0;
        if (d == index.size()) break;
    }
    auto& r = s.result();
    if (r.iterations[r.best].accepted) {
        r.status = CalibrationStatus::converged;
    } else {
        r.status = CalibrationStatus::not_converged;
        r.message = "no grid point matches the targets; the best misses by " + num(r.iterations[r.best].mismatch) +
                    " acceptance widths";
    }
}

}  // namespace

std::vector<ControlParameter> choose_controls(const SensitivityStudy& study, const std::vector<MacroTarget>& targets,
                                              double tolerance, const std::vector<std::string>& candidates,
                                              const std::map<std::string, std::pair<double, double>>& bounds) {
    if (targets.empty() || targets.size() > 2)
        throw std::invalid_argument("targets: " + std::to_string(targets.size()) + " given, need mu_b and/or tau_c");
    std::vector<const ParameterSensitivity*> pool;
    for (const auto& p : study.parameters) {
        const bool listed = std::find(candidates.begin(), candidates.end(), p.name) != candidates.end();
        if (candidates.empty() ? p.name != "timestep_fraction" : listed) pool.push_back(&p);
    }
    for (const auto& c : candidates)
        if (!study.find(c))
            throw std::invalid_argument("params: '" + c + "' is not in the sensitivity study (studied: " +
                                        [&] {
                                            std::string s;
                                            for (const auto& p : study.parameters) s += (s.empty() ? "" : ", ") + p.name;
                                            return s;
                                        }() + ")");
    const std::size_t n = targets.size();
    double best_det = 0, best_diagonal = 0;
    std::vector<const ParameterSensitivity*> best;
    // Every ordered choice of n distinct parameters: row t = target t, column t = the control assigned to it.
    std::vector<std::size_t> pick(n, 0);
    auto consider = [&] {
        std::vector<std::vector<double>> e(n, std::vector<double>(n));
        double diagonal = 1;
        for (std::size_t t = 0; t < n; ++t)
            for (std::size_t c = 0; c < n; ++c) e[t][c] = normalized_effect(*pool[pick[c]], targets[t], tolerance);
        for (std::size_t t = 0; t < n; ++t) diagonal *= std::fabs(e[t][t]);
        const double det = std::fabs(determinant(e));
        // Equal determinants (the same set, assigned the other way): prefer each control on the target it moves most.
        if (det > best_det * (1 + 1e-12) || (det > 0 && det >= best_det * (1 - 1e-12) && diagonal > best_diagonal)) {
            best_det = det;
            best_diagonal = diagonal;
            best.clear();
            for (std::size_t c : pick) best.push_back(pool[c]);
        }
    };
    if (n == 1) {
        for (std::size_t a = 0; a < pool.size(); ++a) pick = {a}, consider();
    } else {
        for (std::size_t a = 0; a < pool.size(); ++a)
            for (std::size_t b = 0; b < pool.size(); ++b)
                if (a != b) pick = {a, b}, consider();
    }
    if (best_det < 1)  // the whole studied range moves the targets by less than one acceptance width
        throw std::invalid_argument(
            "no studied parameter set moves " + std::string(n == 2 ? "mu_b and tau_c independently" : "the target") +
            " by more than the tolerance over its range (largest |det| of the normalised effects = " + num(best_det) +
            "); widen the study's ranges (--range) or study other parameters (--params)");
    std::vector<ControlParameter> controls;
    for (const auto* p : best) {
        ControlParameter c{p->name, p->low(), p->high()};
        if (auto it = bounds.find(p->name); it != bounds.end()) std::tie(c.low, c.high) = it->second;
        controls.push_back(c);
    }
    return controls;
}

void check_calibration_options(const CalibrationOptions& options) {
    if (!(options.tolerance > 0 && options.tolerance < 1))
        throw std::invalid_argument("tol = " + num(options.tolerance) + " must be in (0, 1) (a relative distance)");
    if (options.max_evaluations < 1)
        throw std::invalid_argument("max-evaluations = " + std::to_string(options.max_evaluations) + " must be >= 1");
    if (options.method == SearchMethod::grid && options.grid_points < 2)
        throw std::invalid_argument("grid-points = " + std::to_string(options.grid_points) + " must be >= 2");
}

void check_control(const nlohmann::json& start, const ControlParameter& c) {
    const auto* spec = orchestrator::find_shear_param(c.name);
    if (!spec || spec->per_run)  // normal_stress and seed are the campaign's, not the material's
        throw std::invalid_argument("controlling parameter '" + c.name + "' is not a material parameter");
    if (!(c.low < c.high))
        throw std::invalid_argument("bounds of " + c.name + " = " + num(c.low) + ":" + num(c.high) +
                                    " must have low < high");
    const double v = start.at(c.name).get<double>();
    if (v < c.low || v > c.high)
        throw std::invalid_argument("start value " + c.name + " = " + num(v) + " is outside its bounds " +
                                    num(c.low) + ":" + num(c.high));
    for (double end : {c.low, c.high}) {  // the search evaluates materials up to either end
        nlohmann::json material = start;
        material[c.name] = end;
        orchestrator::validate_material(material, "bounds of " + c.name + " = " + num(c.low) + ":" + num(c.high));
    }
}

CalibrationResult calibrate(const nlohmann::json& start, const std::vector<MacroTarget>& targets,
                            const std::vector<ControlParameter>& controls, const SensitivityStudy* study,
                            const FailureLineEvaluator& evaluate, const CalibrationOptions& options,
                            const IterationCallback& on_iteration) {
    check_calibration_options(options);
    if (controls.empty()) throw std::invalid_argument("no controlling parameter to calibrate");
    if (targets.empty()) throw std::invalid_argument("no target to calibrate to");
    if (options.sequential && controls.size() != targets.size())
        throw std::invalid_argument("--sequential needs one controlling parameter per target, got " +
                                    std::to_string(controls.size()) + " for " + std::to_string(targets.size()));
    for (const auto& c : controls) check_control(start, c);
    if (options.method == SearchMethod::surrogate && !study)
        throw std::invalid_argument("the surrogate search needs a sensitivity study");
    CalibrationResult result;
    result.method = options.method;
    result.controls = controls;
    result.targets = targets;
    result.tolerance = options.tolerance;
    auto effective = options;
    if (options.method == SearchMethod::grid) {  // a plain grid evaluates all of itself
        effective.max_evaluations = 1;
        for (std::size_t j = 0; j < controls.size(); ++j) effective.max_evaluations *= options.grid_points;
    }
    Search search(start, targets, controls, evaluate, effective, on_iteration, result);
    switch (options.method) {
        case SearchMethod::surrogate: run_surrogate(search, *study); break;
        case SearchMethod::coordinate: run_coordinate(search); break;
        case SearchMethod::grid: run_grid(search); break;
    }
    if (result.status == CalibrationStatus::converged) {
        // The accepted point nearest the targets (the surrogate and coordinate searches stop at their first).
        int chosen = -1;
        for (std::size_t k = 0; k < result.iterations.size(); ++k)
            if (result.iterations[k].accepted &&
                (chosen < 0 || result.iterations[k].mismatch < result.iterations[chosen].mismatch))
                chosen = static_cast<int>(k);
        result.best = chosen;
        result.message = "matched after " + std::to_string(result.evaluations) + " failure-line evaluations (" +
                         result.iterations[chosen].accepted_by + ")";
        const CalibrationIteration& acc = result.iterations[chosen];
        if (acc.accepted_by == "simulated interval" && acc.mismatch > 1) {
            // Accepted only because the simulated interval is wide: say so, it is not a match at the tolerance.
            std::ostringstream why;
            why.precision(2);
            why << "; the simulated line is " << acc.mismatch
                << " tolerances from the target, accepted only because its own interval is that wide: add packings "
                   "(--replicates) or normal stresses, or pass --strict";
            result.message += why.str();
        }
    }
    result.material = start;
    for (const auto& [name, value] : result.iterations[result.best].values) result.material[name] = value;
    return result;
}

}  // namespace demcal::calibration
