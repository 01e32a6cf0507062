// Options of every command that runs campaigns (shear, resume, sensitivity, calibrate, enlarge): how runs execute.
#pragma once
#include "orchestrator/shear_campaign.hpp"

#include <CLI/CLI.hpp>

namespace demcal {

void add_execution_options(CLI::App* cmd, orchestrator::ExecutionOptions& e);

}  // namespace demcal
