// A campaign of `demcal silo` runs, shared by the commands that sweep the silo case (demcal vibration, demcal diagnose
// --model silo-dem): every run is a subprocess of this very demcal in DIR/runs/<name>/ (its own checkpoint, its own
// summary.json), so a crash or Ctrl-C of one run loses nothing finished. Running a campaign again continues it:
// finished runs (summary.json) are read, suspended ones (checkpoint.bin) resumed with `demcal silo --resume`, failed
// ones (a `failed` marker) left alone, the rest run, up to `jobs` at a time.
#pragma once
#include "app/cli_support.hpp"  // NamedPath

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace demcal {

// The environment variable by which a campaign tells the demcal it starts for a run to end with it (its pid);
// app/main.cpp reads it.
inline constexpr const char* kDieWithParentVariable = "DEMCAL_END_WITH_PARENT";

// One run: its folder name under DIR/runs/ and its `demcal silo` options except --out (which the campaign sets).
struct SiloRunPlan {
    std::string name;
    std::vector<std::string> silo_args;  // e.g. {"--theta", "30", "--seed", "1", "--particles", "2000", ...}
};

// The silo options that name one run's output file or folder: a campaign cannot pass them on to all its runs.
inline constexpr const char* kOneRunOutputOptions[] = {"--export-bed", "--export-final-bed", "--export-cloud", "--vtk",
                                                       "--vtk-every"};

// Refuses (UserError naming the option and `command`) a silo option after -- that the command sets for every run,
// or one of kOneRunOutputOptions.
void refuse_owned_silo_options(const std::vector<std::string>& silo_args, const std::vector<std::string>& owned,
                               const std::string& command);

// Checks each plan's settings with `demcal silo --check` (nothing written); throws UserError naming the run and silo's
// message. Call with the distinct settings only (repeats differing by seed need one check).
void check_silo_runs(const std::vector<SiloRunPlan>& plans);

// The input files the silo options name: (option, path) for --material and --geometry, given as "--opt FILE" or
// "--opt=FILE".
std::vector<std::pair<std::string, std::string>> silo_input_files(const std::vector<std::string>& silo_args);

// What a command's own outputs (--json, --report) must never land on: the silo options' input files and the campaign's
// settings file DIR/campaign.json (`cutoff --json` on the --material file replaced the material with its result).
// For check_paths_apart's inputs.
std::vector<NamedPath> silo_campaign_inputs(const std::vector<std::string>& silo_args,
                                            const std::filesystem::path& dir);

// The key under which a campaign's settings hold silo_input_file_digests.
inline constexpr const char* kInputFileDigestsKey = "input_files_sha256";

// The SHA-256 of each input file the silo options name (--material, --geometry; "--opt FILE" or "--opt=FILE"), by
// option: a campaign's settings hold them, so that a material or geometry file edited in place is a new campaign, not
// the old runs reused under the same option text (a sweep reported 155 g/s from runs of the unedited material, where
// the edited one discharges 75 g/s). Call after the files were checked (silo --check): a file that cannot be read
// throws.
nlohmann::json silo_input_file_digests(const std::vector<std::string>& silo_args);

// Replaces a campaign.json's (or a run identity's) "silo_args" list by its one spelling (canonical_silo_options), so
// that two commands that run the same silo case compare equal: the options after -- in another order, as
// --opt=value, 1e-3 for 0.001 or a file by another path were refused as other settings (probe 61).
void canonicalize_silo_args(nlohmann::json& settings);

// DIR/campaign.json: created with `settings` (and DIR/runs) when absent; when present it must hold the same settings,
// else UserError naming the settings that differ (another campaign lives there, or its input files changed). A
// campaign.json from before the input files' digests (no kInputFileDigestsKey) takes the files' present digests, with
// a note. The keys in `may_change` (a sweep's grid: more angles, frequencies or
// seeds add runs to the same campaign) are left out of the comparison. Call after every check of the input.
void open_silo_campaign(const std::filesystem::path& dir, const nlohmann::json& settings, const std::string& command,
                        const std::vector<std::string>& may_change = {});

// `demcal status` of a silo sweep's folder (DIR/campaign.json): which command made it and its runs by state (finished,
// failed, suspended with a checkpoint, begun), read from the run folders; nothing written.
void print_silo_sweep_status(const std::filesystem::path& dir);

struct SiloCampaignOutcome {
    std::size_t finished = 0;  // with a summary.json (before or now)
    std::size_t failed = 0;    // a `failed` marker (before or now)
    std::size_t started = 0;   // runs started or resumed by this call
    bool stopped = false;      // a signal or a run's suspension (exit 75) stopped the campaign: run it again
    double cpu_seconds = 0;    // CPU time of the children this call waited for
};

// Where a campaign's runs go: processes of this machine, or SLURM job arrays (one array task per run, at most `jobs`
// at once), for sweeps that outgrow one machine. On SLURM each task runs a copy of this demcal pinned in
// DIR/.program/ (a rebuild during the campaign changes nothing), its output in the run folder's stdout.log and
// stderr.log, under a SLURM time limit of `time_limit_s` (a run that reaches it checkpoints on SLURM's SIGTERM and
// the same command resumes it).
struct SiloCampaignExecutor {
    std::string executor = "local";  // local | slurm
    std::string partition;           // SLURM partition; empty: the default one
    double time_limit_s = 86400;     // SLURM only
};

// Runs what is left of `plans` in DIR/runs/<name>/, at most `jobs` at once; progress lines "[k/N] name" on stdout,
// each run's output in its silo.log; a resumed run takes the session options of its plan again (--threads,
// --no-plots, ...: the rest is in its checkpoint). SIGINT/SIGTERM during the call: the running runs are sent
// SIGTERM (they checkpoint and exit 75), the call waits for them and returns stopped.
SiloCampaignOutcome run_silo_campaign(const std::filesystem::path& dir, const std::vector<SiloRunPlan>& plans,
                                      int jobs, const std::string& command, const SiloCampaignExecutor& where = {});

// A finished run's summary.json, read field by field: a field given by its path ("rate/rate_kg_s") that is missing
// or holds another type throws UserError naming the file, the field and what it holds (a summary edited or damaged
// by hand stops the report with that, not with a library's message).
class SiloRunSummary {
public:
    SiloRunSummary(nlohmann::json summary, std::filesystem::path file);
    double number(const std::string& field) const;
    // Empty when the field is absent (summaries of an older demcal); any other type than a number is an error.
    std::optional<double> optional_number(const std::string& field) const;
    std::string text(const std::string& field) const;
    // Throws UserError naming the file and the field: "FIELD WHY" (a caller's own check of a value).
    [[noreturn]] void fail(const std::string& field, const std::string& why) const;

private:
    bool has(const std::string& field) const;
    const nlohmann::json& find(const std::string& field) const;
    nlohmann::json j_;
    std::filesystem::path file_;
};

// The summary.json of a finished run of DIR, if any.
std::optional<SiloRunSummary> silo_run_summary(const std::filesystem::path& dir, const std::string& name);
bool silo_run_failed(const std::filesystem::path& dir, const std::string& name);

// A number as a silo option: all 17 digits, so that the run gets exactly the value planned.
std::string silo_number(double value);

}  // namespace demcal
