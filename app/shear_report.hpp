// What the shear commands print while campaigns run and when a failure line is fitted (shear, resume, crosscheck).
#pragma once
#include "analytics/failure_line.hpp"
#include "orchestrator/shear_campaign.hpp"

namespace demcal {

// One line per finished run (started runs are not printed: an overnight log stays readable).
void print_progress(const orchestrator::CampaignProgress& p);
// A failure line with its standard errors, intervals and lack-of-fit test.
void print_line(const char* title, const analytics::FailureLine& fl);

}  // namespace demcal
