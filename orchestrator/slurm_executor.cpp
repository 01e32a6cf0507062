#include "orchestrator/slurm_executor.hpp"
#include "orchestrator/campaign_suspended.hpp"

#include "analytics/number_text.hpp"
#include "orchestrator/run_identity.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace demcal::orchestrator {

namespace fs = std::filesystem;

namespace {

std::string shell_quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// Runs a command and returns its stdout; throws with the command's stderr on a non-zero exit.
std::string capture(const std::string& cmd, int* exit_code = nullptr) {
    std::array<char, 4096> buf{};
    std::string out;
    FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
    if (!p) throw std::runtime_error("cannot run: " + cmd);
    while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
    const int status = ::pclose(p);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (exit_code) {
        *exit_code = code;
    } else if (code != 0) {
        std::string said = out;  // (its final newline would end the one-line message early)
        while (!said.empty() && std::isspace(static_cast<unsigned char>(said.back()))) said.pop_back();
        throw std::runtime_error("'" + cmd + "' failed (exit " + std::to_string(code) + "): " + said);
    }
    return out;
}

struct Task {
    Job job;
    long array_id;
    int index;
    std::chrono::steady_clock::time_point submitted;
    std::chrono::steady_clock::time_point last_listed;  // when squeue last listed it (or its submission)
    bool cancel_sent = false;
};

// How long a stopped campaign waits for SLURM to confirm that a cancelled task ended (a silo task writes its
// checkpoint first) before it leaves the task to SLURM and stops: with the controller gone, squeue never confirms and
// Ctrl-C or SIGTERM went unheeded (probe 60: 11 minutes, until kill -9).
constexpr double kCancelGraceS = 30;
// How long squeue may fail without a break before the campaign stops for a resume (exit 75) instead of waiting on.
constexpr double kControllerLostAfterS = 600;

// A cancelled task SLURM did not confirm ending within kCancelGraceS: its run goes back to pending, for a resume.
JobOutcome outcome_of_unconfirmed_cancel(const Task& t, std::chrono::steady_clock::time_point now) {
    JobOutcome o;
    o.exit_code = -1;
    o.interrupted = true;
    o.failure_cause = "interrupted";
    o.message = "SLURM did not confirm within " + std::to_string(static_cast<int>(kCancelGraceS)) +
                " s that cancelled array task " + std::to_string(t.array_id) + "_" + std::to_string(t.index) +
                " ended; it is left to SLURM";
    o.wall_s = std::chrono::duration<double>(now - t.submitted).count();
    return o;
}

// run.sh: the job's command with its logs, then one line: exit code, start and end (epoch s), CPU seconds.
void write_task_script(const Job& job) {
    std::ostringstream s;
    s << "#!/bin/bash\n# Written by demcal's SLURM executor: runs this job, then records how it ended.\n"
      << "cd " << shell_quote(job.dir.string()) << " || exit 1\nrm -f exit_status\n"
      // the job's file-size limit in 1024-byte blocks (the soft limit only: a hard limit below it stays)
      << "ulimit -S -f " << job.max_file_bytes / 1024 << " 2>/dev/null\nstart=$(date +%s.%N)\n";
    for (const auto& a : job.argv) s << shell_quote(a) << ' ';
    s << ">>stdout.log 2>>stderr.log </dev/null\ncode=$?\nend=$(date +%s.%N)\n"
      // `times` in this shell, not in $(...): a subshell's children times start at zero.
      << "times >times.txt\n"
      << "cpu=$(tail -n 1 times.txt | awk '{split($1,u,/[ms]/); split($2,v,/[ms]/); print u[1]*60+u[2]+v[1]*60+v[2]}')\n"
      << "echo \"$code $start $end $cpu\" > exit_status.tmp && mv exit_status.tmp exit_status\nexit $code\n";
    write_text_file_atomically(job.dir / "run.sh", s.str());
    fs::permissions(job.dir / "run.sh", fs::perms::owner_all | fs::perms::group_read | fs::perms::others_read);
    // a previous attempt's record (it may have appeared after that attempt was given up) is not this attempt's: the
    // task's own `rm -f` comes only when it starts, and the poll would read the old file while this one waits
    std::error_code ec;
    fs::remove(job.dir / "exit_status", ec);
}

// The task's own record of how it ended (run.sh's last line, renamed into place), if it is there.
bool read_exit_status(const Job& job, JobOutcome& o) {
    std::ifstream st(job.dir / "exit_status");
    double start = 0, end = 0, cpu = 0;
    if (!(st >> o.exit_code >> start >> end >> cpu)) return false;
    o.wall_s = end - start;
    o.cpu_s = cpu;
    read_failure_from_stderr(job.dir / "stderr.log", o);
    note_file_size_limit(job, o);
    return true;
}

// Task index -> SLURM state for an array job, from `squeue -r` (one line per task; finished tasks stay listed for
// MinJobAge seconds); nothing when squeue itself failed (the controller unreachable: the tasks may still run).
std::optional<std::map<int, std::string>> array_task_states(long array_id) {
    int code = 0;
    const std::string out =
        capture("squeue -h -r -t all -j " + std::to_string(array_id) + " -o '%i %T'", &code);
    std::map<int, std::string> states;
    if (code != 0) return std::nullopt;
    std::istringstream in(out);
    std::string id, state;
    while (in >> id >> state) {
        const auto us = id.find('_');
        if (us == std::string::npos) continue;
        try {
            states[std::stoi(id.substr(us + 1))] = state;
        } catch (...) {
        }
    }
    return states;
}

bool is_terminal(const std::string& state) {
    return state != "PENDING" && state != "RUNNING" && state != "CONFIGURING" && state != "COMPLETING" &&
           state != "SUSPENDED" && state != "REQUEUED" && state != "RESIZING";
}

}  // namespace

std::optional<long> parse_sbatch_job_id(const std::string& output) {
    // `sbatch --parsable` prints "jobid" or "jobid;cluster"; warnings (stderr, merged) may come before it
    std::optional<long> id;
    std::istringstream in(output);
    std::string line;
    while (std::getline(in, line)) {
        const std::string head = line.substr(0, line.find(';'));
        if (head.empty() || head.size() > 18 || head.find_first_not_of("0123456789") != std::string::npos) continue;
        const long v = std::stol(head);
        if (v > 0) id = v;
    }
    return id;
}

long parse_max_array_size(const std::string& config) {
    // a line "MaxArraySize            = 1001" of `scontrol show config`; SLURM's default where it is not found
    std::istringstream in(config);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string key, eq, value;
        if (!(words >> key >> eq >> value) || key != "MaxArraySize" || eq != "=") continue;
        if (value.empty() || value.size() > 9 || value.find_first_not_of("0123456789") != std::string::npos) break;
        const long v = std::stol(value);
        return v >= 1 ? v : kSlurmDefaultMaxArraySize;
    }
    return kSlurmDefaultMaxArraySize;
}

std::string slurm_partition_defect(const std::string& partition) {
    if (partition.empty()) return "";  // the cluster's default partition
    if (partition.size() > 256) return "longer than 256 characters";
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = partition.find(',', start);
        const std::string name = partition.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (name.empty()) return "an empty name in the list";
        if (name.front() == '-') return "a name starts with '-'";
        for (char c : name)
            if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.')
                return "holds a character that is not a letter, a digit, '_', '-', '.' or ','";
        if (comma == std::string::npos) return "";
        start = comma + 1;
    }
}

bool task_vanished(bool listed_now, double seconds_since_listed) {
    return !listed_now && seconds_since_listed > kTaskVanishedAfterS;
}

bool sbatch_on_path() { return find_program_on_path("sbatch").has_value(); }

SlurmExecutor::SlurmExecutor(int slots, fs::path work_dir, std::string partition)
    : slots_(slots), work_dir_(std::move(work_dir)), partition_(std::move(partition)) {
    if (slots < 1) throw std::invalid_argument("jobs = " + std::to_string(slots) + " must be at least 1");
    if (const std::string defect = slurm_partition_defect(partition_); !defect.empty())
        throw std::invalid_argument("partition = '" + analytics::shortened_text(partition_, 300) + "': " + defect);
    if (!sbatch_on_path())
        throw std::invalid_argument("executor = 'slurm' but sbatch is not on PATH (install slurm-client and reach a "
                                    "SLURM controller)");
    int code = 0;
    // an array of more tasks than the cluster's MaxArraySize is refused by sbatch: larger batches are split
    const std::string config = capture("scontrol show config", &code);
    max_array_size_ = code == 0 ? parse_max_array_size(config) : kSlurmDefaultMaxArraySize;
}

namespace {

// The batch script: one array of `tasks` tasks, `slots` at once, each running the run.sh named on its line of `list`.
std::string array_script_text(const fs::path& list, std::size_t tasks, int slots, double longest_s,
                              const std::string& partition) {
    std::ostringstream s;
    s << "#!/bin/bash\n#SBATCH --job-name=demcal\n#SBATCH --output=/dev/null\n#SBATCH --cpus-per-task=1\n"
      << "#SBATCH --array=0-" << tasks - 1 << "%" << slots << "\n"
      << "#SBATCH --time=" << static_cast<long>(std::ceil(longest_s / 60.0)) << "\n"
      << (partition.empty() ? "" : "#SBATCH --partition=" + partition + "\n")
      << "exec bash \"$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" " << shell_quote(list.string()) << ")\"\n";
    return s.str();
}

// sbatch did not take a batch (the controller unreachable, a limit, a partition it does not know): a stop to resume
// once SLURM answers, not a failure of the runs.
struct SubmissionRefused : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Submits `batch` as one array (its task list and script named by `stem` in work_dir); returns its tasks.
std::vector<Task> submit_array(const std::vector<Job>& batch, const fs::path& work_dir, const std::string& stem,
                               int slots, const std::string& partition) {
    const fs::path list = work_dir / (stem + ".tasks"), script = work_dir / (stem + ".sbatch");
    std::ostringstream l;
    double longest = 0;
    for (const auto& j : batch) {
        write_task_script(j);
        l << (j.dir / "run.sh").string() << "\n";
        longest = std::max(longest, j.timeout_s);
    }
    write_text_file_atomically(list, l.str());
    write_text_file_atomically(script, array_script_text(list, batch.size(), slots, longest, partition));
    int code = 0;
    const std::string out = capture("sbatch --parsable " + shell_quote(script.string()), &code);
    const std::optional<long> array_id = code == 0 ? parse_sbatch_job_id(out) : std::nullopt;
    if (!array_id) {  // nothing was submitted: the batch's files would only mislead
        std::error_code ec;
        fs::remove(list, ec);
        fs::remove(script, ec);
        std::string said = out;
        while (!said.empty() && std::isspace(static_cast<unsigned char>(said.back()))) said.pop_back();
        throw SubmissionRefused("sbatch " + (code == 0 ? std::string("printed no job id") : "exit " + std::to_string(code)) +
                                ": " + analytics::shortened_text(said, 300));
    }
    const auto now = std::chrono::steady_clock::now();
    std::vector<Task> tasks;
    for (std::size_t i = 0; i < batch.size(); ++i) tasks.push_back({batch[i], *array_id, static_cast<int>(i), now, now});
    return tasks;
}

// How a task ended that SLURM ended in `state` (TIMEOUT, CANCELLED, NODE_FAIL, ...) without an exit status of its own.
JobOutcome outcome_of_slurm_state(const Task& t, const std::string& state) {
    JobOutcome o;
    o.exit_code = -1;
    o.timed_out = state == "TIMEOUT";
    o.interrupted = t.cancel_sent;
    o.failure_cause = o.timed_out ? "timeout" : o.interrupted ? "interrupted" : "slurm";
    o.message = "SLURM ended the task in state " + state;
    o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t.submitted).count();
    return o;
}

// A task SLURM no longer lists and that left no exit status (the controller restarted without its state, the job
// removed by hand): waiting would never end, so it is tried again like a node failure.
JobOutcome outcome_of_vanished_task(const Task& t, std::chrono::steady_clock::time_point now) {
    JobOutcome o;
    o.exit_code = -1;
    o.interrupted = t.cancel_sent;
    o.failure_cause = o.interrupted ? "interrupted" : "slurm";
    o.message = "SLURM no longer lists array task " + std::to_string(t.array_id) + "_" + std::to_string(t.index) +
                " and it left no exit status";
    o.wall_s = std::chrono::duration<double>(now - t.submitted).count();
    return o;
}

// squeue's answer per array job, asked once per poll (nothing: squeue failed)
using ArrayStates = std::map<long, std::optional<std::map<int, std::string>>>;

// Whether task t has ended, and how (into o): its exit_status file, else SLURM's state for it.
bool poll_task(Task& t, ArrayStates& states, JobOutcome& o) {
    if (read_exit_status(t.job, o)) return true;
    if (!states.count(t.array_id)) states[t.array_id] = array_task_states(t.array_id);
    static const std::map<int, std::string> unknown;
    const auto& s = states[t.array_id] ? *states[t.array_id] : unknown;
    const auto it = s.find(t.index);
    const auto now = std::chrono::steady_clock::now();
    if (it != s.end() || !states[t.array_id]) t.last_listed = now;  // (squeue failed: no news)
    if (it != s.end() && is_terminal(it->second)) {
        // a task that ended between the file's read and SLURM's answer left its record by then: read again
        if (!read_exit_status(t.job, o)) o = outcome_of_slurm_state(t, it->second);
        return true;
    }
    if (task_vanished(it != s.end(), std::chrono::duration<double>(now - t.last_listed).count())) {
        if (!read_exit_status(t.job, o)) o = outcome_of_vanished_task(t, now);
        return true;
    }
    return false;
}

}  // namespace

void SlurmExecutor::run(const JobSource& next_job, const ExecutorEvents& events) {
    fs::create_directories(work_dir_);
    std::vector<Task> tasks;
    std::string refused;  // why sbatch did not take a batch: no further batch is submitted, the submitted ones end
    auto submit_batch = [&](const std::vector<Job>& batch) {
        const std::string stem = "batch-" + std::to_string(::getpid()) + "-" + std::to_string(batches_++);
        std::vector<Task> submitted;
        try {
            submitted = submit_array(batch, work_dir_, stem, slots_, partition_);
        } catch (const SubmissionRefused& e) {
            refused = e.what();
            return;
        }
        for (const Task& t : submitted) {
            tasks.push_back(t);
            if (events.started) events.started(t.job, t.array_id * kTaskBase + static_cast<long>(t.index));
        }
    };
    auto submit_ready_jobs = [&] {
        std::vector<Job> batch;
        while (refused.empty()) {
            auto j = next_job();
            if (!j) break;
            batch.push_back(*j);
            if (static_cast<long>(batch.size()) == std::min<long>(max_array_size_, kTaskBase)) {
                submit_batch(batch);
                batch.clear();
            }
        }
        if (!batch.empty()) submit_batch(batch);
    };

    submit_ready_jobs();
    auto controller_answered = std::chrono::steady_clock::now();
    bool controller_lost = false;
    std::optional<std::chrono::steady_clock::time_point> stopped_at;
    while (!tasks.empty()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        const bool stop = interrupted() || controller_lost;
        if (stop && !stopped_at) stopped_at = std::chrono::steady_clock::now();
        if (stop) {  // one scancel for all: each call waits on the controller (10 s apiece with it gone)
            std::string ids;
            for (Task& t : tasks)
                if (!t.cancel_sent) {
                    ids += " " + std::to_string(t.array_id) + "_" + std::to_string(t.index);
                    t.cancel_sent = true;
                }
            int code = 0;
            if (!ids.empty()) capture("scancel" + ids, &code);
        }
        const auto now = std::chrono::steady_clock::now();
        const bool grace_over = stopped_at && std::chrono::duration<double>(now - *stopped_at).count() > kCancelGraceS;
        ArrayStates states;
        for (std::size_t i = 0; i < tasks.size();) {
            Task& t = tasks[i];
            JobOutcome o;
            bool ended = false;
            if (grace_over) {  // what the task recorded, else given up: SLURM is not asked again
                if (!read_exit_status(t.job, o)) o = outcome_of_unconfirmed_cancel(t, now);
                ended = true;
            } else {
                ended = poll_task(t, states, o);
            }
            if (ended) {
                if (t.cancel_sent && !o.succeeded()) o.interrupted = true;  // (one that finished first is done)
                Job j = t.job;
                tasks.erase(tasks.begin() + static_cast<long>(i));
                if (events.finished) events.finished(j, o);
                continue;
            }
            ++i;
        }
        if (!stop) submit_ready_jobs();  // retries queued by the finished callbacks
        // squeue answered for some array this round (no array polled: no news either way)
        if (states.empty() || std::any_of(states.begin(), states.end(), [](const auto& a) { return a.second.has_value(); }))
            controller_answered = now;
        else if (std::chrono::duration<double>(now - controller_answered).count() > kControllerLostAfterS)
            controller_lost = true;
    }
    if (controller_lost)
        throw CampaignSuspended("SLURM's controller did not answer squeue for " +
                                std::to_string(static_cast<int>(kControllerLostAfterS)) +
                                " s; the runs it held go back to pending: resume once SLURM answers, or run them "
                                "with --executor local");
    // the jobs of a refused batch were never started: their runs are as they were (pending), for a resume
    if (!refused.empty())
        throw CampaignSuspended("SLURM did not take the runs (" + refused + "); the runs not submitted stay as they "
                                "were: resume once sbatch works, or run them with --executor local");
}

std::unique_ptr<Executor> make_executor(const std::string& kind, int slots, const fs::path& work_dir,
                                        const std::string& partition) {
    if (kind == "local") return std::make_unique<LocalExecutor>(slots);
    if (kind == "slurm") return std::make_unique<SlurmExecutor>(slots, work_dir, partition);
    throw std::invalid_argument("executor = '" + kind + "' is not one of: local, slurm");
}

void cancel_stale_slurm_task(long handle) {
    if (handle <= 0) return;
    const long array_id = handle / SlurmExecutor::kTaskBase, task = handle % SlurmExecutor::kTaskBase;
    int code = 0;
    capture("scancel " + std::to_string(array_id) + "_" + std::to_string(task), &code);
}

}  // namespace demcal::orchestrator
