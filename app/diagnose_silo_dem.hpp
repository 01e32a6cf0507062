// demcal diagnose --model silo-dem: measured silo discharge rates against the kernel's silo with a declared material,
// the residuals traced to a DEM effect the material lacks (analytics/dem_diagnosis.hpp has the method). The kernel's
// predictions are a resumable campaign of `demcal silo` runs (app/silo_campaign.hpp) in DIR/runs/, one per material,
// condition and seed; a run's material lives in DIR/materials/<sha256>.json and names the run, so a value proposed
// twice, by two candidates or by a second diagnosis of other data with the same settings, runs once.
#pragma once
#include <string>
#include <vector>

namespace demcal {

struct SiloDemArgs {
    std::string data, material, campaign, json_out, report_out;
    int jobs = 1;             // runs at once (processes here, or SLURM array tasks)
    std::string executor = "local", partition;  // local | slurm (app/silo_campaign.hpp), SLURM partition
    int seeds = 1;            // prediction seeds per condition and material
    long long first_seed = 1;
    int grid_points = 5, refine_steps = 3;
    long max_runs = 10000;    // most kernel runs the plan may hold (a guard against typos), refused before any run
    double alpha = 0.01, min_cv_gain = 0.05;
    bool no_plots = false;
    std::vector<std::string> silo_args;  // after --: options of every demcal silo run
    std::vector<std::string> candidates;  // names of the DEM effects to try (empty: every row of the table)
};

// Checks every input and output before any run; returns the exit status (0, or 75 when stopped: run again).
int run_silo_dem_diagnosis(const SiloDemArgs& args);

// The folder a campaign lives in by default: silo_dem_<data file's stem>.
std::string default_silo_dem_campaign(const std::string& data_path);

}  // namespace demcal
