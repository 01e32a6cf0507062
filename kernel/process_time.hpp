#pragma once
// CPU time of the whole process (all threads), for the cost figures of long runs: wall time counts the pauses of a
// shared machine, CPU time does not.
#include <ctime>

namespace demcal::kernel {

inline double process_cpu_seconds() {
    timespec ts{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace demcal::kernel
