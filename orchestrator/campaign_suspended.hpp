// A campaign that stopped before its end for a reason a later run of the same command removes: a stop signal (Ctrl-C,
// SIGTERM, SIGHUP) or a simulator that could not be started. Every finished run is stored. Every command that runs a
// campaign ends such a stop with exit status 75 (EX_TEMPFAIL of sysexits.h: "try again later"), whatever the campaign
// (shear, crosscheck, sensitivity, calibrate, scale, the silo campaigns), so that a script or a batch system tells
// "resume it" from "it failed" (1) and "bad input" (2) by one number.
#pragma once
#include <stdexcept>

namespace demcal::orchestrator {

inline constexpr int kExitCampaignSuspended = 75;

/// Thrown by code below the command (a calibration's evaluator, say) that finds its campaign suspended; the command's
/// entry point turns it into exit status kExitCampaignSuspended with its message.
struct CampaignSuspended : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace demcal::orchestrator
