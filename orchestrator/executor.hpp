// Executors run jobs (a command in a directory) and report how each ended. The campaign decides what a job is and
// what to do with its outcome; an executor only runs processes: a local pool (LocalExecutor) or SLURM job arrays
// (SlurmExecutor). Both pull jobs from a callback, so the campaign can re-queue a retry while others still run.
#pragma once
#include "orchestrator/stop_signals.hpp"

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace demcal::orchestrator {

// 4 GiB: a checkpoint of several million grains fits, a log that grows without end does not.
inline constexpr std::uintmax_t kMaxJobFileBytes = std::uintmax_t{4} << 30;
// A job stopped for passing its file-size limit: the cause recorded for it (a run that did it once does it again).
inline constexpr const char* kOutputLimitCause = "output_limit";

struct Job {
    std::string id;                   // the run's identity
    std::filesystem::path dir;        // working directory; stdout.log and stderr.log are written there
    std::vector<std::string> argv;    // command, run in `dir`
    double timeout_s = 3600;          // wall-clock limit: terminate, then kill after the grace period
    // the largest file the job may write (RLIMIT_FSIZE, `ulimit -f` on SLURM): a simulator whose output runs away
    // (a print in a loop) stops there instead of filling the disk
    std::uintmax_t max_file_bytes = kMaxJobFileBytes;
};

struct JobOutcome {
    int exit_code = -1;               // -1 when killed by a signal
    int term_signal = 0;
    bool timed_out = false;
    bool interrupted = false;         // stopped because the campaign was interrupted (Ctrl-C / SIGTERM)
    double wall_s = 0, cpu_s = 0;
    std::string failure_cause;        // from a `DEMCAL_FAILURE cause: message` line on stderr, if any
    std::string message;              // that line's message, or the last line of stderr
    bool succeeded() const { return exit_code == 0 && !timed_out && !interrupted; }
};

struct ExecutorEvents {
    std::function<void(const Job&, long handle)> started;            // handle: process group or SLURM job id
    std::function<void(const Job&, const JobOutcome&)> finished;
};

using JobSource = std::function<std::optional<Job>()>;  // next job to start, or none for now

class Executor {
public:
    virtual ~Executor() = default;
    virtual std::string name() const = 0;
    // Runs jobs until the source is empty and nothing runs, or until interrupted(); then every running job is
    // stopped and reported with interrupted = true.
    virtual void run(const JobSource& next_job, const ExecutorEvents& events) = 0;
};

// The program `name` (no '/') as a shell finds it on PATH: the first regular file with execute permission (an empty
// or "." entry is the current folder), made absolute; nullopt when there is none.
std::optional<std::filesystem::path> find_program_on_path(const std::string& name);

// Set by SIGINT/SIGTERM while an InterruptGuard lives; executors poll it.
bool interrupted();
void request_interrupt();
// Guards nest: only the outermost clears the flag, so that a signal caught by an outer guard (a command's, around its
// campaign and report) is not lost when an executor's own guard begins.
class InterruptGuard {
public:
    InterruptGuard();  // clears the flag (outermost guard) and installs the handlers of the stop signals (stop_signals.hpp)
    ~InterruptGuard();  // (the previous handlers are put back when it ends)
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;

private:
    StopSignalHandlers handlers_;
};

// Reads the tail of a job's stderr.log for the failure cause and message.
void read_failure_from_stderr(const std::filesystem::path& stderr_log, JobOutcome& out);

// After a job ended: when it was stopped for writing a file past job.max_file_bytes (SIGXFSZ, or a shell's exit code
// 128 + SIGXFSZ with such a file in its folder), the outcome says so (cause kOutputLimitCause) and each of its logs
// that reached the limit is cut to its last 64 KiB, so that a failed run does not keep gigabytes of repeated lines.
void note_file_size_limit(const Job& job, JobOutcome& out);

class LocalExecutor : public Executor {
public:
    explicit LocalExecutor(int slots, double kill_grace_s = 5.0);
    std::string name() const override { return "local"; }
    void run(const JobSource& next_job, const ExecutorEvents& events) override;

private:
    int slots_;
    double kill_grace_s_;
};

// True if a process group still has a member whose working directory is `dir` (a job left by a dead orchestrator).
bool process_group_runs_in(long pgid, const std::filesystem::path& dir);
// Kills such a left-over process group (SIGKILL) after checking it still belongs to `dir`.
void kill_stale_process_group(long pgid, const std::filesystem::path& dir);

}  // namespace demcal::orchestrator
