#include "orchestrator/executor.hpp"

#include <chrono>
#include <cstdio>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iterator>
#include <signal.h>
#include <stdexcept>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <cstdlib>

namespace demcal::orchestrator {

namespace {
std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt_signal(int) { g_interrupted.store(true); }

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

std::optional<std::filesystem::path> find_program_on_path(const std::string& name) {
    const char* path = std::getenv("PATH");
    if (!path) return std::nullopt;
    const std::string p = path;
    for (std::size_t a = 0; a <= p.size();) {
        std::size_t b = p.find(':', a);
        if (b == std::string::npos) b = p.size();
        const std::filesystem::path candidate = std::filesystem::path(p.substr(a, b - a)) / name;
        std::error_code ec;  // (a folder of that name is no program: access(X_OK) alone took one)
        if (std::filesystem::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0)
            return std::filesystem::absolute(candidate);
        a = b + 1;
    }
    return std::nullopt;
}

bool interrupted() { return g_interrupted.load(); }
void request_interrupt() { g_interrupted.store(true); }

int g_guard_depth = 0;  // InterruptGuards alive (nested on one thread: a command's around its executor's)

// (the flag cleared before the handlers are installed: a signal that comes in between is kept)
InterruptGuard::InterruptGuard()
    : handlers_((g_guard_depth++ == 0 ? g_interrupted.store(false) : void(), on_interrupt_signal)) {}

InterruptGuard::~InterruptGuard() { --g_guard_depth; }

void read_failure_from_stderr(const std::filesystem::path& stderr_log, JobOutcome& out) {
    std::ifstream f(stderr_log, std::ios::binary);
    if (!f) return;
    f.seekg(0, std::ios::end);
    const std::streamoff size = f.tellg();
    const std::streamoff from = size > 16384 ? size - 16384 : 0;
    f.seekg(from);
    std::string line, last;
    while (std::getline(f, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const auto pos = line.find("DEMCAL_FAILURE ");
        if (pos != std::string::npos) {
            const std::string rest = line.substr(pos + 15);
            const auto colon = rest.find(':');
            out.failure_cause = rest.substr(0, colon);
            out.message = colon == std::string::npos ? rest : rest.substr(colon + 1 + (rest.size() > colon + 1 && rest[colon + 1] == ' '));
            return;
        }
        if (line.find_first_not_of(" \t") != std::string::npos) last = line;
    }
    out.message = last;
}

namespace {

// Keeps the last `keep` bytes of a log that passed its limit, under a first line that says what was dropped.
void cut_runaway_log(const std::filesystem::path& log, std::uintmax_t size, std::uintmax_t limit) {
    constexpr std::uintmax_t keep = 64 * 1024;
    std::ifstream in(log, std::ios::binary);
    if (!in) return;
    in.seekg(static_cast<std::streamoff>(size > keep ? size - keep : 0));
    std::string tail((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    const std::filesystem::path cut = log.string() + ".cut";
    {
        std::ofstream out(cut, std::ios::binary | std::ios::trunc);
        out << "[demcal: this log passed the limit of " << limit << " bytes per file and the run was stopped; its first "
            << (size - tail.size()) << " bytes were dropped]\n"
            << tail;
        if (!out) return;
    }
    std::error_code ec;
    std::filesystem::rename(cut, log, ec);
}

}  // namespace

void note_file_size_limit(const Job& job, JobOutcome& out) {
    const bool killed_by_limit = out.term_signal == SIGXFSZ;
    if (!killed_by_limit && out.exit_code != 128 + SIGXFSZ) return;
    std::error_code ec;
    std::string largest;
    for (std::filesystem::directory_iterator it(job.dir, ec), end; !ec && it != end; it.increment(ec)) {
        std::error_code size_ec;
        if (!it->is_regular_file(size_ec)) continue;
        const std::uintmax_t size = it->file_size(size_ec);
        if (size_ec || size < job.max_file_bytes) continue;
        largest = it->path().filename().string();
        if (it->path().extension() == ".log") cut_runaway_log(it->path(), size, job.max_file_bytes);
    }
    if (largest.empty() && !killed_by_limit) return;  // a shell's exit code 153 of its own
    out.failure_cause = kOutputLimitCause;
    out.message = "stopped for writing a file past the limit of " + std::to_string(job.max_file_bytes) +
                  " bytes per file" + (largest.empty() ? std::string() : " (" + largest + ")") +
                  ": its output ran away";
}

bool process_group_runs_in(long pgid, const std::filesystem::path& dir) {
    if (pgid <= 0 || ::kill(-static_cast<pid_t>(pgid), 0) != 0) return false;
    std::error_code ec;
    // The group leader is the job's first process; its working directory tells whether it is still ours.
    const auto cwd = std::filesystem::read_symlink("/proc/" + std::to_string(pgid) + "/cwd", ec);
    return !ec && std::filesystem::equivalent(cwd, dir, ec);
}

void kill_stale_process_group(long pgid, const std::filesystem::path& dir) {
    if (process_group_runs_in(pgid, dir)) ::kill(-static_cast<pid_t>(pgid), SIGKILL);
}

LocalExecutor::LocalExecutor(int slots, double kill_grace_s) : slots_(slots), kill_grace_s_(kill_grace_s) {
    if (slots < 1) throw std::invalid_argument("jobs = " + std::to_string(slots) + " must be at least 1");
}

namespace {

struct Running {
    Job job;
    pid_t pid;
    std::chrono::steady_clock::time_point started;
    bool terminating = false;
    std::chrono::steady_clock::time_point term_sent;
    bool timed_out = false;
    bool interrupted = false;
};

pid_t spawn(const Job& job) {
    std::filesystem::create_directories(job.dir);
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
    if (pid == 0) {
        ::setpgid(0, 0);  // own process group: Ctrl-C on the terminal reaches the orchestrator only, which decides
        ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // an orchestrator killed with -9 takes its jobs with it
        if (::getppid() != parent) ::_exit(126);
        sigset_t none;
        sigemptyset(&none);
        ::sigprocmask(SIG_SETMASK, &none, nullptr);
        ::signal(SIGINT, SIG_DFL);
        ::signal(SIGTERM, SIG_DFL);
        if (::chdir(job.dir.c_str()) != 0) ::_exit(126);
        struct rlimit file_size {};
        if (::getrlimit(RLIMIT_FSIZE, &file_size) == 0 && file_size.rlim_cur > job.max_file_bytes) {
            file_size.rlim_cur = static_cast<rlim_t>(job.max_file_bytes);
            ::setrlimit(RLIMIT_FSIZE, &file_size);
        }
        const int out = ::open("stdout.log", O_WRONLY | O_CREAT | O_APPEND, 0644);
        const int err = ::open("stderr.log", O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (out < 0 || err < 0) ::_exit(126);
        ::dup2(out, 1);
        ::dup2(err, 2);
        const int devnull = ::open("/dev/null", O_RDONLY);
        if (devnull >= 0) ::dup2(devnull, 0);
        std::vector<char*> argv;
        for (const auto& a : job.argv) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execvp(argv[0], argv.data());
        const std::string m = "DEMCAL_FAILURE exec: cannot start '" + job.argv[0] + "': " + std::strerror(errno) + "\n";
        (void)!::write(2, m.data(), m.size());
        ::_exit(127);
    }
    ::setpgid(pid, pid);  // also from the parent, so the group exists before we might signal it
    return pid;
}

}  // namespace

void LocalExecutor::run(const JobSource& next_job, const ExecutorEvents& events) {
    std::vector<Running> running;
    while (true) {
        const bool stop = interrupted();
        // Start jobs while there are free slots; the source is asked again each round since a finished job's
        // callback may have queued a retry.
        while (!stop && static_cast<int>(running.size()) < slots_) {
            auto job = next_job();
            if (!job) break;
            Running r{*job, spawn(*job), std::chrono::steady_clock::now(), false, {}, false, false};
            running.push_back(r);
            if (events.started) events.started(r.job, r.pid);
        }
        if (running.empty()) return;
        // Reap, time out, interrupt.
        for (std::size_t i = 0; i < running.size();) {
            Running& r = running[i];
            int status = 0;
            struct rusage ru {};
            const pid_t w = ::wait4(r.pid, &status, WNOHANG, &ru);
            if (w == r.pid) {
                ::kill(-r.pid, SIGKILL);  // anything the job left behind in its group
                JobOutcome o;
                o.wall_s = seconds_since(r.started);
                o.cpu_s = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
                if (WIFEXITED(status)) o.exit_code = WEXITSTATUS(status);
                if (WIFSIGNALED(status)) o.term_signal = WTERMSIG(status);
                o.timed_out = r.timed_out;
                o.interrupted = r.interrupted;
                read_failure_from_stderr(r.job.dir / "stderr.log", o);
                note_file_size_limit(r.job, o);
                if (o.timed_out) {
                    o.failure_cause = "timeout";
                    char buf[64];
                    std::snprintf(buf, sizeof buf, "killed after the timeout of %g s", r.job.timeout_s);
                    o.message = buf;
                } else if (o.interrupted) {
                    o.failure_cause = "interrupted";
                    o.message = "stopped by the user";
                } else if (o.term_signal && o.failure_cause != kOutputLimitCause) {
                    o.failure_cause = "signal";
                    o.message = std::string("killed by signal ") + ::strsignal(o.term_signal);
                }
                Job finished_job = r.job;
                running.erase(running.begin() + static_cast<long>(i));
                if (events.finished) events.finished(finished_job, o);
                continue;
            }
            const double age = seconds_since(r.started);
            if (!r.terminating && (stop || age > r.job.timeout_s)) {
                r.timed_out = !stop;
                r.interrupted = stop;
                r.terminating = true;
                r.term_sent = std::chrono::steady_clock::now();
                ::kill(-r.pid, SIGTERM);
            } else if (r.terminating && seconds_since(r.term_sent) > kill_grace_s_) {
                ::kill(-r.pid, SIGKILL);
            }
            ++i;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
}

}  // namespace demcal::orchestrator
