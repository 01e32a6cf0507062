// The calibration's evaluator over shear campaigns (YADE or the kernel engine): each material becomes one campaign of the orchestrator
// (stored, cached by run hash, resumable), always at the same normal stresses and packing seeds, so that every
// material of a study or a calibration sees the same packings (common random numbers).
#pragma once
#include "calibration/macro_target.hpp"
#include "orchestrator/shear_campaign.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace demcal::calibration {

struct CampaignSettings {
    std::vector<double> normal_stresses;   // [Pa], the same for every material
    int replicates = 1;                    // packings per stress (seeds base_seed, base_seed + 1, ...)
    long base_seed = 1;                    // fixed: common random numbers across materials
    std::filesystem::path template_path;   // empty: the installed yade_scripts/shear_box.py
    std::string label;                     // campaign label prefix, e.g. "sensitivity" or "calibrate"
    orchestrator::ShearEngine engine = orchestrator::ShearEngine::yade;  // which engine runs the boxes

    // The campaign of one failure line of `material`.
    orchestrator::ShearCampaignSpec spec_for(const nlohmann::json& material) const;
};

// Most rounds of replacement packings for one failure line (see campaign_evaluator).
inline constexpr int kMaxReplacementRounds = 2;

// The label of round `round` (1, 2, ...) of the fresh packings that replace a line's failed runs, for a line
// labelled `label` ("scale r=0.004" -> "scale r=0.004 replacement 1").
std::string replacement_label(const std::string& label, int round);

// Whether campaign `later` holds the fresh packings that replaced the failed runs of `earlier` (the next round of
// campaign_evaluator): the same material, stresses, replicates, engine and template, the seeds after earlier's, and
// the next round's label. Such failures are not the line's: the study fitted it over both campaigns' runs.
bool replaces_failed_runs(const orchestrator::ShearCampaignSpec& later, const orchestrator::ShearCampaignSpec& earlier);

// Evaluates materials through `runner` (which must outlive the evaluator). A run that fails for a physical reason
// (a packing the lid servo cannot hold, say) fails again whenever it is rerun, so a line left with too few runs to fit
// would stop a study or a calibration for good, resumed or not: such a line gets up to kMaxReplacementRounds rounds of
// fresh packings (the same stresses and replicate count, seeds after the ones already used), a campaign each, and is
// fitted to every run that finished (FailureLineEvaluation::replacement_rounds says how many rounds it took). Which
// rounds run follows from the stored runs alone, so a resumed study makes the same choice. Throws std::runtime_error
// when the campaign was interrupted (Ctrl-C: run the command again to resume) or when the simulator cannot start.
FailureLineEvaluator campaign_evaluator(orchestrator::ShearCampaignRunner& runner, CampaignSettings settings,
                                        orchestrator::ProgressCallback progress = {});

}  // namespace demcal::calibration
