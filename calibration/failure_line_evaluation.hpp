// From shear runs to failure lines: the bridge between the orchestrator (which only runs and stores) and the
// analytics (which only fits). Used by `demcal shear` and by the calibration loop.
#pragma once
#include "analytics/failure_line.hpp"
#include "orchestrator/shear_campaign.hpp"

#include <optional>

namespace demcal::calibration {

struct FailureLineEvaluation {
    std::optional<analytics::FailureLine> peak;      // fitted to the peak shear stresses; none if < 3 runs done
    std::optional<analytics::FailureLine> residual;  // fitted to the residual (steady) shear stresses
    int simulations_run = 0;                         // computed by this evaluation
    int simulations_reused = 0;                      // found in the store
    int simulations_failed = 0;
    double cpu_s = 0;                                // CPU seconds of the runs behind the fit
    int replacement_rounds = 0;                      // rounds of fresh packings added after failed runs
    orchestrator::ShearCampaignOutcome outcome;      // (with replacement rounds: every round's runs, in order)
};

// The runs of `more` after those of `first`, the counts summed: one line's packings over several campaigns.
orchestrator::ShearCampaignOutcome merged_outcome(orchestrator::ShearCampaignOutcome first,
                                                  const orchestrator::ShearCampaignOutcome& more);

// Fits both failure lines to the finished runs of a campaign outcome (failed runs are left out, and counted).
FailureLineEvaluation failure_lines_of(const orchestrator::ShearCampaignOutcome& outcome);

// Runs (or reuses) the campaign and fits its failure lines.
FailureLineEvaluation evaluate_failure_line(orchestrator::ShearCampaignRunner& runner,
                                            const orchestrator::ShearCampaignSpec& spec,
                                            const orchestrator::ProgressCallback& progress = {});

}  // namespace demcal::calibration
