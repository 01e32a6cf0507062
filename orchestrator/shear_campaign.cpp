#include "orchestrator/shear_campaign.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"

#include "orchestrator/run_identity.hpp"
#include "orchestrator/shear_params.hpp"
#include "orchestrator/slurm_executor.hpp"

#include <optional>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <regex>
#include <map>
#include <set>
#include <stdexcept>
#include <thread>

namespace demcal::orchestrator {

namespace fs = std::filesystem;

std::string to_string(ShearEngine e) { return e == ShearEngine::kernel ? "kernel" : "yade"; }

ShearEngine parse_shear_engine(const std::string& name) {
    if (name == "yade") return ShearEngine::yade;
    if (name == "kernel") return ShearEngine::kernel;
    throw std::invalid_argument("engine = '" + analytics::shortened_text(name) + "' is not one of: yade, kernel");
}

nlohmann::json ShearCampaignSpec::to_json() const {
    nlohmann::json j = {{"material", material},       {"normal_stresses", normal_stresses}, {"replicates", replicates},
                        {"base_seed", base_seed},     {"template", template_path.string()}, {"label", label}};
    // Written for the kernel only: a YADE campaign keeps the spec, and so the name, it had before engines existed.
    if (engine == ShearEngine::kernel) {
        j["engine"] = to_string(engine);
        j["template"] = "";
    }
    if (!material_name.empty()) j["material_name"] = material_name;
    return j;
}

ShearCampaignSpec ShearCampaignSpec::from_json(const nlohmann::json& j) {
    // A stored spec an edit or a damaged store changed: its field named, not the JSON library's text (status and
    // resume printed "[json.exception.out_of_range.403] key 'material' not found", exit 1, probe 63).
    if (!j.is_object()) throw std::invalid_argument("the campaign's spec is not a JSON object");
    const auto field = [&j](const char* key, bool (nlohmann::json::*is_type)() const noexcept,
                            const char* type) -> const nlohmann::json& {
        if (!j.contains(key)) throw std::invalid_argument(std::string("the campaign's spec has no '") + key + "'");
        const nlohmann::json& v = j.at(key);
        if (!(v.*is_type)())
            throw std::invalid_argument(std::string("the campaign's spec field '") + key + "' = " +
                                        analytics::json_value_text(v) + " is not " + type);
        return v;
    };
    const auto optional_text = [&](const char* key, const char* fallback) -> std::string {
        return j.contains(key) ? field(key, &nlohmann::json::is_string, "a text").get<std::string>() : fallback;
    };
    ShearCampaignSpec s;
    s.material = field("material", &nlohmann::json::is_object, "a JSON object");
    const nlohmann::json& stresses = field("normal_stresses", &nlohmann::json::is_array, "a list of numbers");
    for (const auto& x : stresses) {
        if (!x.is_number())
            throw std::invalid_argument("the campaign's spec field 'normal_stresses' holds " +
                                        analytics::json_value_text(x) + ", not a number");
        s.normal_stresses.push_back(x.get<double>());
    }
    s.replicates = field("replicates", &nlohmann::json::is_number_integer, "a whole number").get<int>();
    s.base_seed = field("base_seed", &nlohmann::json::is_number_integer, "a whole number").get<long>();
    s.template_path = field("template", &nlohmann::json::is_string, "a text").get<std::string>();
    s.label = optional_text("label", "");
    s.engine = parse_shear_engine(optional_text("engine", "yade"));
    s.material_name = optional_text("material_name", "");
    return s;
}

namespace {
// DEMCAL_YADE_SCRIPTS, when set and not empty: another folder of demcal's YADE scripts (an installed copy).
const char* scripts_folder_override() {
    const char* d = std::getenv("DEMCAL_YADE_SCRIPTS");
    return d && *d ? d : nullptr;
}
}  // namespace

fs::path yade_scripts_folder() {
    if (const char* d = scripts_folder_override()) return fs::path(d);
    return fs::path(DEMCAL_YADE_SCRIPTS_DIR);
}

fs::path yade_script(const std::string& name) {
    const fs::path file = yade_scripts_folder() / name;
    if (fs::is_regular_file(file)) return file;
    const char* folder = scripts_folder_override();
    throw std::invalid_argument("YADE script '" + file.string() + "' is not a file" +
                                (folder ? std::string(" (its folder is DEMCAL_YADE_SCRIPTS = '") + folder +
                                              "'; unset it to use demcal's own scripts)"
                                        : std::string(" (demcal's yade_scripts folder is incomplete)")));
}

fs::path default_shear_template() { return yade_scripts_folder() / "shear_box.py"; }

namespace {
// A program a process can start: a regular file (after symlinks) with execute permission. access(X_OK) alone also
// accepts a folder, which then failed every run as if the simulation had.
bool is_executable_file(const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

// The significant decimal digits of the real numbers of the YADE build `launcher` starts, as YADE's generated launcher
// writes them ("mpmath.mp.dps=(int(18)+1)" in the long-double build's); 0 when the launcher does not say (a wrapper).
int yade_launcher_digits(const fs::path& launcher) {
    std::ifstream in(launcher);
    std::string line;
    const std::regex dps(R"(^\s*mpmath\.mp\.dps\s*=\s*\(\s*int\(\s*(\d{1,6})\s*\)\s*\+\s*1\s*\)\s*$)");
    for (int n = 0; n < 200 && std::getline(in, line); ++n) {
        std::smatch m;
        if (std::regex_match(line, m, dps)) return std::stoi(m[1].str());
    }
    return 0;
}

// demcal's YADE scripts write their results with Python's json, which takes the double build's floats only: a
// higher-precision build ran every run to its end and then failed to write its result.
fs::path checked_yade_build(const fs::path& launcher, const std::string& given) {
    constexpr int kDoubleDigits = 15;
    const int digits = yade_launcher_digits(launcher);
    if (digits > kDoubleDigits)
        throw std::invalid_argument("yade = '" + given + "' is a YADE build of " + std::to_string(digits) +
                                    "-digit reals (long double, float128 or MPFR): demcal's YADE scripts need the "
                                    "double build (15 digits; Debian's /usr/bin/yade-double)");
    return launcher;
}

}  // namespace

fs::path find_yade(const std::string& yade) {
    if (yade.empty()) throw std::invalid_argument("yade = '': empty; give the YADE launcher's name or path");
    if (yade.find('/') != std::string::npos) {
        if (is_executable_file(yade)) return checked_yade_build(fs::absolute(yade), yade);  // runs start in their own folders
        std::error_code ec;
        const std::string why = !fs::exists(yade, ec)        ? "does not exist"
                                : fs::is_directory(yade, ec) ? "is a folder, not a program"
                                : !fs::is_regular_file(yade, ec) ? "is not a regular file"
                                                                 : "is not executable";
        throw std::invalid_argument("yade = '" + yade + "' " + why + " (pass --yade with the YADE launcher)");
    } else if (const auto found = find_program_on_path(yade)) {
        return checked_yade_build(*found, yade);
    }
    throw std::invalid_argument("yade = '" + yade +
                                "' was not found on this machine (install the Debian package 'yade', e.g. with "
                                "scripts/setup.sh, or pass --yade PATH)");
}

namespace {
// "shear-" and a digest of the spec without its material's name (a label: one material under two names is one
// campaign); with numbers_by_value, the material's numbers by value (2650 and 2650.0, 50000000 and 5e7 are one
// material: probe 61), as names are given since stop 61.
std::string campaign_name_of(const ShearCampaignSpec& spec, bool numbers_by_value) {
    nlohmann::json identity = spec.to_json();
    identity.erase("material_name");
    if (numbers_by_value)
        for (auto& [key, value] : identity["material"].items())
            if (value.is_number()) value = value.get<double>();
    return "shear-" + sha256_hex(identity.dump()).substr(0, 12);
}
}  // namespace

std::string campaign_name(const ShearCampaignSpec& spec) { return campaign_name_of(spec, true); }

std::string legacy_campaign_name(const ShearCampaignSpec& spec) { return campaign_name_of(spec, false); }

namespace {

constexpr const char* kWrapperName = "run_clean.py";  // yade_scripts/run_clean.py, beside the default template

struct PlannedRun {
    std::string hash;
    nlohmann::json params;
    nlohmann::json label;
    fs::path dir;
};

ShearCampaignSpec resolved(const ShearCampaignSpec& spec) {
    ShearCampaignSpec s = spec;
    if (s.engine == ShearEngine::kernel) {
        s.template_path.clear();  // the kernel has no script
    } else {
        if (s.template_path.empty()) s.template_path = default_shear_template();
        s.template_path = fs::absolute(s.template_path).lexically_normal();
    }
    // one campaign whatever the order the stresses were typed in (-s 8e3,4e3 opened a second campaign: probe 61)
    std::sort(s.normal_stresses.begin(), s.normal_stresses.end());
    if (s.material_name.empty() && spec.material.is_object())
        if (const auto name = spec.material.find("name"); name != spec.material.end() && name->is_string())
            s.material_name = name->get<std::string>();
    s.material = validate_material(spec.material);
    return s;
}

std::vector<PlannedRun> plan_runs(const ShearCampaignSpec& spec, const std::string& template_text,
                                  const fs::path& campaign_dir) {
    std::vector<PlannedRun> plan;
    for (double sigma : spec.normal_stresses)
        for (int rep = 0; rep < spec.replicates; ++rep) {
            const long seed = spec.base_seed + rep;
            PlannedRun r;
            r.params = make_run_params(spec.material, sigma, seed);
            r.hash = run_identity(template_text, r.params);
            r.label = {{"normal_stress", sigma}, {"replicate", rep}, {"seed", seed}};
            r.dir = campaign_dir / "runs" / r.hash.substr(0, 16);
            plan.push_back(std::move(r));
        }
    return plan;
}

// What one engine needs to plan and start its runs.
struct EngineSetup {
    std::string identity_text;           // the script (YADE) or the engine's name and version (kernel)
    std::string wrapper_text;            // YADE: run_clean.py
    std::vector<std::string> command;    // to which the run's files are appended
    std::string started_marker;          // a file the run writes once the simulator has started (YADE), or none
    std::string build;                   // YADE: the build its results come from (yade_build_of), recorded in the store
};

// The YADE build a store's results come from: the launcher's resolved path and the SHA-256 of its text, which names
// the build's version, precision and features. Runs of two builds share identities (the script and the parameters),
// so a second build would take the first one's results as its own: a store holds one build's results.
constexpr const char* kYadeBuildSetting = "yade_build";

std::string yade_build_of(const fs::path& launcher) {
    std::error_code ec;
    fs::path resolved = fs::weakly_canonical(launcher, ec);
    if (ec) resolved = launcher;
    return nlohmann::json{{"launcher", resolved.string()}, {"sha256", sha256_hex(read_text_file(launcher))}}.dump();
}

// Refuses `given` (the --yade value) when the store holds results of another build, before anything is written.
void check_store_yade_build(CampaignStore& store, const std::string& build, const std::string& given) {
    const auto recorded = store.setting(kYadeBuildSetting);
    if (!recorded || *recorded == build) return;
    std::string recorded_launcher = *recorded;
    try {
        recorded_launcher = nlohmann::json::parse(*recorded).at("launcher").get<std::string>();
    } catch (const std::exception&) {
    }
    const std::string now_launcher = nlohmann::json::parse(build).at("launcher").get<std::string>();
    throw std::invalid_argument(
        "yade = '" + analytics::shortened_text(given) + "' (" + analytics::shortened_text(now_launcher) +
        ") is another YADE build than the one this campaign folder's results came from (" +
        analytics::shortened_text(recorded_launcher) +
        (recorded_launcher == now_launcher ? ", since changed: another version or an edited launcher" : "") +
        "): the two builds' results would be mixed. Pass --yade with that build, or use another campaign folder");
}

// The file yade_scripts/run_clean.py writes in the run's folder first thing, once YADE has started.
constexpr const char* kYadeStartedMarker = "yade_started";

void write_params(const PlannedRun& r) {
    const fs::path params = r.dir / "params.json";
    const std::string p = r.params.dump(2) + "\n";
    if (!fs::exists(params) || read_text_file(params) != p) write_text_file_atomically(params, p);
}

// The run directory holds everything needed to repeat the run by hand: `cd DIR && yade -n -x shear_box.py`; the
// orchestrator runs it through run_clean.py, which removes the temporary directory YADE leaves in /tmp.
void write_run_directory(const PlannedRun& r, const std::string& template_text, const std::string& wrapper_text) {
    fs::create_directories(r.dir);
    const fs::path script = r.dir / "shear_box.py", params = r.dir / "params.json", wrapper = r.dir / kWrapperName;
    if (!fs::exists(script) || read_text_file(script) != template_text) write_text_file_atomically(script, template_text);
    if (!fs::exists(wrapper) || read_text_file(wrapper) != wrapper_text) write_text_file_atomically(wrapper, wrapper_text);
    write_params(r);
}

// A kernel run's directory: params.json and ENGINE, which says which engine ran it and how to repeat it by hand.
void write_kernel_run_directory(const PlannedRun& r, const EngineSetup& engine) {
    fs::create_directories(r.dir);
    std::string how = "engine: " + engine.identity_text + "\nrepeat by hand in this directory:";
    for (const auto& a : engine.command) how += " " + a;
    how += " params.json result.json\n";
    const fs::path file = r.dir / "ENGINE";
    if (!fs::exists(file) || read_text_file(file) != how) write_text_file_atomically(file, how);
    write_params(r);
}

EngineSetup engine_setup(const ShearCampaignSpec& spec, const ExecutionOptions& o) {
    if (spec.engine == ShearEngine::kernel) {
        if (o.kernel_command.empty() || o.kernel_engine.empty())
            throw std::invalid_argument("engine = 'kernel': this program does not say how to run the kernel engine");
        return {o.kernel_engine, "", o.kernel_command, "", ""};
    }
    const fs::path yade = find_yade(o.yade);
    return {read_text_file(spec.template_path),
            read_text_file(yade_script(kWrapperName)),
            {yade.string(), "-n", "-j1", "-x", kWrapperName, "shear_box.py"},
            kYadeStartedMarker,
            yade_build_of(yade)};
}

// The executors append to DIR/stdout.log and DIR/stderr.log and read the failure cause from stderr.log: an earlier
// attempt's "DEMCAL_FAILURE" line would be taken for this attempt's (a retry that succeeded was recorded with the
// failure before it). Each attempt's logs are kept under their own names instead.
void keep_previous_attempt_logs(const fs::path& run_dir, int attempts_so_far) {
    for (const char* log : {"stdout", "stderr"}) {
        const fs::path current = run_dir / (std::string(log) + ".log");
        std::error_code ec;
        if (fs::exists(current, ec))
            fs::rename(current, run_dir / (std::string(log) + ".attempt" + std::to_string(attempts_so_far) + ".log"));
    }
}

// The cause of an attempt whose simulator did not start: its process could not be started (local_executor.cpp: execvp
// failed), or it exited before it started the run (the started marker missing, judge_attempt).
constexpr const char* kSimulatorNotStarted = "exec";

// Physical failures and bad parameters are deterministic: a retry would fail the same way.
bool retry_is_pointless(const std::string& cause) {
    static const std::set<std::string> final_causes = {"nan", "kinetic_energy", "escaped", "normal_stress", "params",
                                                       "no_result", kOutputLimitCause};
    return final_causes.count(cause) > 0;
}

std::unique_ptr<Executor> make_executor(const ExecutionOptions& o, const fs::path& campaign_dir) {
    const int jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
    return orchestrator::make_executor(o.executor, jobs, campaign_dir / "slurm", o.slurm_partition);
}

}  // namespace

std::string pinned_program(const std::string& program, const fs::path& dir) {
    fs::create_directories(dir);
    const fs::path copy = dir / fs::path(program).filename();
    remove_abandoned_temporaries(copy);
    const std::string bytes = read_text_file(program);
    if (fs::exists(copy) && fs::file_size(copy) == bytes.size() && read_text_file(copy) == bytes) return copy.string();
    write_text_file_atomically(copy, bytes);
    fs::permissions(copy, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                              fs::perms::others_read | fs::perms::others_exec);
    return copy.string();
}

void check_run_count(double runs, long max_runs, const std::string& breakdown) {
    if (runs > static_cast<double>(max_runs))
        throw std::invalid_argument(breakdown + " = " + analytics::number_text(runs, 10) + " simulations, more than " +
                                    "the limit --max-runs = " + std::to_string(max_runs) +
                                    " (raise it with --max-runs if that many are meant)");
}

namespace {
// A --template is a YADE script that runs as the stock one: `yade -x SCRIPT params.json result.json` (its arguments,
// or those names). Any file was taken: a JSON file given by mistake started every run, and each failed after YADE's
// start-up. Refused here: a file with a NUL byte (not a script), and one that never names its arguments (sys.argv) nor
// result.json (the file the orchestrator reads).
void check_shear_template_text(const fs::path& file) {
    const std::string text = read_text_file(file);
    const std::string named = "template = '" + analytics::shortened_text(file.string(), 200) + "'";
    if (text.find('\0') != std::string::npos)
        throw std::invalid_argument(named + " holds a NUL byte: not a YADE (Python) script");
    if (text.find("sys.argv") == std::string::npos && text.find("result.json") == std::string::npos)
        throw std::invalid_argument(named + " names neither sys.argv nor result.json: a shear box script reads "
                                    "params.json and writes result.json, its two arguments (see "
                                    "yade_scripts/shear_box.py)");
}
}  // namespace

void validate_shear_spec(const ShearCampaignSpec& spec) {
    if (spec.normal_stresses.empty()) throw std::invalid_argument("normal_stress: at least one normal stress is needed");
    for (double s : spec.normal_stresses)
        if (!(s > 0) || !std::isfinite(s))
            throw std::invalid_argument("normal_stress = " + std::to_string(s) + " Pa must be positive");
    if (spec.replicates < 1 || spec.replicates > kMaxReplicates)
        throw std::invalid_argument("replicates = " + std::to_string(spec.replicates) + " must be between 1 and " +
                                    std::to_string(kMaxReplicates));
    if (spec.base_seed < 0) throw std::invalid_argument("seed = " + std::to_string(spec.base_seed) + " must be >= 0");
    // the replicates take the seeds base_seed, base_seed + 1, ...: the last one named by the options that gave it,
    // not as a run's field the user never typed
    const auto largest_seed = static_cast<long>(find_shear_param("seed")->max);
    if (spec.base_seed > largest_seed - (spec.replicates - 1))
        throw std::invalid_argument("seed = " + std::to_string(spec.base_seed) + " with replicates = " +
                                    std::to_string(spec.replicates) + ": the replicates' packings take the seeds " +
                                    std::to_string(spec.base_seed) + " to " +
                                    std::to_string(spec.base_seed + spec.replicates - 1) + ", and a seed is at most " +
                                    std::to_string(largest_seed) + "; give --seed at most " +
                                    std::to_string(largest_seed - (spec.replicates - 1)));
    // every run's own fields in their ranges (each stress, the last replicate's seed), before anything is written
    const nlohmann::json material = validate_material(spec.material);
    // (named by the option that gave the stress: every campaign command takes its stresses from --normal-stress)
    for (double s : spec.normal_stresses)
        make_run_params(material, s, spec.base_seed + spec.replicates - 1,
                        "the run at --normal-stress " + analytics::number_text(s));
    if (spec.engine != ShearEngine::yade) return;
    // the scripts YADE runs, each named with the folder it was looked for in (an installed copy may lack one)
    if (spec.template_path.empty())
        yade_script("shear_box.py");
    else if (!fs::is_regular_file(spec.template_path))
        throw std::invalid_argument("template = '" + spec.template_path.string() + "' is not a file");
    else
        check_shear_template_text(spec.template_path);
    yade_script(kWrapperName);
}

nlohmann::json read_shear_result(const fs::path& file, const nlohmann::json* run_params) {
    const std::string what = "result = '" + file.string() + "'";
    auto [result, sealed] = read_result_file(file, what);
    if (!result.is_object()) throw std::invalid_argument(what + ": not a JSON object");
    const std::string schema = result.value("schema", std::string());
    // a schema that needs the seal, without it: the seal itself was hit (or the file is not a demcal result)
    if (!sealed && schema != "demcal.shear_result/1")
        throw DamagedResult(what + ": schema " + analytics::shortened_text(schema.empty() ? "(none)" : schema) +
                            " without its SHA-256 seal: damaged or not a demcal result");
    if (!result.contains("peak_shear_stress") || !result["peak_shear_stress"].is_number())
        throw std::invalid_argument(what + ": no number 'peak_shear_stress'");
    check_shear_result_values(result, what, run_params);
    return result;
}

namespace {
// ": seed = 2 where this run has 1": the first field in which a result's recorded params differ from the run's
std::string differing_param(const nlohmann::json& recorded, const nlohmann::json& own) {
    for (const auto& [key, value] : own.items()) {
        if (!recorded.contains(key)) return ": " + analytics::shortened_text(key) + " is missing";
        if (params_digest(recorded[key]) != params_digest(value))
            return ": " + analytics::shortened_text(key) + " = " + analytics::json_value_text(recorded[key]) +
                   " where this run has " + analytics::json_value_text(value);
    }
    for (const auto& [key, value] : recorded.items())
        if (!own.contains(key))
            return ": " + analytics::shortened_text(key) + " = " + analytics::json_value_text(value) +
                   " is not this run's";
    return "";
}
}  // namespace

void check_shear_result_values(const nlohmann::json& result, const std::string& what,
                               const nlohmann::json* run_params) {
    // the stresses a box can hold: a simulator (or a file planted in a run folder) that reports a negative peak or
    // one of 1e99 Pa made a failure line of them, R^2 = 1, exit 0
    const auto number = [&](const char* field) -> std::optional<double> {
        if (!result.contains(field)) return std::nullopt;
        const auto& v = result[field];
        if (!v.is_number() || !std::isfinite(v.get<double>()))
            throw std::invalid_argument(what + ": " + field + " = " + analytics::json_value_text(v) +
                                        " is not a finite number");
        return v.get<double>();
    };
    const std::optional<double> target = number("normal_stress_target");
    if (target && !(*target > 0))
        throw std::invalid_argument(what + ": normal_stress_target = " + analytics::number_text(*target) +
                                    " Pa is not positive");
    for (const char* field : {"peak_shear_stress", "residual_shear_stress"}) {
        const std::optional<double> tau = number(field);
        if (!tau) continue;
        // tau / sigma_n beyond 100 is no granular material's (friction coefficients stay below about 2)
        const double limit = target ? kMaxShearOverNormalStress * *target : analytics::kLargestPlausibleNumber;
        if (*tau < 0 || *tau > limit)
            throw std::invalid_argument(what + ": " + field + " = " + analytics::number_text(*tau) +
                                        " Pa is outside [0, " + analytics::number_text(limit) +
                                        "] (not a shear box's result)");
    }
    // the run's own result, not another run's copied into its folder: by the parameters it records (schema /3, both
    // engines), by their digest (a /2 result of the kernel engine), else by its normal stress (YADE's /2 template
    // recorded no more of its run)
    if (result.contains("schema") && result["schema"] == kShearResultSchema) {  // (any type: a stored row may hold any)
        if (!result.contains("params") || !result["params"].is_object())
            throw std::invalid_argument(what + ": params = " +
                                        (result.contains("params") ? analytics::json_value_text(result["params"])
                                                                   : std::string("<missing>")) +
                                        " is not the object of the run's params.json (schema " + kShearResultSchema +
                                        " records it)");
        if (run_params && params_digest(result["params"]) != params_digest(*run_params))
            throw std::invalid_argument(what + ": the result of a run with other parameters (its params are not this "
                                        "run's" + differing_param(result["params"], *run_params) +
                                        "): another run's result in this run's folder");
    }
    if (result.contains("params_sha256")) {
        const auto& digest = result["params_sha256"];
        if (!digest.is_string() || digest.get<std::string>().size() != 64 ||
            digest.get<std::string>().find_first_not_of("0123456789abcdef") != std::string::npos)
            throw std::invalid_argument(what + ": params_sha256 = " + analytics::json_value_text(digest) +
                                        " is not 64 lowercase hex digits");
        if (run_params && digest.get<std::string>() != params_digest(*run_params))
            throw std::invalid_argument(what + ": the result of a run with other parameters (its params_sha256 is "
                                        "not this run's): another run's result in this run's folder");
    }
    if (run_params && target && run_params->contains("normal_stress") && (*run_params)["normal_stress"].is_number()) {
        const double own = (*run_params)["normal_stress"].get<double>();
        if (std::fabs(*target - own) > 1e-9 * std::fabs(own))
            throw std::invalid_argument(what + ": the result of a run at normal stress " +
                                        analytics::number_text(*target) + " Pa, not of this run's " +
                                        analytics::number_text(own) + " Pa");
    }
}

namespace {
// The result a run left in its directory, if it is a usable one (a damaged one is not: the run is run again).
std::optional<nlohmann::json> finished_result(const RunRecord& run) {
    const fs::path file = run.run_dir / "result.json";
    if (!fs::exists(file)) return std::nullopt;
    try {
        return read_shear_result(file, &run.params);
    } catch (const std::exception&) {
    }
    return std::nullopt;
}
}  // namespace

ShearCampaignRunner::ShearCampaignRunner(const fs::path& dir, ExecutionOptions options)
    : directory_(dir, [](const RunRecord& r) { return finished_result(r); }),
      dir_(directory_.dir()),
      options_(std::move(options)),
      store_(&directory_.store()) {}

ShearCampaignRunner::~ShearCampaignRunner() = default;

namespace {

// The runs a pass has to compute (the campaign and its runs stored before): the pending ones in plan order, the done
// ones counted as reused.
struct PreparedRuns {
    std::deque<std::string> queue;                      // hashes to run
    std::map<std::string, const PlannedRun*> by_hash;  // every distinct run of the plan
    int reused = 0;
};

// Writes every planned run's folder, then stores the campaign with all its runs in one transaction: a kill leaves
// the campaign whole in the store or not there (then the same command starts it again), never with part of its runs.
CampaignRecord store_campaign_with_runs(CampaignStore& store, const std::string& name, const nlohmann::json& spec,
                                        const std::vector<PlannedRun>& plan, ShearEngine engine_kind,
                                        const EngineSetup& engine) {
    std::vector<CampaignStore::RunEntry> entries;
    std::set<std::string> seen;
    for (const auto& r : plan) {
        if (!seen.insert(r.hash).second) continue;  // the same run twice in a plan (repeated stress) runs once
        if (engine_kind == ShearEngine::kernel)
            write_kernel_run_directory(r, engine);
        else
            write_run_directory(r, engine.identity_text, engine.wrapper_text);
        entries.push_back({r.hash, r.params, r.dir, r.label});
    }
    return store.ensure_campaign(name, CampaignKind::shear, spec, entries);
}

PreparedRuns prepare_runs(CampaignStore& store, const std::vector<PlannedRun>& plan, bool force) {
    PreparedRuns p;
    for (const auto& r : plan) {
        if (p.by_hash.count(r.hash)) continue;
        p.by_hash[r.hash] = &r;
        RunRecord rec = *store.run(r.hash);
        if (force && rec.state != RunState::pending) {
            store.reset_to_pending(r.hash, "forced recomputation");
            rec.state = RunState::pending;
        }
        // a failure that is not the physics' verdict (a timeout, a crash, a lost SLURM task) is tried again by a new
        // invocation (resume, or the same command; perhaps with a longer --timeout): one more attempt, then its
        // retries as counted so far
        if (rec.state == RunState::failed && !retry_is_pointless(rec.cause)) {
            store.reset_to_pending(r.hash, "tried again: its last attempt ended by " + rec.cause);
            rec.state = RunState::pending;
        }
        if (rec.state == RunState::done) ++p.reused;
        if (rec.state == RunState::pending) p.queue.push_back(r.hash);
    }
    return p;
}

// What an attempt that ran to its end left: its result (cause empty) or the cause of its failure and a message.
struct AttemptVerdict {
    std::string cause, message;
    nlohmann::json result;
};

// `started_marker`: the file the run writes once its simulator has started ("" if none): a run that failed without
// it never got to its script, and its simulator cannot start here (the machine's fault: kSimulatorNotStarted).
AttemptVerdict judge_attempt(const JobOutcome& o, const fs::path& run_dir, const nlohmann::json& params,
                             const std::string& started_marker) {
    AttemptVerdict v{o.failure_cause, o.message, {}};
    std::error_code ec;
    if (!o.timed_out && !o.interrupted && !started_marker.empty() && v.cause.empty() &&
        !fs::exists(run_dir / started_marker, ec)) {  // (exit 0 too: a launcher that is not YADE's)
        v.cause = kSimulatorNotStarted;
        v.message = "the simulator exited (code " + std::to_string(o.exit_code) + ") before it started the run" +
                    (o.message.empty() ? "" : ": " + o.message);
        return v;
    }
    if (o.succeeded()) {
        try {
            v.result = read_shear_result(run_dir / "result.json", &params);
        } catch (const DamagedResult& e) {
            // damaged between its write and this read (disk, copy): not the run's physics, so run it again
            v.cause = kDamagedResult;
            v.message = std::string("exit code 0 but result.json is damaged: ") + e.what();
        } catch (const std::exception& e) {
            v.cause = "no_result";
            v.message = std::string("exit code 0 but result.json is unusable: ") + e.what();
        }
    } else if (v.cause.empty()) {
        v.cause = "exit_code";
        v.message = "exit code " + std::to_string(o.exit_code) + (v.message.empty() ? "" : ": " + v.message);
    }
    return v;
}

// The time left: the mean wall time of the runs finished in this pass times the runs left, over the slots in use.
double remaining_seconds(const CampaignProgress& prog, double finished_wall, int finished, int slots) {
    if (finished == 0) return -1;
    return (finished_wall / finished) * (prog.pending + 0.5 * prog.running) /
           std::min(slots, std::max(1, prog.pending + prog.running));
}

// The campaign's runs as the store now holds them, its failures and CPU counted, and its status recorded.
void conclude(CampaignStore& store, ShearCampaignOutcome& out) {
    out.runs.clear();
    for (auto& rec : store.campaign_runs(out.campaign.id)) {
        if (rec.state == RunState::failed) ++out.failed;
        if (rec.state == RunState::done) out.cpu_s += rec.cpu_s;
        out.runs.push_back(std::move(rec));
    }
    const bool all_done = std::all_of(out.runs.begin(), out.runs.end(),
                                      [](const RunRecord& r) { return r.state == RunState::done; });
    store.set_campaign_status(out.campaign.id, all_done                               ? CampaignStatus::complete
                                               : out.interrupted                      ? CampaignStatus::interrupted
                                               : !out.infrastructure_failure.empty() ? CampaignStatus::open
                                               : out.failed                           ? CampaignStatus::failed
                                                                                      : CampaignStatus::open);
    out.campaign = *store.find_campaign(out.campaign.name);
}

}  // namespace

namespace {

// One call of ShearCampaignRunner::run once its runs are prepared: hands the queued runs to the executor, records how
// each attempt ended (done, retried, failed for good, interrupted, not started), and reports the progress.
class CampaignExecution {
public:
    CampaignExecution(CampaignStore& store, const ExecutionOptions& options, const EngineSetup& engine,
                      PreparedRuns& runs, ShearCampaignOutcome& out, const ProgressCallback& progress)
        : store_(store), options_(options), engine_(engine), queue_(runs.queue), by_hash_(runs.by_hash), out_(out),
          progress_(progress) {
        prog_.total = static_cast<int>(by_hash_.size());
        prog_.reused = out_.reused;
        prog_.done = out_.reused;
        for (const auto& [h, _] : by_hash_)
            if (store_.run(h)->state == RunState::failed) ++prog_.failed;
        prog_.pending = static_cast<int>(queue_.size());
        slots_ = options_.jobs > 0 ? options_.jobs : std::max(1u, std::thread::hardware_concurrency());
    }

    // Runs the queue on `executor` until it is empty, a run cannot start, or the user interrupts (Ctrl-C, SIGTERM,
    // SIGHUP: the running runs go back to pending).
    void run(Executor& executor) {
        executor_name_ = executor.name();
        InterruptGuard guard;
        ExecutorEvents events;
        events.started = [this](const Job& job, long handle) { started(job, handle); };
        events.finished = [this](const Job& job, const JobOutcome& o) { finished(job, o); };
        if (!queue_.empty()) executor.run([this] { return next_job(); }, events);
        if (interrupted()) out_.interrupted = true;
    }

private:
    std::optional<Job> next_job() {
        if (queue_.empty() || !out_.infrastructure_failure.empty()) return std::nullopt;
        const std::string h = queue_.front();
        queue_.pop_front();
        const PlannedRun& r = *by_hash_.at(h);
        fs::remove(r.dir / "result.json");  // a result (and the simulator's start) must come from this attempt
        if (!engine_.started_marker.empty()) fs::remove(r.dir / engine_.started_marker);
        keep_previous_attempt_logs(r.dir, store_.run(h)->attempts);
        std::vector<std::string> argv = engine_.command;
        argv.insert(argv.end(), {"params.json", "result.json"});
        return Job{h, r.dir, std::move(argv), options_.timeout_s};
    }

    void started(const Job& job, long handle) {
        store_.mark_running(job.id, handle, ::getpid(), executor_name_);
        --prog_.pending;
        ++prog_.running;
        report("started", job.id);
    }

    void finished(const Job& job, const JobOutcome& o) {
        --prog_.running;
        if (o.interrupted) {
            store_.reset_to_pending(job.id, "interrupted by the user");
            ++prog_.pending;
            out_.interrupted = true;
            report("interrupted", job.id);
            return;
        }
        finished_wall_ += o.wall_s;
        ++finished_here_;
        const AttemptVerdict v = judge_attempt(o, job.dir, by_hash_.at(job.id)->params, engine_.started_marker);
        if (v.cause.empty()) {
            if (!engine_.build.empty()) store_.set_setting_once(kYadeBuildSetting, engine_.build);
            store_.mark_done(job.id, v.result, o.exit_code, o.wall_s, o.cpu_s);
            ++out_.executed;
            ++prog_.done;
            report("done", job.id);
        } else if (v.cause == kSimulatorNotStarted) {
            // the machine's fault, not the run's: the run stays pending for a resume with a working simulator, and
            // no further run is started (each would fail the same way)
            store_.mark_attempt_failed(job.id, v.cause, v.message, o.exit_code, o.wall_s, o.cpu_s, false);
            ++prog_.pending;
            if (out_.infrastructure_failure.empty()) out_.infrastructure_failure = v.message;
            report("not started", job.id);
        } else {
            failed(job, o, v);
        }
    }

    // An attempt the run itself failed: tried again, or failed for good (a physical failure, or no retries left).
    void failed(const Job& job, const JobOutcome& o, const AttemptVerdict& v) {
        const int attempts = store_.run(job.id)->attempts;
        const bool final = retry_is_pointless(v.cause) || attempts > options_.retries;
        store_.mark_attempt_failed(job.id, v.cause, v.message, o.exit_code, o.wall_s, o.cpu_s, final);
        if (final) {
            ++prog_.failed;
            report("failed", job.id);
        } else {
            queue_.push_back(job.id);
            ++prog_.pending;
            report("retry", job.id);
        }
    }

    void report(const std::string& event, const std::string& hash) {
        if (!progress_) return;
        prog_.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        prog_.remaining_s = remaining_seconds(prog_, finished_wall_, finished_here_, slots_);
        prog_.event = event;
        std::optional<RunRecord> rec = store_.run(hash);
        if (rec) rec->label = by_hash_.at(hash)->label;
        prog_.run = rec ? &*rec : nullptr;
        progress_(prog_);
        prog_.run = nullptr;
    }

    CampaignStore& store_;
    const ExecutionOptions& options_;
    const EngineSetup& engine_;
    std::deque<std::string>& queue_;
    const std::map<std::string, const PlannedRun*>& by_hash_;
    ShearCampaignOutcome& out_;
    const ProgressCallback& progress_;
    std::string executor_name_;
    CampaignProgress prog_;
    int slots_ = 1;
    const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
    double finished_wall_ = 0;  // of the attempts that ended here (the estimate of the time left)
    int finished_here_ = 0;
};

}  // namespace

ShearCampaignOutcome ShearCampaignRunner::run(const ShearCampaignSpec& spec_in, const ProgressCallback& progress) {
    validate_shear_spec(spec_in);
    const ShearCampaignSpec spec = resolved(spec_in);
    EngineSetup engine = engine_setup(spec, options_);
    if (spec.engine == ShearEngine::kernel) engine.command[0] = pinned_program(engine.command[0], dir_ / ".kernel-engine");
    if (!engine.build.empty()) check_store_yade_build(*store_, engine.build, options_.yade);
    const auto plan = plan_runs(spec, engine.identity_text, dir_);

    ShearCampaignOutcome out;
    // a campaign made before the stresses were sorted and the numbers named by value keeps the name it was given
    // (the stresses in the order typed, the numbers as written): continued, not doubled (review of stop 61)
    ShearCampaignSpec as_typed = spec;
    as_typed.normal_stresses = spec_in.normal_stresses;
    const std::string name = campaign_name(spec), legacy = legacy_campaign_name(as_typed);
    const bool typed_campaign = legacy != name && store_->find_campaign(legacy).has_value();
    out.campaign = typed_campaign
                       ? store_campaign_with_runs(*store_, legacy, as_typed.to_json(), plan, spec.engine, engine)
                       : store_campaign_with_runs(*store_, name, spec.to_json(), plan, spec.engine, engine);
    PreparedRuns runs = prepare_runs(*store_, plan, options_.force);
    out.reused = runs.reused;
    auto executor = make_executor(options_, dir_);
    CampaignExecution(*store_, options_, engine, runs, out, progress).run(*executor);
    conclude(*store_, out);
    return out;
}

namespace {
// Whether a shear campaign stored complete is: every run its spec plans is in the store, and done. A store edited or
// damaged by hand (a run's row deleted, a run set back to pending) was shown complete and skipped by resume, whose
// report then lost its line (held-back probe 65): its runs decide, not its stored status.
bool complete_by_its_runs(const CampaignRecord& c, const std::vector<RunRecord>& runs) {
    if (c.status != CampaignStatus::complete) return false;
    // every planned (stress, replicate) done; a campaign may hold more runs than planned (the same spec run again
    // on another engine identity or script links the new runs beside the old: review of stop 65)
    const ShearCampaignSpec spec = ShearCampaignSpec::from_json(c.spec);
    std::set<std::pair<double, int>> missing;
    for (double sigma : spec.normal_stresses)
        for (int rep = 0; rep < spec.replicates; ++rep) missing.insert({sigma, rep});
    for (const auto& r : runs) {
        if (r.state != RunState::done) return false;
        if (r.label.contains("normal_stress") && r.label.contains("replicate") && r.label["normal_stress"].is_number() &&
            r.label["replicate"].is_number_integer())
            missing.erase({r.label["normal_stress"].get<double>(), r.label["replicate"].get<int>()});
    }
    return missing.empty();
}
}  // namespace

std::vector<ShearCampaignOutcome> ShearCampaignRunner::resume(const ProgressCallback& progress) {
    std::vector<ShearCampaignOutcome> outs;
    for (const auto& c : store_->campaigns()) {
        if (c.kind != CampaignKind::shear || complete_by_its_runs(c, store_->campaign_runs(c.id))) continue;
        outs.push_back(run(ShearCampaignSpec::from_json(c.spec), progress));
        if (outs.back().interrupted) break;
    }
    return outs;
}

namespace {
void check_shear_specs_of(const std::vector<CampaignRecord>& campaigns, const fs::path& file) {
    for (const auto& c : campaigns) {
        if (c.kind != CampaignKind::shear) continue;
        try {
            ShearCampaignSpec::from_json(c.spec);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("campaign store '" + file.string() + "': campaign " + std::to_string(c.id) +
                                        ": " + e.what() + "; nothing was written to it");
        }
    }
}
}  // namespace

void check_stored_shear_specs(const fs::path& dir) {
    const fs::path file = dir / "campaign.sqlite";
    CampaignStore store(file, StoreAccess::read_only);
    check_shear_specs_of(store.campaigns(), file);
}

std::vector<ShearCampaignOutcome> inspect_campaigns(const fs::path& dir) {
    if (!fs::exists(dir / "campaign.sqlite"))
        throw std::invalid_argument("campaign = '" + dir.string() + "' holds no campaign.sqlite");
    CampaignStore store(dir / "campaign.sqlite", StoreAccess::read_only);
    const std::vector<CampaignRecord> campaigns = store.campaigns();
    check_shear_specs_of(campaigns, dir / "campaign.sqlite");  // before anything of them is printed
    std::vector<ShearCampaignOutcome> outs;
    for (const auto& c : campaigns) {
        ShearCampaignOutcome o;
        o.campaign = c;
        o.runs = store.campaign_runs(c.id);
        if (c.kind == CampaignKind::shear && c.status == CampaignStatus::complete && !complete_by_its_runs(c, o.runs))
            o.campaign.status = CampaignStatus::open;  // (what resume makes of it)
        for (const auto& r : o.runs) {
            if (r.state == RunState::failed) ++o.failed;
            // the CPU the campaign spent: failed runs' too (a campaign of failed runs showed "CPU 0s")
            if (r.state == RunState::done || r.state == RunState::failed) o.cpu_s += r.cpu_s;
        }
        outs.push_back(std::move(o));
    }
    return outs;
}

}  // namespace demcal::orchestrator
