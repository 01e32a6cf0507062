// A shear campaign: one material sheared at several normal stresses (optionally replicated with other packing
// seeds). It lives in a directory: DIR/campaign.sqlite (the store) and DIR/runs/<identity>/ (one generated run each:
// shear_box.py, params.json, result.json, stdout.log, stderr.log). Runs are identified by their hash, so a run that
// is already done in the store is reused, never computed twice (unless forced), and a campaign killed at any moment
// resumes by running this again (or resume_shear_campaigns) on the same directory.
#pragma once
#include "orchestrator/campaign_directory.hpp"
#include "orchestrator/campaign_store.hpp"
#include "orchestrator/executor.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace demcal::orchestrator {

// Which engine runs a campaign's shear boxes: YADE (yade_scripts/shear_box.py) or the native kernel (the same
// procedure with YADE's laws, kernel/cases/shear_box.hpp, run as `demcal shear-run` subprocesses). Part of each run's
// identity: the two engines' runs of one material never share a cache entry.
enum class ShearEngine { yade, kernel };
std::string to_string(ShearEngine e);
// Throws std::invalid_argument naming the field 'engine' and the value.
ShearEngine parse_shear_engine(const std::string& name);

struct ShearCampaignSpec {
    nlohmann::json material;                 // as given; validated by plan_runs
    std::vector<double> normal_stresses;     // [Pa]
    int replicates = 1;                      // packings per normal stress, seeds base_seed, base_seed + 1, ...
    long base_seed = 1;
    std::filesystem::path template_path;     // empty: the installed yade_scripts/shear_box.py
    std::string label;                       // optional human name, e.g. "sensitivity density level 2"
    ShearEngine engine = ShearEngine::yade;  // template_path applies to yade only
    // The material file's "name" (resolved() takes it from `material`): what `demcal status` calls the campaign's
    // material. Not part of the campaign's identity (campaign_name): a renamed file is the same campaign.
    std::string material_name;

    nlohmann::json to_json() const;
    static ShearCampaignSpec from_json(const nlohmann::json& j);
};

// A copy of `program` in `dir` (replaced atomically when it changed), returned as the path to run: a rebuild of the
// program while a campaign runs then neither fails the runs it starts ("cannot start: permission denied" while the
// linker writes the file: measured, an overnight campaign stopped at 182 of 300 runs) nor mixes two builds within one
// campaign call. Used for the kernel engine (DIR/.kernel-engine/) and the silo campaigns' SLURM tasks.
std::string pinned_program(const std::string& program, const std::filesystem::path& dir);

struct ExecutionOptions {
    int jobs = 0;                 // parallel runs; 0 = the number of cores
    double timeout_s = 3600;      // per run
    int retries = 1;              // further attempts after a crash or a timeout (not after a physical failure)
    bool force = false;           // recompute runs already done
    std::string executor = "local";  // "local" or "slurm"
    std::string yade = "yade";    // the YADE launcher (path or name on PATH)
    std::string slurm_partition;  // SLURM only; empty = the default partition
    long max_runs = 10000;        // most simulations one command may plan (a typo in --levels started millions)
    // The kernel engine, as the program that embeds it says (the orchestrator knows nothing of the kernel): the
    // command of one run, to which "params.json result.json" is appended (demcal: {its own path, "shear-run"}), and
    // the engine's name and version, which stands in a kernel run's identity where a YADE run has its script.
    std::vector<std::string> kernel_command;
    std::string kernel_engine;
};

// Most packings per normal stress a campaign may ask for: the interval of a failure line narrows as 1/sqrt(n), so
// 1000 replicates already put it at 3 % of one packing's scatter, below the box's own systematic error; more is a
// typo (a replicate count of 2e9 planned millions of runs per stress). Refused by name (--replicates) before any work.
inline constexpr int kMaxReplicates = 1000;

// Refuses a plan of more than `max_runs` simulations before anything is planned or written; `breakdown` says how
// the count came about ("3 normal stresses x 1000 replicates"). Counts as double: the product may overflow an int.
void check_run_count(double runs, long max_runs, const std::string& breakdown);

// The failure cause of a run whose result.json fails its SHA-256 seal: retried (up to --retries), never a result.
inline constexpr const char* kDamagedResult = "damaged_result";

// A run's result.json, read under the input rules and checked against its seal (run_identity.hpp: a file of schema
// demcal.shear_result/2 must carry a matching one; /1, from older templates, has none) and for a number
// peak_shear_stress. Throws DamagedResult for a damaged file, std::invalid_argument for one that is not a result.
nlohmann::json read_shear_result(const std::filesystem::path& file, const nlohmann::json* run_params = nullptr);
// A result's stresses within what a shear box can report (finite, 0 <= tau <= kMaxShearOverNormalStress x its
// normal stress) and, given the run's params, its normal stress the run's: throws std::invalid_argument naming `what`.
inline constexpr double kMaxShearOverNormalStress = 100;
void check_shear_result_values(const nlohmann::json& result, const std::string& what,
                               const nlohmann::json* run_params = nullptr);

struct CampaignProgress {
    int total = 0, done = 0, failed = 0, running = 0, pending = 0, reused = 0;
    double elapsed_s = 0;
    double remaining_s = -1;      // estimate from finished runs; < 0 when none finished yet
    std::string event;            // "started", "done", "failed", "retry", "interrupted"
    const RunRecord* run = nullptr;
};
using ProgressCallback = std::function<void(const CampaignProgress&)>;

struct ShearCampaignOutcome {
    CampaignRecord campaign;
    std::vector<RunRecord> runs;  // in plan order, with their labels {"normal_stress", "replicate", "seed"}
    int executed = 0;             // runs computed by this call
    int reused = 0;               // runs found done in the store
    int failed = 0;
    double cpu_s = 0;             // CPU seconds of all the campaign's successful runs (also the reused ones)
    bool interrupted = false;
    // Why the simulator could not be started (empty when it could): an infrastructure failure, not a run's. The
    // runs it hit stay pending, so a resume with a working simulator runs them.
    std::string infrastructure_failure;
    bool complete() const { return !interrupted && failed == 0 && infrastructure_failure.empty(); }
};

// The folder of demcal's YADE scripts: yade_scripts/ of this build, or the folder DEMCAL_YADE_SCRIPTS names when it
// is set and not empty (an installed copy).
std::filesystem::path yade_scripts_folder();
// The script `name` of that folder; throws std::invalid_argument when it is not a file there, naming the file and,
// when the folder came from DEMCAL_YADE_SCRIPTS, the variable and its value.
std::filesystem::path yade_script(const std::string& name);
// yade_scripts_folder() / "shear_box.py"
std::filesystem::path default_shear_template();
// Throws std::invalid_argument when the YADE launcher cannot be found (naming it and how to install it).
std::filesystem::path find_yade(const std::string& yade);

// Checks the spec (material, stresses, replicates, template, YADE) without writing anything.
void validate_shear_spec(const ShearCampaignSpec& spec);

class ShearCampaignRunner {
public:
    // Opens (creating if needed) the campaign directory and takes its lock; throws if another demcal holds it.
    ShearCampaignRunner(const std::filesystem::path& dir, ExecutionOptions options);
    ~ShearCampaignRunner();

    // Plans the runs, reuses what is done, computes the rest. Blocks; Ctrl-C stops cleanly (outcome.interrupted).
    ShearCampaignOutcome run(const ShearCampaignSpec& spec, const ProgressCallback& progress = {});
    // Runs every campaign of the directory that is not complete.
    std::vector<ShearCampaignOutcome> resume(const ProgressCallback& progress = {});

    CampaignStore& store() { return *store_; }
    const std::filesystem::path& dir() const { return dir_; }

private:
    CampaignDirectory directory_;  // the lock and the store, stale runs recovered
    std::filesystem::path dir_;
    ExecutionOptions options_;
    CampaignStore* store_;
};

// Summary of a campaign directory without running anything (for `demcal status`): opens the store read-only.
std::vector<ShearCampaignOutcome> inspect_campaigns(const std::filesystem::path& dir);

// Refuses (std::invalid_argument naming the store, the campaign and the field) a store whose shear campaigns' specs
// an edit or damage made unreadable, reading only: before status prints or resume runs anything of them.
void check_stored_shear_specs(const std::filesystem::path& dir);

std::string campaign_name(const ShearCampaignSpec& spec);
// The name a demcal before stop 61 gave the campaign (its stresses in the order typed, its numbers as written): a
// store made then keeps its campaigns under these names.
std::string legacy_campaign_name(const ShearCampaignSpec& spec);

}  // namespace demcal::orchestrator
