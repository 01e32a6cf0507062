#include "calibration/campaign_evaluator.hpp"

#include "orchestrator/campaign_suspended.hpp"

#include <stdexcept>

namespace demcal::calibration {

orchestrator::ShearCampaignSpec CampaignSettings::spec_for(const nlohmann::json& material) const {
    orchestrator::ShearCampaignSpec spec;
    spec.material = material;
    spec.normal_stresses = normal_stresses;
    spec.replicates = replicates;
    spec.base_seed = base_seed;
    spec.template_path = template_path;
    spec.label = label;
    spec.engine = engine;
    return spec;
}

FailureLineEvaluator campaign_evaluator(orchestrator::ShearCampaignRunner& runner, CampaignSettings settings,
                                        orchestrator::ProgressCallback progress) {
    return [&runner, settings = std::move(settings), progress = std::move(progress)](const nlohmann::json& material) {
        auto spec = settings.spec_for(material);
        auto ev = evaluate_failure_line(runner, spec, progress);
        const std::string label = spec.label;
        for (int round = 1; round <= kMaxReplacementRounds && (!ev.peak || !ev.residual) &&
                            ev.simulations_failed > 0 && !ev.outcome.interrupted &&
                            ev.outcome.infrastructure_failure.empty();
             ++round) {
            spec.base_seed += spec.replicates;  // the next unused seeds
            spec.label = label + (label.empty() ? "" : " ") + "replacement " + std::to_string(round);
            ev = failure_lines_of(merged_outcome(ev.outcome, runner.run(spec, progress)));
            ev.replacement_rounds = round;
        }
        if (ev.outcome.interrupted)
            throw orchestrator::CampaignSuspended(
                "interrupted; every finished run is stored: run the same command again to resume");
        if (!ev.outcome.infrastructure_failure.empty())
            throw orchestrator::CampaignSuspended("the simulator could not be started (" + ev.outcome.infrastructure_failure +
                                     "); every finished run is stored: fix it (--yade; the kernel engine: the demcal program) and run the same command again");
        return ev;
    };
}

}  // namespace demcal::calibration
