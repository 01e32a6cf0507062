// Runs jobs as SLURM job arrays (for campaigns larger than one machine). Each batch of jobs that the campaign has
// ready becomes one `sbatch --array=0-N%slots`; every array task runs its job's run.sh in the job's directory, which
// leaves an `exit_status` file (exit code, start, end, CPU seconds). The executor polls those files and `squeue` for
// tasks that SLURM ended without one (timeout, cancel, node failure). Needs sbatch/squeue/scancel on PATH.
#pragma once
#include "orchestrator/campaign_store.hpp"
#include "orchestrator/executor.hpp"

#include <memory>
#include <optional>
#include <string>

namespace demcal::orchestrator {

class SlurmExecutor : public Executor {
public:
    // slots: array tasks running at once (the %N throttle); work_dir: where batch scripts and task lists go.
    SlurmExecutor(int slots, std::filesystem::path work_dir, std::string partition = {});
    std::string name() const override { return "slurm"; }
    void run(const JobSource& next_job, const ExecutorEvents& events) override;

    // The handle reported to `started` encodes the array job and task: job_id * kTaskBase + task.
    static constexpr long kTaskBase = 100000;

private:
    int slots_;
    long max_array_size_ = 1001;  // the cluster's MaxArraySize: larger batches go as several arrays
    std::filesystem::path work_dir_;
    std::string partition_;
    int batches_ = 0;
};

// Whether SLURM's sbatch is a program on PATH: checked where `--executor slurm` is read, before anything is written.
bool sbatch_on_path();

// What the executor reads from SLURM's output (pure functions, tested without a cluster):
// the job id `sbatch --parsable` printed among any warnings, or nothing;
std::optional<long> parse_sbatch_job_id(const std::string& output);
// MaxArraySize from `scontrol show config` (SLURM's default, 1001, where it is missing or not a number);
constexpr long kSlurmDefaultMaxArraySize = 1001;
long parse_max_array_size(const std::string& config);
// whether a task that left no exit status is gone for good: not listed by a squeue that answered, for longer than
// kTaskVanishedAfterS since it was last listed (longer than a poll's hiccup, far shorter than MinJobAge's default 300)
constexpr double kTaskVanishedAfterS = 120;
bool task_vanished(bool listed_now, double seconds_since_listed);

// Why `partition` cannot be a SLURM partition for --partition, or "" when it can: one name or a comma-separated list
// of names of letters, digits, '_', '-' and '.' (it goes into the batch script's #SBATCH line: a newline in it
// would have added a line of shell to the script).
std::string slurm_partition_defect(const std::string& partition);

// The executor a campaign asked for by name: "local" (LocalExecutor, `slots` processes) or "slurm" (SlurmExecutor,
// `slots` array tasks at once, its batch files in `work_dir`, on `partition` or the default one). Throws
// std::invalid_argument naming any other.
std::unique_ptr<Executor> make_executor(const std::string& kind, int slots, const std::filesystem::path& work_dir,
                                        const std::string& partition = {});

// On resume: cancels the SLURM array task (a handle reported to `started`) that a dead orchestrator left behind.
void cancel_stale_slurm_task(long handle);

}  // namespace demcal::orchestrator
