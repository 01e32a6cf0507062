#include "orchestrator/stop_signals.hpp"

namespace demcal::orchestrator {

std::string stop_signal_name(int sig) {
    switch (sig) {
        case SIGINT: return "SIGINT";
        case SIGTERM: return "SIGTERM";
        case SIGHUP: return "SIGHUP";
        default: return "signal " + std::to_string(sig);
    }
}

StopSignalHandlers::StopSignalHandlers(void (*handler)(int), int flags) {
    for (std::size_t i = 0; i < std::size(kStopSignals); ++i) {
        struct sigaction sa {};
        sa.sa_handler = handler;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = flags;
        ::sigaction(kStopSignals[i], &sa, &previous_[i]);
        if (previous_[i].sa_handler == SIG_IGN) ::sigaction(kStopSignals[i], &previous_[i], nullptr);
    }
}

StopSignalHandlers::~StopSignalHandlers() {
    for (std::size_t i = 0; i < std::size(kStopSignals); ++i) ::sigaction(kStopSignals[i], &previous_[i], nullptr);
}

}  // namespace demcal::orchestrator
