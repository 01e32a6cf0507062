#include "app/silo_campaign.hpp"
#include "app/silo_settings.hpp"  // canonical_silo_options

#include "app/cli_support.hpp"
#include "analytics/number_text.hpp"
#include "app/commands.hpp"
#include "orchestrator/executor.hpp"
#include "orchestrator/folder_lock.hpp"
#include "orchestrator/run_identity.hpp"  // write_text_file_atomically, read_result_json
#include "orchestrator/shear_campaign.hpp"  // pinned_program
#include "orchestrator/slurm_executor.hpp"
#include "orchestrator/stop_signals.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

extern char** environ;

namespace demcal {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

volatile std::sig_atomic_t g_stop_requested = 0;
extern "C" void request_campaign_stop(int) { g_stop_requested = 1; }

// Starts this demcal with `args`, stdout and stderr appended to `log`; returns the child's pid.
pid_t spawn_demcal(const std::vector<std::string>& args, const fs::path& log) {
    std::vector<char*> argv;
    // this very binary, even when the file was replaced since it started (a rebuild during a long sweep)
    std::string self = "/proc/self/exe";
    argv.push_back(self.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    posix_spawnattr_t attr;  // the run gets the default dispositions (it checkpoints on SIGINT/SIGTERM itself)
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);  // (SIGHUP keeps its disposition: under nohup the runs ignore it too)
    posix_spawnattr_setsigdefault(&attr, &defaults);
    // its own process group: Ctrl-C reaches this process only, which sends the run one SIGTERM. In the terminal's group
    // the run got SIGINT and then the forwarded SIGTERM, and the second signal (SA_RESETHAND: "stop now") killed it
    // while it wrote its checkpoint.
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETPGROUP);
    // the run ends with this process (app/main.cpp, kDieWithParentVariable): a sweep killed with -9 left its run
    // going, which the sweep run again then found busy and marked failed (probe 60)
    std::vector<std::string> env_text;
    for (char** e = environ; *e; ++e)
        if (std::string_view(*e).rfind(std::string(kDieWithParentVariable) + "=", 0) != 0) env_text.emplace_back(*e);
    env_text.push_back(std::string(kDieWithParentVariable) + "=" + std::to_string(::getpid()));
    std::vector<char*> envp;
    for (auto& e : env_text) envp.push_back(e.data());
    envp.push_back(nullptr);
    pid_t pid = 0;
    const int err = posix_spawn(&pid, self.c_str(), &fa, &attr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&attr);
    if (err != 0) throw std::runtime_error("cannot start " + self + ": " + std::strerror(err));
    return pid;
}

int exit_status(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status); }

double cpu_of(const rusage& u) {
    return double(u.ru_utime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec) + double(u.ru_stime.tv_sec) +
           1e-6 * double(u.ru_stime.tv_usec);
}

// `demcal silo --resume DIR` with the session options of the run's own options (--threads, --no-plots, ...: the rest
// is in the checkpoint). From the plan, not the campaign's shared options: a command may add a session option to
// every plan (cutoff's --no-plots), and a resumed run without it drew plots, or failed where gnuplot is missing.
std::vector<std::string> resume_command(const SiloRunPlan& plan, const fs::path& dir) {
    std::vector<std::string> a{"silo", "--resume", dir.string()};
    const std::vector<std::string>& args = plan.silo_args;
    for (std::size_t k = 0; k < args.size(); ++k) {
        const std::string& arg = args[k];
        if (arg == "--no-plots") a.push_back(arg);
        if ((arg == "--threads" || arg == "--checkpoint-every" || arg == "--wall-limit") && k + 1 < args.size())
            a.insert(a.end(), {arg, args[k + 1]});
    }
    return a;
}

std::vector<std::string> fresh_command(const SiloRunPlan& plan, const fs::path& out, bool check) {
    std::vector<std::string> a{"silo"};
    a.insert(a.end(), plan.silo_args.begin(), plan.silo_args.end());
    a.insert(a.end(), {"--out", out.string()});
    if (check) a.push_back("--check");
    return a;
}

// The stop handlers for the lifetime of a campaign call (the previous ones put back after it), the flag cleared.
class StopHandlers {
public:
    StopHandlers() : handlers_((g_stop_requested = 0, request_campaign_stop)) {}  // (cleared, then installed)

private:
    orchestrator::StopSignalHandlers handlers_;
};

}  // namespace

std::string silo_number(double value) {
    std::ostringstream s;
    s << std::setprecision(17) << value;
    return s.str();
}

void refuse_owned_silo_options(const std::vector<std::string>& silo_args, const std::vector<std::string>& owned,
                               const std::string& command) {
    auto is = [](const std::string& a, const std::string& o) { return a == o || a.rfind(o + "=", 0) == 0; };
    for (const std::string& a : silo_args) {
        for (const std::string& o : owned)
            if (is(a, o)) throw UserError("silo option " + a + " after --: " + command + " sets it for every run");
        // one path for every run: each run wrote the same bed file over the last one's, and the second run's
        // snapshots were refused in the --vtk folder the first had filled (the campaign failed halfway)
        for (const char* o : kOneRunOutputOptions)
            if (is(a, o))
                throw UserError("silo option " + a + " after --: " + command + " would give every run the same " +
                                "output path (each run overwriting the last); run `demcal silo` with it for one run");
    }
}

namespace {

// The folder for the check's scratch runs: TMPDIR (or /tmp), tried for real, named when it cannot take them.
fs::path scratch_parent() {
    const char* env = std::getenv("TMPDIR");
    const fs::path tmp = env && *env ? fs::path(env) : fs::path("/tmp");
    std::string probe = (tmp / ".demcal-tmp-probe-XXXXXX").string();
    const int fd = ::mkstemp(probe.data());
    if (fd < 0)
        throw UserError(std::string(env && *env ? "TMPDIR" : "/tmp (TMPDIR is not set)") + " = '" +
                        analytics::shortened_text(tmp.string(), 200) + "': " + std::strerror(errno) +
                        ": the runs' settings are checked by a short run in it; set TMPDIR to a writable folder");
    ::close(fd);
    ::unlink(probe.c_str());
    return tmp;
}

}  // namespace

void check_silo_runs(const std::vector<SiloRunPlan>& plans) {
    const fs::path scratch = scratch_parent() / ("demcal-silo-check-" + std::to_string(::getpid()));
    const fs::path log = scratch.string() + ".log";
    for (const SiloRunPlan& plan : plans) {
        int status = 0;
        const pid_t pid = spawn_demcal(fresh_command(plan, scratch / plan.name, true), log);
        while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        std::ifstream is(log);
        std::stringstream text;
        text << is.rdbuf();
        is.close();
        fs::remove(log);
        if (exit_status(status) != 0) {
            // the run's own refusal, one line: without its "demcal: error: " (the caller's message has one) and its
            // closing newline (shown as a literal \n at the end of the caller's line)
            std::string why = text.str().substr(0, 500);
            constexpr std::string_view prefix = "demcal: error: ";
            if (why.rfind(prefix, 0) == 0) why.erase(0, prefix.size());
            while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
            throw UserError("run " + plan.name + ": " + why);
        }
    }
}

std::vector<std::pair<std::string, std::string>> silo_input_files(const std::vector<std::string>& silo_args) {
    std::vector<std::pair<std::string, std::string>> files;
    for (std::size_t i = 0; i < silo_args.size(); ++i)
        for (const std::string option : kSiloFileOptions) {
            if (silo_args[i] == option && i + 1 < silo_args.size())
                files.emplace_back(option, silo_args[i + 1]);
            else if (silo_args[i].rfind(option + "=", 0) == 0)
                files.emplace_back(option, silo_args[i].substr(option.size() + 1));
        }
    return files;
}

std::vector<NamedPath> silo_campaign_inputs(const std::vector<std::string>& silo_args, const fs::path& dir) {
    std::vector<NamedPath> inputs{{(dir / "campaign.json").string(), "the campaign's settings (--campaign)"}};
    for (const auto& [option, file] : silo_input_files(silo_args)) inputs.push_back({file, option + " (after --)"});
    return inputs;
}

json silo_input_file_digests(const std::vector<std::string>& silo_args) {
    json digests = json::object();
    for (const auto& [option, file] : silo_input_files(silo_args))
        digests[option] = orchestrator::sha256_hex(orchestrator::read_text_file(file));
    return digests;
}

void canonicalize_silo_args(json& settings) {
    if (!settings.is_object()) return;
    const auto args = settings.find("silo_args");
    if (args == settings.end() || !args->is_array()) return;
    std::vector<std::string> list;
    for (const auto& a : *args) {
        if (!a.is_string()) return;  // not demcal's: compared as it is
        list.push_back(a.get<std::string>());
    }
    *args = canonical_silo_options(list);
}

namespace {
// The top-level settings whose values differ between two campaign.json objects, e.g. "amplitude_m, input_files_sha256"
std::string differing_settings(const json& stored, const json& now) {
    if (!stored.is_object() || !now.is_object()) return "the whole file";
    std::set<std::string> keys;  // (sorted, each once)
    for (const auto& [key, value] : now.items())
        if (!stored.contains(key) || stored[key] != value) keys.insert(key);
    for (const auto& [key, value] : stored.items())
        if (!now.contains(key)) keys.insert(key);
    std::string text;
    for (const auto& key : keys) text += (text.empty() ? "" : ", ") + key;
    return text;
}
// The silo options that differ between two canonical "silo_args" objects, e.g. "--material given now, not before;
// --particles 300 before, 1000 now".
std::string differing_silo_options(const json& before, const json& now) {
    if (!before.is_object() || !now.is_object()) return "";
    std::string text;
    const auto add = [&](const std::string& item) { text += (text.empty() ? "" : "; ") + item; };
    for (const auto& [option, values] : now.items())
        if (!before.contains(option)) add(option + " given now, not before");
        else if (before[option] != values)
            add(option + " " + analytics::shortened_text(before[option].dump(), 80) + " before, " +
                analytics::shortened_text(values.dump(), 80) + " now");
    for (const auto& [option, values] : before.items())
        if (!now.contains(option)) add(option + " given before, not now");
    return text;
}
}  // namespace

void open_silo_campaign(const fs::path& dir, const json& settings, const std::string& command,
                        const std::vector<std::string>& may_change) {
    const fs::path settings_file = dir / "campaign.json";
    try {
        orchestrator::check_campaign_folder(dir, "campaign.json");
    } catch (const std::invalid_argument& e) {
        throw UserError(e.what());
    }
    // a shear campaign's store (or a file of its name): a sweep beside it made a folder that status and resume then
    // refused for its store, the sweep's results unreadable by them (held-back probe 65)
    if (std::error_code ec; fs::exists(fs::symlink_status(dir / "campaign.sqlite", ec)))
        throw UserError("campaign = '" + analytics::shortened_text(dir.string(), 200) +
                        "' holds campaign.sqlite (the store of shear campaigns, or a file of that name), and a " +
                        command + " sweep keeps its own campaign.json: give another --campaign");
    if (fs::exists(settings_file)) {
        json stored = read_json_file(settings_file.string(), "campaign settings"), now = settings;
        for (const std::string& key : may_change) {
            if (stored.is_object()) stored.erase(key);
            now.erase(key);
        }
        // the command that made it, where its settings say (cutoff's do; a vibration sweep's were taken for this
        // command's with other settings)
        const std::string stored_command = stored.is_object() && stored.contains("command") &&
                                                   stored["command"].is_string()
                                               ? stored["command"].get<std::string>()
                                               : "";
        if (stored_command != (now.contains("command") ? now["command"].get<std::string>() : ""))
            throw UserError("campaign = '" + dir.string() + "' holds a " +
                            (stored_command.empty() ? "campaign of another command" : stored_command + " campaign") +
                            " (" + settings_file.string() + "), not a " + command + " one: give another --campaign");
        // made before its input files' digests: it takes the files as they are now (what it ran with is not known)
        const bool without_digests = stored.is_object() && !stored.contains(kInputFileDigestsKey) &&
                                     now.contains(kInputFileDigestsKey);
        if (without_digests) now.erase(kInputFileDigestsKey);
        // in one spelling only where the files' digests are compared too: the canonical form leaves a file's path
        // out (a campaign made before the digests took another --geometry file unseen: review of stop 61)
        if (!without_digests) {
            canonicalize_silo_args(stored);
            canonicalize_silo_args(now);
        }
        if (stored != now) {
            const std::string differ = differing_settings(stored, now);
            const std::string options = differing_silo_options(stored.value("silo_args", json()),
                                                               now.value("silo_args", json()));
            const bool files_differ = differ.find(kInputFileDigestsKey) != std::string::npos;
            throw UserError("campaign = '" + dir.string() + "' holds a " + command + " campaign with other settings (" +
                            settings_file.string() + "; they differ in " + differ +
                            (options.empty() ? "" : ": " + options) + ")" +
                            (files_differ && options.empty()
                                 ? ": a --material or --geometry file was changed since the campaign began; its runs "
                                   "are of the file as it was"
                                 : "") +
                            ": give another --campaign, or the same settings to continue it");
        }
        if (without_digests) {
            json updated = read_json_file(settings_file.string(), "campaign settings");
            updated[kInputFileDigestsKey] = settings[kInputFileDigestsKey];
            orchestrator::write_text_file_atomically(settings_file, updated.dump(1) + "\n");
            std::cout << "note: " << settings_file.string() << " was made before demcal recorded its input files' "
                         "digests; it takes them as they are now\n";
        }
        return;
    }
    fs::create_directories(dir / "runs");
    orchestrator::write_text_file_atomically(settings_file, settings.dump(1) + "\n");
}

void print_silo_sweep_status(const fs::path& dir) {
    const json settings = read_json_file((dir / "campaign.json").string(), "campaign settings");
    // cutoff's and diagnose silo-dem's settings name their command; a vibration sweep's hold its grid
    const std::string command = settings.is_object() && settings.contains("command") && settings["command"].is_string()
                                    ? settings["command"].get<std::string>()
                                    : settings.is_object() && settings.contains("frequencies_hz") ? "vibration"
                                                                                                   : "(unknown)";
    std::size_t finished = 0, failed = 0, suspended = 0, begun = 0;
    std::error_code ec;
    if (fs::is_directory(dir / "runs", ec))
        for (const auto& entry : fs::directory_iterator(dir / "runs", ec)) {
            if (!entry.is_directory()) continue;
            const fs::path rd = entry.path();
            if (fs::exists(rd / "summary.json")) ++finished;
            else if (fs::exists(rd / "failed")) ++failed;
            else if (fs::exists(rd / "checkpoint.bin")) ++suspended;
            else ++begun;
        }
    std::cout << dir.string() << ": a silo sweep of demcal " << command << " (campaign.json), "
              << (finished + failed + suspended + begun) << " run folders: " << finished << " finished, " << failed
              << " failed, " << suspended << " suspended (a checkpoint), " << begun << " begun"
              << (orchestrator::FolderLock::held(dir) ? "; a demcal is running it now" : "")
              << "\n  the same demcal " << command << " command continues it (its finished runs are reused)\n";
}

SiloRunSummary::SiloRunSummary(json summary, fs::path file) : j_(std::move(summary)), file_(std::move(file)) {}

void SiloRunSummary::fail(const std::string& field, const std::string& why) const {
    throw UserError("run summary '" + file_.string() + "': " + field + " " + why +
                    " (written by demcal silo: remove the run's folder to run it again)");
}

bool SiloRunSummary::has(const std::string& field) const {
    return j_.is_object() && j_.contains(json::json_pointer("/" + field));
}

const json& SiloRunSummary::find(const std::string& field) const {
    if (!has(field)) fail(field, "is missing");
    return j_.at(json::json_pointer("/" + field));
}

double SiloRunSummary::number(const std::string& field) const {
    const json& v = find(field);
    if (!v.is_number()) fail(field, "= " + v.dump().substr(0, 40) + ": not a number");
    return v.get<double>();
}

std::optional<double> SiloRunSummary::optional_number(const std::string& field) const {
    if (!has(field)) return std::nullopt;
    return number(field);
}

std::string SiloRunSummary::text(const std::string& field) const {
    const json& v = find(field);
    if (!v.is_string()) fail(field, "= " + v.dump().substr(0, 40) + ": not a text");
    return v.get<std::string>();
}

std::optional<SiloRunSummary> silo_run_summary(const fs::path& dir, const std::string& name) {
    const fs::path summary = dir / "runs" / name / "summary.json";
    if (!fs::exists(summary)) return std::nullopt;
    try {
        return SiloRunSummary(orchestrator::read_result_json(summary, "run summary '" + summary.string() + "'"),
                              summary);
    } catch (const std::exception& e) {  // damaged (its seal), or not JSON within the reader's rules
        throw UserError(std::string(e.what()) + " (written by demcal silo: remove " + (dir / "runs" / name).string() +
                        " to run it again)");
    }
}

bool silo_run_failed(const fs::path& dir, const std::string& name) { return fs::exists(dir / "runs" / name / "failed"); }

namespace {

// A run folder's identity, DIR/runs/NAME/run.json, written before its first launch: the run's silo options and the
// digests of the files they name. A run is found by its folder's name, so a folder copied from another campaign (of
// another amplitude, particle count, ...) was read, or its checkpoint resumed, as this campaign's run: a vibration
// cell reported another amplitude's rate, a still reference of 2000 grains paired with runs of 300.
constexpr const char* kRunIdentityFile = "run.json";

json silo_run_identity(const SiloRunPlan& plan) {
    return {{"schema", "demcal.silo-run/1"},
            {"silo_args", plan.silo_args},
            {kInputFileDigestsKey, silo_input_file_digests(plan.silo_args)}};
}

// Refuses a run folder that holds a run of other settings (its run.json differs), naming the first option that
// differs. A folder without run.json (not begun, or from a demcal before it) is taken as it is.
void check_run_folder_identity(const fs::path& rd, const json& identity, const std::string& command) {
    const fs::path file = rd / kRunIdentityFile;
    // a checkpoint without the folder's run.json cannot be told from another run's (a folder copied in): resumed,
    // a 1000-grain run was reported as a 300-grain sweep's cell (held-back suite). Finished runs of a demcal before
    // run.json (summary.json alone) are still taken.
    if (!fs::exists(fs::symlink_status(file)) && fs::exists(fs::symlink_status(rd / "checkpoint.bin")))
        throw UserError("demcal " + command + ": the run folder " + rd.string() + " holds a checkpoint but no " +
                        kRunIdentityFile + ", so nothing tells that it is this campaign's run (a folder copied in?): "
                        "remove it to run it again");
    if (!fs::exists(fs::symlink_status(file))) return;
    json stored;
    try {
        stored = read_json_file(file.string(), "run identity");
    } catch (const UserError& e) {
        throw UserError(std::string(e.what()) + " (remove the run's folder " + rd.string() + " to run it again)");
    }
    json stored_canonical = stored, identity_canonical = identity;
    if (stored.is_object() && stored.contains(kInputFileDigestsKey)) {  // (the files compared apart: see above)
        canonicalize_silo_args(stored_canonical);
        canonicalize_silo_args(identity_canonical);
    }
    if (stored_canonical == identity_canonical) return;
    std::string what = "its settings";
    if (stored.is_object() && stored.value(kInputFileDigestsKey, json()) != identity[kInputFileDigestsKey])
        what = "the contents of its input files (--material, --geometry)";
    if (stored_canonical.is_object() && stored_canonical.value("silo_args", json()) != identity_canonical["silo_args"])
        what = "its silo options (" + analytics::shortened_text(stored.value("silo_args", json()).dump(), 300) +
               ", this campaign's run: " + analytics::shortened_text(identity["silo_args"].dump(), 300) + ")";
    throw UserError("demcal " + command + ": the run folder " + rd.string() + " holds a run of other settings than " +
                    "this campaign's run of that name: " + what + " differ (a folder copied from another campaign?); "
                    "remove it to run it here");
}

// Records the identity of a run about to start in its folder (made if need be).
void record_run_identity(const fs::path& rd, const json& identity) {
    fs::create_directories(rd);
    if (!fs::exists(rd / kRunIdentityFile)) orchestrator::write_text_file_atomically(rd / kRunIdentityFile, identity.dump(1) + "\n");
}

// The run's end as the campaign records it: finished, stopped (resume later), or failed (a marker; left alone).
void record_run_end(const fs::path& rd, const std::string& name, int rc, bool stop_requested,
                    const std::string& log, const std::string& command, SiloCampaignOutcome& outcome) {
    if (rc == 0) {
        ++outcome.finished;
        if (stop_requested) outcome.stopped = true;
        return;
    }
    if (rc == kExitResumeLater || rc == 128 + SIGINT || rc == 128 + SIGTERM || stop_requested) {
        std::cout << "stopped at " << name << " (exit " << rc << "); the same command continues the " << command
                  << " campaign\n";
        outcome.stopped = true;
        return;
    }
    if (rc == kExitResultsNotWritten) {  // the disk, not the run: no failure marker, the next command runs it again
        std::cerr << "demcal " << command << ": run " << name << " could not write its results (see " << (rd / log)
                  << "); the campaign stops here: make room, then the same command runs it again\n";
        outcome.stopped = true;
        return;
    }
    std::ofstream(rd / "failed") << "exit status " << rc << "; see " << log << "\n";
    std::cerr << "demcal " << command << ": run " << name << " failed (exit " << rc << "), see " << (rd / log) << "\n";
    ++outcome.failed;
}

// A run folder another demcal holds (a run of a sweep killed before its runs ended): said, and the campaign stops
// for a later resume (exit 75), where the run started here was refused as busy and marked failed for good.
bool run_folder_busy(const fs::path& rd, const std::string& name, const std::string& command) {
    if (!orchestrator::FolderLock::held(rd)) return false;
    std::cout << "run " << name << " is in use by another demcal process (" << rd.string()
              << "); the campaign stops here: when that run has ended, the same command continues the " << command
              << " campaign\n";
    return true;
}

// The runs left as SLURM array tasks (orchestrator::SlurmExecutor: sbatch, squeue, the tasks' exit_status files).
void run_on_slurm(const fs::path& dir, const std::vector<const SiloRunPlan*>& todo,
                  const std::map<const SiloRunPlan*, json>& identities, std::size_t total,
                  int jobs, const std::string& command, const SiloCampaignExecutor& where,
                  SiloCampaignOutcome& outcome) {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw std::runtime_error(command + ": cannot find this program's own path (/proc/self/exe)");
    const std::string program = orchestrator::pinned_program(self.string(), dir / ".program");
    std::vector<orchestrator::Job> queue;
    for (const SiloRunPlan* plan : todo) {
        const fs::path rd = dir / "runs" / plan->name;
        if (run_folder_busy(rd, plan->name, command)) {
            outcome.stopped = true;
            return;
        }
        const bool resume = fs::exists(rd / "checkpoint.bin");
        record_run_identity(rd, identities.at(plan));
        std::vector<std::string> argv{program};
        const auto args = resume ? resume_command(*plan, rd) : fresh_command(*plan, rd, false);
        argv.insert(argv.end(), args.begin(), args.end());
        queue.push_back({plan->name, rd, argv, where.time_limit_s});
    }
    const auto executor = orchestrator::make_executor("slurm", std::max(1, jobs), dir / "slurm", where.partition);
    orchestrator::InterruptGuard interrupts;  // Ctrl-C / SIGTERM: the executor cancels the tasks (they checkpoint)
    std::size_t next = 0;
    executor->run([&]() -> std::optional<orchestrator::Job> {
                     if (next >= queue.size()) return std::nullopt;
                     return queue[next++];
                 },
                 {[&](const orchestrator::Job& job, long handle) {
                      std::cout << "[" << outcome.finished + outcome.failed + ++outcome.started << "/" << total
                                << "] " << job.id << " (SLURM task " << handle / orchestrator::SlurmExecutor::kTaskBase
                                << "_" << handle % orchestrator::SlurmExecutor::kTaskBase << ")" << std::endl;
                  },
                  [&](const orchestrator::Job& job, const orchestrator::JobOutcome& o) {
                      outcome.cpu_seconds += o.cpu_s;
                      const int rc = o.timed_out ? kExitResumeLater : o.exit_code >= 0 ? o.exit_code : 128 + o.term_signal;
                      record_run_end(job.dir, job.id, rc, o.interrupted || orchestrator::interrupted(), "stderr.log",
                                     command, outcome);
                  }});
    if (orchestrator::interrupted()) outcome.stopped = true;
}

}  // namespace

SiloCampaignOutcome run_silo_campaign(const fs::path& dir, const std::vector<SiloRunPlan>& plans,
                                      int jobs,
                                      const std::string& command, const SiloCampaignExecutor& where) {
    // one demcal per campaign: two sweeps on one folder ran the same runs into the same run folders at once
    std::unique_ptr<orchestrator::FolderLock> lock;
    try {
        lock = std::make_unique<orchestrator::FolderLock>(dir, "campaign directory");
    } catch (const std::runtime_error& e) {
        throw UserError(e.what());
    }
    SiloCampaignOutcome outcome;
    std::vector<const SiloRunPlan*> todo;
    std::map<const SiloRunPlan*, json> identities;
    for (const SiloRunPlan& plan : plans) {
        const fs::path rd = dir / "runs" / plan.name;
        const json& identity = identities[&plan] = silo_run_identity(plan);  // (input files read once per plan)
        check_run_folder_identity(rd, identity, command);  // before its summary is read or its checkpoint resumed
        if (fs::exists(rd)) record_run_identity(rd, identity);  // a run of a demcal before run.json: adopted
        if (fs::exists(rd / "summary.json"))
            ++outcome.finished;
        else if (fs::exists(rd / "failed"))
            ++outcome.failed;
        else
            todo.push_back(&plan);
    }
    if (where.executor == "slurm") {
        run_on_slurm(dir, todo, identities, plans.size(), jobs, command, where, outcome);
        return outcome;
    }
    if (where.executor != "local")
        throw UserError("executor = '" + where.executor.substr(0, 40) + "': local or slurm");
    StopHandlers handlers;
    std::map<pid_t, const SiloRunPlan*> running;
    std::size_t next = 0;
    bool signalled_children = false;
    while (next < todo.size() || !running.empty()) {
        const bool stopping = g_stop_requested || outcome.stopped;
        while (!stopping && next < todo.size() && int(running.size()) < std::max(1, jobs)) {
            const SiloRunPlan& plan = *todo[next++];
            const fs::path rd = dir / "runs" / plan.name;
            if (run_folder_busy(rd, plan.name, command)) {
                outcome.stopped = true;
                break;
            }
            const bool resume = fs::exists(rd / "checkpoint.bin");
            record_run_identity(rd, identities.at(&plan));
            std::cout << "[" << outcome.finished + outcome.failed + running.size() + 1 << "/" << plans.size() << "] "
                      << plan.name << (resume ? " (resumed)" : "") << std::endl;
            running[spawn_demcal(resume ? resume_command(plan, rd) : fresh_command(plan, rd, false),
                                 rd / "silo.log")] = &plan;
            ++outcome.started;
        }
        if (running.empty()) break;
        if (g_stop_requested && !signalled_children) {
            // the runs have their own process groups (spawn_demcal): a stop reaches them from here only, once
            for (const auto& [pid, plan] : running) ::kill(pid, SIGTERM);
            signalled_children = true;
        }
        int status = 0;
        rusage usage{};
        const pid_t pid = ::wait4(-1, &status, 0, &usage);
        if (pid < 0) {
            if (errno == EINTR) continue;
            throw std::runtime_error(command + ": waiting for the silo runs: " + std::strerror(errno));
        }
        const auto it = running.find(pid);
        if (it == running.end()) continue;  // not one of ours
        const SiloRunPlan& plan = *it->second;
        running.erase(it);
        outcome.cpu_seconds += cpu_of(usage);
        record_run_end(dir / "runs" / plan.name, plan.name, exit_status(status), g_stop_requested, "silo.log", command,
                       outcome);
    }
    if (g_stop_requested) outcome.stopped = true;
    return outcome;
}

}  // namespace demcal
