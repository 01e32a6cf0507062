#include "calibration/campaign_evaluator.hpp"

#include <stdexcept>

namespace demcal::calibration {

FailureLineEvaluator campaign_evaluator(orchestrator::ShearCampaignRunner& runner, CampaignSettings settings,
                                        orchestrator::ProgressCallback progress) {
    return [&runner, settings = std::move(settings), progress = std::move(progress)](const nlohmann::json& material) {
        orchestrator::ShearCampaignSpec spec;
        spec.material = material;
        spec.normal_stresses = settings.normal_stresses;
        spec.replicates = settings.replicates;
        spec.base_seed = settings.base_seed;
        spec.template_path = settings.template_path;
        spec.label = settings.label;
        auto ev = evaluate_failure_line(runner, spec, progress);
        if (ev.outcome.interrupted)
            throw std::runtime_error("interrupted; every finished run is stored: run the same command again to resume");
        return ev;
    };
}

}  // namespace demcal::calibration
