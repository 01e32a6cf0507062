// The signals that ask a demcal command to stop and keep what it has (a silo run's checkpoint, a campaign's finished
// runs, its running ones stopped and recorded): SIGINT (Ctrl-C), SIGTERM (kill, scancel, a batch system's time limit)
// and SIGHUP (the terminal or the ssh session closed under an overnight campaign started without nohup). One list,
// so that every command stops on the same signals.
#pragma once
#include <csignal>
#include <iterator>
#include <string>

namespace demcal::orchestrator {

inline constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

/// "SIGINT", "SIGTERM", "SIGHUP", or "signal N".
std::string stop_signal_name(int sig);

/// Installs `handler` for every stop signal for its lifetime, then puts the previous handlers back. A signal ignored
/// when it starts stays ignored, as POSIX tools do: SIGINT of a job a script started with `&`, SIGHUP under nohup
/// (whose promise is that a hang-up does not stop the command). `flags`: sigaction's (SA_RESETHAND: a second signal
/// takes the default action and ends the process at once).
class StopSignalHandlers {
public:
    explicit StopSignalHandlers(void (*handler)(int), int flags = 0);
    ~StopSignalHandlers();
    StopSignalHandlers(const StopSignalHandlers&) = delete;
    StopSignalHandlers& operator=(const StopSignalHandlers&) = delete;

private:
    struct sigaction previous_[std::size(kStopSignals)] {};
};

}  // namespace demcal::orchestrator
