// Options and session shared by the commands that evaluate failure lines over stored campaigns (sensitivity,
// calibrate, scale): the normal stresses, packings, engine, campaign directory and execution options, checked before
// anything is written, and one campaign runner per command.
#pragma once
#include "app/execution_options.hpp"
#include "calibration/campaign_evaluator.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace demcal {

struct CampaignCli {
    std::vector<double> normal_stresses{2e3, 4e3, 6e3};
    int replicates = 1;
    long seed = 1;
    std::string engine = "yade";
    std::string campaign_dir = "campaigns/calibration";
    std::string template_path;
    std::string line = "peak";
    std::string plot_format = "png";
    orchestrator::ExecutionOptions exec;
};

void add_campaign_options(CLI::App* cmd, CampaignCli& c);

// "name=low:high" items (repeatable option) -> map; throws UserError naming `option` and the item.
std::map<std::string, std::pair<double, double>> parse_ranges(const std::vector<std::string>& items,
                                                              const std::string& option);

calibration::CampaignSettings settings_of(const CampaignCli& c, const std::string& label);

// The campaign every failure line will run (stresses, replicates, seeds, engine, template), checked on `material`
// before the campaign directory exists (a --template is YADE's: refused with --engine kernel).
void check_campaign(const CampaignCli& c, const nlohmann::json& material);

// "12 s", "3.4 min", "1.2 h": a total CPU time in a summary line.
std::string cpu_duration(double seconds);
// "CPU 2.0 min" of a command's runs, "(the N reused runs' own included)" when some were reused: their CPU was spent
// by the command that computed them (probe 62: "CPU 2 s" beside "0 simulations run").
std::string runs_cpu_text(double cpu_seconds, int reused_runs);

// Runs in a campaign directory with one runner for all the evaluations of a command.
struct CampaignSession {
    std::unique_ptr<orchestrator::ShearCampaignRunner> runner;
    calibration::FailureLineEvaluator evaluate;
    CampaignSession(const CampaignCli& c, const std::string& label);
};

}  // namespace demcal
