#include "calibration/campaign_evaluator.hpp"

#include "orchestrator/campaign_suspended.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <utility>

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

namespace {
constexpr const char* kReplacementWord = "replacement ";

// A label's line label and round: "L replacement 2" -> {"L", 2}; a label of no replacement -> {label, 0}.
std::pair<std::string, int> split_replacement_label(const std::string& label) {
    const std::size_t at = label.rfind(kReplacementWord);
    if (at == std::string::npos || (at > 0 && label[at - 1] != ' ')) return {label, 0};
    const std::string digits = label.substr(at + std::string(kReplacementWord).size());
    if (digits.empty() || digits.size() > 3 || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) return {label, 0};
    return {label.substr(0, at == 0 ? 0 : at - 1), std::stoi(digits)};
}
}  // namespace

std::string replacement_label(const std::string& label, int round) {
    return label + (label.empty() ? "" : " ") + kReplacementWord + std::to_string(round);
}

bool replaces_failed_runs(const orchestrator::ShearCampaignSpec& later, const orchestrator::ShearCampaignSpec& earlier) {
    const auto [line_label, round] = split_replacement_label(earlier.label);
    return later.label == replacement_label(line_label, round + 1) && later.material == earlier.material &&
           later.normal_stresses == earlier.normal_stresses && later.replicates == earlier.replicates &&
           later.base_seed == earlier.base_seed + earlier.replicates && later.engine == earlier.engine &&
           later.template_path == earlier.template_path;
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
            spec.label = replacement_label(label, round);
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
