// Each demcal subcommand lives in its own cmd_*.cpp and registers itself on the CLI11 app here.
// A subcommand's callback throws demcal::UserError for bad input it finds itself, and lets the libraries'
// std::invalid_argument through; main() prints either on one line and exits 2.
#pragma once
#include "orchestrator/campaign_suspended.hpp"

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>

namespace demcal {

// Bad input from the user: the message names the field (or line/column) and the offending value.
struct UserError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Exit status of a command that stopped for a reason outside the input (a stop signal, a simulator that could not be
// started): run the same command, or `demcal resume`, once it is fixed (orchestrator/campaign_suspended.hpp).
inline constexpr int kExitResumeLater = orchestrator::kExitCampaignSuspended;

// Exit status of a silo run that ended but could not write its results (a full disk; EX_IOERR of sysexits.h): not
// the run's failure. A campaign does not mark such a run failed: it stops, and the same command runs it again.
inline constexpr int kExitResultsNotWritten = 74;

void add_shear_commands(CLI::App& app);        // shear, status, resume            (cmd_shear.cpp)
void add_shear_run_command(CLI::App& app);     // shear-run (one kernel shear box)   (cmd_shear_run.cpp)
void add_crosscheck_command(CLI::App& app);    // crosscheck shear, crosscheck silo   (cmd_crosscheck.cpp)
void add_crosscheck_silo_subcommand(CLI::App& crosscheck);  // crosscheck silo     (cmd_crosscheck_silo.cpp)
void add_silo_command(CLI::App& app);          // silo                              (cmd_silo.cpp)
void add_cutoff_command(CLI::App& app);        // cutoff                            (cmd_cutoff.cpp)
void add_vibration_command(CLI::App& app);     // vibration                         (cmd_vibration.cpp)
void add_discharge_commands(CLI::App& app);    // predict, diagnose                 (cmd_diagnose.cpp)
void add_calibration_commands(CLI::App& app);  // sensitivity, calibrate, enlarge   (cmd_calibrate.cpp)
void add_scale_command(CLI::App& app);         // scale                             (cmd_scale.cpp)

}  // namespace demcal
