#include "calibration/failure_line_evaluation.hpp"

#include <vector>

namespace demcal::calibration {

FailureLineEvaluation failure_lines_of(const orchestrator::ShearCampaignOutcome& outcome) {
    FailureLineEvaluation ev;
    ev.outcome = outcome;
    ev.simulations_run = outcome.executed;
    ev.simulations_reused = outcome.reused;
    ev.simulations_failed = outcome.failed;
    ev.cpu_s = outcome.cpu_s;
    std::vector<double> sigma, peak, residual;
    for (const auto& r : outcome.runs) {
        if (r.state != orchestrator::RunState::done) continue;
        sigma.push_back(r.label.at("normal_stress").get<double>());
        peak.push_back(r.result.at("peak_shear_stress").get<double>());
        residual.push_back(r.result.value("residual_shear_stress", r.result.at("peak_shear_stress").get<double>()));
    }
    try {
        ev.peak = analytics::fit_failure_line(sigma, peak);
        ev.residual = analytics::fit_failure_line(sigma, residual);
    } catch (const std::invalid_argument&) {
        // Too few finished runs for a line: the caller reports the runs, not a fit.
    }
    return ev;
}

orchestrator::ShearCampaignOutcome merged_outcome(orchestrator::ShearCampaignOutcome first,
                                                  const orchestrator::ShearCampaignOutcome& more) {
    first.runs.insert(first.runs.end(), more.runs.begin(), more.runs.end());
    first.executed += more.executed;
    first.reused += more.reused;
    first.failed += more.failed;
    first.cpu_s += more.cpu_s;
    first.interrupted = first.interrupted || more.interrupted;
    if (first.infrastructure_failure.empty()) first.infrastructure_failure = more.infrastructure_failure;
    return first;
}

FailureLineEvaluation evaluate_failure_line(orchestrator::ShearCampaignRunner& runner,
                                            const orchestrator::ShearCampaignSpec& spec,
                                            const orchestrator::ProgressCallback& progress) {
    return failure_lines_of(runner.run(spec, progress));
}

}  // namespace demcal::calibration
