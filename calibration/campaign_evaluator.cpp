#include "calibration/campaign_evaluator.hpp"

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
        auto ev = evaluate_failure_line(runner, settings.spec_for(material), progress);
        if (ev.outcome.interrupted)
            throw std::runtime_error("interrupted; every finished run is stored: run the same command again to resume");
        if (!ev.outcome.infrastructure_failure.empty())
            throw std::runtime_error("the simulator could not be started (" + ev.outcome.infrastructure_failure +
                                     "); every finished run is stored: fix --yade and run the same command again");
        return ev;
    };
}

}  // namespace demcal::calibration
