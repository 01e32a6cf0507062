#include "app/cli_support.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"
#include "app/commands.hpp"
#include "app/result_files.hpp"  // same_file_as_descriptor
#include "orchestrator/slurm_executor.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <string_view>
#include <thread>

#include <climits>
#include <sys/stat.h>
#include <unistd.h>

namespace demcal {

nlohmann::json read_json_file(const std::string& path, const std::string& field) {
    try {
        return analytics::read_json_input(path, field);
    } catch (const analytics::InputError& e) {
        throw UserError(e.what());
    }
}

namespace {

constexpr const char* kEmptyValue = "an empty value (omit the option to get its default)";
constexpr const char* kEmptyRequiredValue = "an empty value (this option has no default: give a value)";

// A validator that accepts a number for which `ok` holds; `what` completes "VALUE is not ...". The text is read by
// strtod, so a subnormal or an overflowing exponent is named as such by analytics::number_defect, not as "not a
// number".
CLI::Validator number_check(const std::string& what, std::function<bool(double)> ok) {
    return CLI::Validator(
        [what, ok](std::string& text) -> std::string {
            if (text.empty()) return kEmptyValue;
            const std::string shown = "'" + analytics::shortened_text(text) + "'";
            const auto n = analytics::read_typed_number(text);
            if (!n.is_number) return shown + " is not a number";
            if (n.defect) return shown + " " + *n.defect;
            const double v = n.value;
            if (!ok(v)) return analytics::shortened_text(text) + " is not " + what;
            // -0 is 0: one value, one run (`vibration --frequency 0,-0` planned the same still bin twice); takes
            // effect where the check is a transform (refuse_empty_values)
            if (v == 0.0 && std::signbit(v)) text = "0";
            return {};
        },
        what);
}

}  // namespace

CLI::Validator integer_in(long long lo, long long hi) {
    const std::string what = "an integer between " + std::to_string(lo) + " and " + std::to_string(hi);
    return CLI::Validator(
        [what, lo, hi](std::string& text) -> std::string {
            if (text.empty()) return kEmptyValue;
            long long v = 0;
            const char* begin = text.c_str() + (text.front() == '+' ? 1 : 0);
            const auto [end, ec] = std::from_chars(begin, text.c_str() + text.size(), v);
            const std::string shown = "'" + analytics::shortened_text(text) + "'";
            if (end != text.c_str() + text.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
                return shown + " is not an integer";
            // CLI11 converts integers as C does: "0400" was octal 256 (--particles 0400 ran 256 grains)
            const char* digits = begin + (*begin == '-' ? 1 : 0);
            if (digits[0] == '0' && digits[1] != '\0')
                return shown + " has a leading zero (read as octal by the converter): write it without";
            // out of range of a long long (a seed above 2^63 was silently clamped to 2^63 - 1)
            if (ec == std::errc::result_out_of_range || v < lo || v > hi) return shown + " is not " + what;
            return {};
        },
        what);
}

void refuse_empty_values(CLI::App& app) {
    // An option's type as CLI11 names it: every number option follows the number rule and every integer option the
    // integer rule, whatever checks its command adds (one place: an option registered without a check was read by
    // CLI11 alone, which lets NaN, subnormals and 1e308 through and echoes a 100 kB value in full).
    // No description: the type name says it, and "an integer between -9223372036854775808 and ..." in every
    // option's help says nothing a user needs.
    CLI::Validator any_number = number_check("a number", [](double) { return true; });
    CLI::Validator slurm_partition(
        [](std::string& text) {
            const std::string defect = orchestrator::slurm_partition_defect(text);
            return defect.empty() ? std::string() : "'" + analytics::shortened_text(text) + "': " + defect;
        },
        "");
    CLI::Validator any_integer = integer_in(std::numeric_limits<long long>::min(),
                                            std::numeric_limits<long long>::max());
    any_number.description("");
    any_integer.description("");
    for (CLI::Option* opt : app.get_options()) {
        if (opt->get_type_size_max() <= 0) continue;  // a flag takes no value
        const std::string type = opt->get_type_name();
        // (a type name carries the descriptions of the option's own checks after a ':': "FLOAT:between 0 and 90")
        const auto of_type = [&type](const std::string& t) { return type == t || type.rfind(t + ":", 0) == 0; };
        const bool real = of_type("FLOAT"), whole = of_type("INT") || of_type("UINT");
        if (real) opt->transform(any_number);  // a transform: -0 becomes 0
        else if (whole) opt->check(any_integer);
        // blanks around a number are no part of it, as in a list (`--timeout " 5"` was "not a number", probe 63);
        // a transform added later runs earlier: this runs before the number's checks
        if (real || whole)
            opt->transform(CLI::Validator([](std::string& text) { return text = analytics::trimmed(text), std::string(); },
                                          ""));
        if (opt->check_lname("partition")) opt->check(slurm_partition);  // every command's SLURM partition
        // First of all the option's checks (a transform goes before the others): the option's own check named an
        // empty value by its rule ("--criterion:  not in {...}") instead of as empty.
        // (a required option has no default to omit it for). Blanks only are no value either: `--json " "` wrote a
        // file named " ", `-c " "` a campaign folder so named (probe 63).
        const std::string empty_rule = opt->get_required() ? kEmptyRequiredValue : kEmptyValue;
        opt->transform(CLI::Validator(
            [empty_rule](std::string& text) {
                if (text.empty()) return empty_rule;
                return analytics::trimmed(text).empty() ? "'" + analytics::shortened_text(text) + "': blanks only, " +
                                                              empty_rule
                                                        : std::string();
            },
            ""));
    }
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) refuse_empty_values(*sub);
}

void read_values_strictly(CLI::App& app) {
    std::set<std::string> names{"--"};
    for (const CLI::Option* opt : app.get_options()) {
        for (const std::string& l : opt->get_lnames()) names.insert("--" + l);
        for (const std::string& s : opt->get_snames()) names.insert("-" + s);
    }
    const CLI::Validator not_an_option(
        [names](std::string& text) {
            const std::string name = text.substr(0, text.find('='));
            return names.count(name) ? "'" + analytics::shortened_text(text) + "' is an option of this command, not " +
                                           "a value: the value is missing"
                                     : std::string();
        },
        "");
    // blanks around a list's items are no part of them: "5e3, 1e4" (probe 61: ' 1e4' was refused); added last, so
    // it runs before every other check of the value (CLI11 runs the transforms added last first)
    const CLI::Validator item_blanks_dropped(
        [](std::string& item) {
            item = analytics::trimmed(item);
            return std::string();
        },
        "");
    for (CLI::Option* opt : app.get_options()) {
        if (opt->get_type_size_max() <= 0 || !opt->nonpositional()) continue;  // a flag; the words after --
        if (opt->get_items_expected_max() > 1) opt->allow_extra_args(false);
        opt->transform(not_an_option);
        if (opt->get_delimiter() == ',') opt->transform(item_blanks_dropped);
    }
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) read_values_strictly(*sub);
}

namespace {
// An option of `cmd` by its long name, or nullptr if the command has none.
const CLI::Option* option_named(const CLI::App& cmd, const std::string& name) {
    for (const CLI::Option* opt : cmd.get_options())
        if (opt->check_lname(name)) return opt;
    return nullptr;
}

// The value an option ended with: the one given, else its default (an empty default: `fallback`).
std::string value_or_default(const CLI::Option& opt, const std::string& fallback) {
    if (opt.count() > 0) return opt.as<std::string>();
    const std::string d = opt.get_default_str();
    return d.empty() ? fallback : d;
}

// An option that takes effect only when another option has a given value (the other's default when it is not given).
struct OptionNeeds {
    const char* option;
    const char* other;
    const char* value;
    const char* other_default;
    const char* what;  // what the option is, for the message
};
constexpr OptionNeeds kOptionNeeds[] = {
    {"partition", "executor", "slurm", "local", "a SLURM partition"},
    {"yade", "engine", "yade", "yade", "YADE's launcher"},
    {"grid-points", "method", "grid", "surrogate", "the grid's points per parameter"},
    {"sequential", "method", "surrogate", "surrogate", "the surrogate loop's order (slope, then cohesion)"},
    {"alpha", "criterion", "f-test", "f-test", "the F tests' significance level"},
};

// An option that one value of another option makes void (the opposite of OptionNeeds).
struct OptionVoidWith {
    const char* option;
    const char* other;
    const char* value;
    const char* what;  // what the option is
    const char* why;   // why that value leaves it nothing to do
};
constexpr OptionVoidWith kOptionVoidWith[] = {
    {"max-evaluations", "method", "grid", "the search's budget of failure lines",
     "a grid evaluates all of its --grid-points per control"},
};

// `--option = 'value'`, or `--option` for a flag (which has no value to show).
std::string given_text(const CLI::Option& opt, const char* name) {
    if (opt.get_expected_max() == 0) return std::string("--") + name;
    return std::string("--") + name + " = '" + analytics::shortened_text(opt.as<std::string>()) + "'";
}

// Two options of which the second makes the first void: given together, one was ignored (silo's --dt with
// --dt-fraction recorded a fraction it did not run; --plot svg with --no-plot drew nothing).
struct ExclusiveOptions {
    const char* option;
    const char* other;
};
constexpr ExclusiveOptions kExclusiveOptions[] = {{"dt-fraction", "dt"}, {"plot", "no-plot"}};

// A local pool of --jobs runs takes that many cores and the memory of as many simulations (YADE: about 250 MB each):
// `-j 1000` on a laptop is a typo that takes the machine down, not a plan. Four per core leaves room to oversubscribe
// on purpose; a batch system takes any number (--executor slurm).
constexpr unsigned kMaxLocalJobsPerCore = 4;

void check_local_jobs(const CLI::App& cmd) {
    const CLI::Option* jobs = option_named(cmd, "jobs");
    if (!jobs || jobs->count() == 0) return;
    const CLI::Option* executor = option_named(cmd, "executor");
    if (executor && value_or_default(*executor, "local") != "local") return;
    double asked = 0;
    try {
        asked = jobs->as<double>();  // (an integer already: the option's own check ran during the parse)
    } catch (const CLI::Error&) {
        return;
    }
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    if (asked <= double(kMaxLocalJobsPerCore) * cores) return;
    throw UserError("--jobs = " + analytics::shortened_text(jobs->as<std::string>()) + ": the local pool would run " +
                    "that many simulations at once on this machine's " + std::to_string(cores) + " cores; at most " +
                    std::to_string(kMaxLocalJobsPerCore) + " per core (" +
                    std::to_string(kMaxLocalJobsPerCore * cores) + "), 0 for one per core" +
                    (executor ? "; --executor slurm spreads more over a cluster" : ""));
}

void check_options_apply(const CLI::App& cmd) {
    for (const OptionNeeds& rule : kOptionNeeds) {
        const CLI::Option* opt = option_named(cmd, rule.option);
        const CLI::Option* other = option_named(cmd, rule.other);
        if (!opt || !other || opt->count() == 0) continue;
        const std::string value = value_or_default(*other, rule.other_default);
        if (value == rule.value) continue;
        throw UserError(given_text(*opt, rule.option) + " is " + rule.what + ": it applies to --" + rule.other + " " +
                        rule.value + " only (this command runs with --" + rule.other + " " + value + ")");
    }
    for (const OptionVoidWith& rule : kOptionVoidWith) {
        const CLI::Option* opt = option_named(cmd, rule.option);
        const CLI::Option* other = option_named(cmd, rule.other);
        if (!opt || !other || opt->count() == 0 || other->count() == 0 || other->as<std::string>() != rule.value)
            continue;
        throw UserError(given_text(*opt, rule.option) + " is " + rule.what + ", void with --" + rule.other + " " +
                        rule.value + ": " + rule.why + "; leave it out");
    }
    for (const ExclusiveOptions& pair : kExclusiveOptions) {
        const CLI::Option* opt = option_named(cmd, pair.option);
        const CLI::Option* other = option_named(cmd, pair.other);
        if (opt && other && opt->count() > 0 && other->count() > 0)
            throw UserError(std::string("--") + pair.option + " and --" + pair.other + ": --" + pair.other +
                            " makes --" + pair.option + " void; give one of the two");
    }
    check_local_jobs(cmd);
    // SLURM asked for where it is not installed: refused before a campaign is written (it was after, exit 2 all the
    // same, with a store, run folders and a program copy left)
    if (const CLI::Option* executor = option_named(cmd, "executor");
        executor && executor->count() > 0 && executor->as<std::string>() == "slurm" && !orchestrator::sbatch_on_path())
        throw UserError("--executor slurm: sbatch is not on PATH (install slurm-client and reach a SLURM controller, "
                        "or run on --executor local)");
    for (const CLI::App* sub : cmd.get_subcommands()) check_options_apply(*sub);
}
}  // namespace

void refuse_inapplicable_options(CLI::App& app) {
    app.parse_complete_callback([&app] { check_options_apply(app); });
}

void check_argument_lengths(int argc, const char* const* argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg(argv[i]);
        if (arg.size() <= kMaxArgumentChars) continue;
        std::string named = "argument " + std::to_string(i);
        if (arg.rfind("--", 0) == 0 && arg.find('=') != std::string_view::npos)
            named = std::string(arg.substr(0, std::min(arg.find('='), std::size_t(40))));
        else if (i > 1 && argv[i - 1][0] == '-' && std::string_view(argv[i - 1]).size() <= 40)
            named = argv[i - 1];
        throw UserError(named + ": '" + analytics::shortened_text(arg) + "' is longer than " +
                        std::to_string(kMaxArgumentChars) + " characters (no path, number or list of demcal is)");
    }
}

CLI::Validator number_in(double lo, double hi) {
    return number_check("between " + analytics::number_text(lo) + " and " + analytics::number_text(hi),
                        [lo, hi](double v) { return v >= lo && v <= hi; });
}

CLI::Validator run_timeout() {
    return number_check("a number of seconds from " + analytics::number_text(kMinRunTimeout) + " to " +
                            analytics::number_text(kMaxRunTimeout),
                        [](double v) { return v >= kMinRunTimeout && v <= kMaxRunTimeout; });
}

CLI::Validator positive_number() {
    return number_check("a positive number", [](double v) { return v > 0; });
}

CLI::Validator non_negative_number() {
    return number_check("a number >= 0", [](double v) { return v >= 0; });
}

namespace {

// Whether a file can be created in `folder`, tried for real: access(2) says yes to root in /proc or in a folder
// mounted read-only by some file systems. The probe is removed at once.
bool can_create_files_in(const std::filesystem::path& folder) {
    std::string probe = (folder / ".demcal-write-probe-XXXXXX").string();
    const int fd = ::mkstemp(probe.data());
    if (fd < 0) return false;
    ::close(fd);
    ::unlink(probe.c_str());
    return true;
}

// Room demcal needs beyond an output's own name and path: its temporary copies (".tmp" and a process id) and the
// files it writes beside an output under derived names ("_residuals.png", ...).
constexpr std::size_t kDerivedNameChars = 40;

// Refuses a path the file system would refuse only when the first file is written, hours later ("File name too
// long"): a name longer than NAME_MAX (a file's own name less the room for its derived names), or a whole path that
// leaves no room below PATH_MAX for the files demcal writes into it.
enum class PathKind { file, folder };
void check_name_lengths(const std::string& path, const std::string& named, PathKind kind) {
    namespace fs = std::filesystem;
    // (here, where every output path is first looked at: a name demcal cannot pass on is as unusable as a long one)
    if (analytics::has_control_character(path))
        throw UserError(named + ": the path holds a control character (a newline, a tab): no batch script, plot or "
                        "log line can name it; give a path without one");
    const fs::path p(path);
    for (const fs::path& part : p) {
        const bool own_name = kind == PathKind::file && part == p.filename();
        const std::size_t most = own_name ? NAME_MAX - kDerivedNameChars : NAME_MAX;
        if (part.native().size() > most)
            throw UserError(named + ": a name in the path is " + std::to_string(part.native().size()) +
                            " characters long; at most " + std::to_string(most) + " (the file system takes " +
                            std::to_string(NAME_MAX) +
                            (own_name ? ", demcal adds up to " + std::to_string(kDerivedNameChars) +
                                            " for its temporary and side files)"
                                      : ")"));
    }
    std::error_code ec;
    const std::size_t whole = fs::absolute(p, ec).native().size();
    if (whole + 2 * kDerivedNameChars > PATH_MAX)
        throw UserError(named + ": the path is " + std::to_string(whole) + " characters long as an absolute path; at most " +
                        std::to_string(PATH_MAX - 2 * kDerivedNameChars));
}

}  // namespace

namespace {
// An existing output is replaced by a rename over it (a result is never half-written). In a folder with the sticky bit
// (as /tmp) only the file's or the folder's owner may do that: another user's file there passed every check, then
// failed the command after its work with "Operation not permitted". Followed through a link, as the write is.
void check_replaceable(const std::string& path, const std::string& named) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path target = fs::canonical(path, ec);
    if (ec) return;  // not there yet: created, not replaced
    const fs::path folder = target.parent_path();
    struct stat file_st {}, folder_st {};
    if (::stat(target.c_str(), &file_st) != 0 || ::stat(folder.c_str(), &folder_st) != 0) return;
    const uid_t me = ::geteuid();
    if ((folder_st.st_mode & S_ISVTX) && me != 0 && file_st.st_uid != me && folder_st.st_uid != me)
        throw UserError(named + ": another user's file in " + analytics::shortened_text(folder.string(), 200) +
                        ", a folder with the sticky bit (as /tmp), where only its owner may replace it; give "
                        "another name");
}
}  // namespace

namespace {
// A campaign's own files are never a command's output: `calibrate -o CAMPAIGN/campaign.sqlite` replaced a store of
// finished runs with a material's JSON, `scale -o DIR/runs/ID/result.json` a stored run's result. Refused: a file that
// is an SQLite database (its header), a store's name or side file (campaign.sqlite, -wal, -shm, -journal), and any
// (check_output_outside_run_folders: a run's folder, for the commands a campaign does not run itself).
void refuse_campaign_files(const std::string& path, const std::string& named) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const std::string name = fs::path(path).filename().string();
    for (const char* store : {"campaign.sqlite", "campaign.sqlite-wal", "campaign.sqlite-shm", "campaign.sqlite-journal"})
        if (name == store)
            throw UserError(named + " is a campaign store's file name: a command's output is never written over a "
                            "store; give another name");
    if (fs::is_regular_file(path, ec)) {
        char header[16] = {};
        std::ifstream in(path, std::ios::binary);
        if (in.read(header, sizeof header) && std::string(header, sizeof header) == std::string("SQLite format 3\0", 16))
            throw UserError(named + " is an SQLite database (a campaign store?): a command's output is never written "
                            "over one; give another name");
    }
}
}  // namespace

void check_output_outside_run_folders(const std::string& path, const std::string& option) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path run_folder = fs::weakly_canonical(fs::absolute(path, ec), ec).parent_path();
    const fs::path campaign = run_folder.parent_path().parent_path();
    if (!ec && run_folder.parent_path().filename() == "runs" &&
        (fs::exists(campaign / "campaign.sqlite", ec) || fs::exists(campaign / "campaign.json", ec)))
        throw UserError(option + " = '" + analytics::shortened_text(path, 200) + "' lies in the run folder " +
                        run_folder.string() + " of the campaign " + campaign.string() +
                        ": a run's files are its own; give a path outside it");
}

namespace {
// A path ending in '/' names a folder ("/dev/stdout/" was told that the folder /dev/stdout does not exist; predict
// --json out/ made the folder out, did its work and failed on the write, probe 63).
void refuse_folder_name(const std::string& path, const std::string& named) {
    if (!path.empty() && path.back() == '/')
        throw UserError(named + " ends with '/', a folder's name; give a file name");
}

// An output that is the very file a standard stream is redirected to, by its own name or through a link
// (`--report r.md > r.md`, a link to /dev/stderr): written whole through a rename, it replaced what the command
// printed there (probe 63).
void refuse_standard_stream_file(const std::string& path, const std::string& named) {
    for (const auto& [fd, stream] : {std::pair{1, "standard output"}, std::pair{2, "standard error"}})
        if (same_file_as_descriptor(path, fd))
            throw UserError(named + " is the file " + stream + " is redirected to; give another file" +
                            (fd == 1 && named.rfind("--json", 0) == 0 ? " (or -: standard output)" : ""));
}
}  // namespace

bool names_process_stream(const std::string& absolute) {
    static const std::regex stream(R"(/dev/(stdin|stdout|stderr|fd/.*)|/proc/[^/]+(/task/[^/]+)?/fd/.*)");
    return std::regex_match(absolute, stream);
}

void check_output_file(const std::string& path, const std::string& option) {
    namespace fs = std::filesystem;
    const std::string named = option + " = '" + analytics::shortened_text(path, 200) + "'";
    if (path.empty()) throw UserError(option + ": an empty path");
    // "-" is standard output where a command takes it so (predict's and diagnose's --json); elsewhere it wrote a file
    // named - (probe 62b)
    if (path == "-")
        throw UserError(named + ": standard output is no place for this output (only predict's and diagnose's --json "
                        "write there); give a file name (./- for a file named so)");
    check_name_lengths(path, named, PathKind::file);
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw UserError(named + " is a folder; give a file name");
    refuse_folder_name(path, named);
    // /dev/stderr, /proc/self/fd/2: a stream's name, not a file's. Where the stream was redirected to a file, that
    // file was replaced whole (a result is written to a temporary file and renamed), the lines before it lost.
    const std::string absolute = fs::absolute(path, ec).lexically_normal().string();
    if (names_process_stream(absolute))  // (a file in /dev/shm, or /proc/self/cwd/x, is a file)
        throw UserError(named + " names a process's stream, not a regular file; give a file name");
    const fs::file_status st = fs::status(path, ec);  // (through a link: what the output would be written into)
    if (fs::exists(st) && !fs::is_regular_file(st))
        throw UserError(named + " is not a regular file (a device, FIFO or socket); give a file name");
    refuse_standard_stream_file(path, named);
    if (fs::is_symlink(fs::symlink_status(path, ec)) && !fs::exists(st))
        throw UserError(named + " is a link to nothing (" +
                        analytics::shortened_text(fs::read_symlink(path, ec).string(), 200) + "); give a file name");
    const fs::path folder = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
    if (!fs::is_directory(folder, ec)) throw UserError(named + ": the folder " + folder.string() + " does not exist");
    if (!can_create_files_in(folder))
        throw UserError(named + ": the folder " + folder.string() + " is not writable");
    if (fs::exists(path, ec) && ::access(path.c_str(), W_OK) != 0) throw UserError(named + " is not writable");
    check_replaceable(path, named);
    refuse_campaign_files(path, named);
}

namespace {
// Where files below `folder` will be created: `folder` itself when it exists, else the nearest existing folder above
// it (the command creates the rest); it must be a folder in which files can be created. `named`: the option and
// the path as given, for the message.
void check_files_can_be_created_below(const std::filesystem::path& folder, const std::string& named) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path existing = fs::absolute(folder, ec).lexically_normal();
    if (ec) throw UserError(named + ": " + ec.message());
    while (!fs::exists(existing, ec) && existing.has_parent_path() && existing.parent_path() != existing)
        existing = existing.parent_path();
    if (!fs::is_directory(existing, ec))
        throw UserError(named + ": " + existing.string() + " is a file, so the folder cannot be created");
    if (!can_create_files_in(existing)) throw UserError(named + ": " + existing.string() + " is not writable");
}
}  // namespace

void check_output_folder(const std::string& path, const std::string& option) {
    namespace fs = std::filesystem;
    const std::string named = option + " = '" + analytics::shortened_text(path, 200) + "'";
    if (path.empty()) throw UserError(option + ": an empty path");
    check_name_lengths(path, named, PathKind::folder);
    std::error_code ec;
    if (fs::is_symlink(fs::symlink_status(path, ec)) && !fs::exists(path, ec))  // ("File exists" when made: probe 60)
        throw UserError(named + " is a symbolic link to '" +
                        analytics::shortened_text(fs::read_symlink(path, ec).string(), 200) +
                        "', which does not exist: make its target, or give another folder");
    if (fs::exists(path, ec) && !fs::is_directory(path, ec)) throw UserError(named + " is a file, not a folder");
    check_files_can_be_created_below(path, named);
}

void check_output_file_in_new_folders(const std::string& path, const std::string& option) {
    namespace fs = std::filesystem;
    if (path.empty()) return;
    std::error_code ec;
    const std::string named = option + " = '" + analytics::shortened_text(path, 200) + "'";
    refuse_folder_name(path, named);
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty() || fs::exists(parent, ec)) return check_output_file(path, option);
    check_name_lengths(path, named, PathKind::file);
    check_files_can_be_created_below(parent, named);
}

std::filesystem::path without_trailing_separator(const std::filesystem::path& p) {
    // "dir/" and "dir/." are the folder dir: lexically_normal keeps an empty last part that no comparison matches
    return p.has_filename() || !p.has_parent_path() || p == p.root_path() ? p : p.parent_path();
}

void check_output_in_campaign_or_existing_folder(const std::string& path, const std::string& option,
                                                 const std::string& campaign_dir) {
    namespace fs = std::filesystem;
    const fs::path parent = without_trailing_separator(fs::absolute(fs::path(path)).lexically_normal().parent_path());
    const fs::path campaign = without_trailing_separator(fs::absolute(fs::path(campaign_dir)).lexically_normal());
    const auto [end, rest] = std::mismatch(campaign.begin(), campaign.end(), parent.begin(), parent.end());
    if (!campaign_dir.empty() && end == campaign.end())  // the campaign folder or below: the command makes it
        return check_output_file_in_new_folders(path, option);
    check_output_file(path, option);
}

namespace {
// The path as the file system resolves it (absolute, "." and ".." and links of its existing part resolved), so that
// two spellings of one file compare equal.
std::filesystem::path resolved(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
    if (ec) p = fs::absolute(path, ec).lexically_normal();
    return p;
}
std::string quoted_path(const std::string& path) { return "'" + analytics::shortened_text(path, 200) + "'"; }
}  // namespace

void check_paths_apart(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
    std::vector<std::filesystem::path> out_resolved;
    for (const NamedPath& o : outputs) out_resolved.push_back(o.path.empty() ? std::filesystem::path() : resolved(o.path));
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        if (outputs[i].path.empty()) continue;
        for (const NamedPath& in : inputs)
            if (!in.path.empty() && resolved(in.path) == out_resolved[i])
                throw UserError(outputs[i].option + " = " + quoted_path(outputs[i].path) + " is the input " + in.option +
                                " (" + quoted_path(in.path) + "): it would be overwritten; give another path");
        for (std::size_t k = 0; k < i; ++k)
            if (!outputs[k].path.empty() && out_resolved[k] == out_resolved[i])
                throw UserError(outputs[i].option + " = " + quoted_path(outputs[i].path) + " is also " +
                                outputs[k].option + " (" + quoted_path(outputs[k].path) +
                                "): one output would overwrite the other; give another path");
    }
}

std::string with_data_option(const std::string& message) {
    return message.rfind("data file ", 0) == 0 ? "--data: " + message : message;
}

std::string with_option_name(const CLI::App& app, const std::string& message) {
    std::size_t n = 0;
    while (n < message.size() && (std::islower(static_cast<unsigned char>(message[n])) ||
                                  std::isdigit(static_cast<unsigned char>(message[n])) || message[n] == '_' ||
                                  message[n] == '-'))
        ++n;
    if (n == 0 || (message.compare(n, 3, " = ") != 0 && message.compare(n, 2, ": ") != 0)) return message;
    const CLI::App* command = &app;
    for (auto subs = command->get_subcommands(); !subs.empty(); subs = command->get_subcommands())
        command = subs.front();
    std::string option = "--" + message.substr(0, n);
    std::replace(option.begin(), option.end(), '_', '-');
    if (command->get_option_no_throw(option) == nullptr) return message;
    return option + message.substr(n);
}

std::string duration_text(double seconds) {
    if (!(seconds >= 0)) return "?";
    char buf[32];
    const long t = std::lround(seconds);
    if (t >= 3600)
        std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
    else if (t >= 60)
        std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
    else
        std::snprintf(buf, sizeof buf, "%lds", t);
    return buf;
}

}  // namespace demcal

namespace demcal {

void check_side_files_free(const std::string& output, const std::vector<std::string>& side_files,
                           const std::string& option) {
    if (output.empty() || std::filesystem::exists(std::filesystem::symlink_status(output))) return;
    for (const std::string& f : side_files)
        if (std::filesystem::exists(std::filesystem::symlink_status(f)))
            throw UserError(option + " = '" + analytics::shortened_text(output, 200) + "': " +
                            analytics::shortened_text(f, 200) + " is already there, and it would be written beside " +
                            "it: not from an earlier run (the output itself is not there); give another name, or "
                            "remove that file");
}

}  // namespace demcal

namespace demcal {

namespace {

// The names (--long and -s) of every option of `app` and its subcommands that takes a comma-separated list, each
// with the name a message gives it (the long one).
void collect_list_options(const CLI::App& app, std::map<std::string, std::string>& names) {
    for (const CLI::Option* opt : app.get_options()) {
        if (opt->get_delimiter() != ',') continue;
        const std::string shown = opt->get_lnames().empty() ? "-" + opt->get_snames().front() : "--" + opt->get_lnames().front();
        for (const auto& l : opt->get_lnames()) names.emplace("--" + l, shown);
        for (const auto& sn : opt->get_snames()) names.emplace("-" + sn, shown);
    }
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) collect_list_options(*sub, names);
}

}  // namespace

namespace {

// Whether `arg` is written as a number ("-5", "-1e-3"): a value, not an option.
bool looks_like_number(std::string_view arg) {
    double x = 0;
    const auto [end, ec] = std::from_chars(arg.data(), arg.data() + arg.size(), x);
    return ec == std::errc() && end == arg.data() + arg.size();
}

// Whether the command passes the arguments after `--` on to the runs it starts (its positional "silo_args").
bool passes_arguments_on(const CLI::App& command) {
    return !command
                .get_options([](const CLI::Option* o) {
                    const std::string& name = o->get_name();
                    return o->get_positional() && name.size() > 5 && name.compare(name.size() - 5, 5, "_args") == 0;
                })
                .empty();
}

// Options that may be given more than once, each time with another value: NAME=LOW:HIGH ranges and bounds, the
// columns that may change an effect. Any other option given twice kept its last value (a number) or joined the two
// lists (--radii A,B,C --radii D,E,F was read as six radii), silently.
const std::set<std::string> kRepeatableOptions{"range", "bounds", "regime-column"};

}  // namespace

void refuse_repeated_option(const CLI::Option& opt, const std::string& value, std::vector<std::string>& earlier) {
    const std::string name = "--" + (opt.get_lnames().empty() ? opt.get_snames().front() : opt.get_lnames().front());
    const bool repeatable = std::any_of(opt.get_lnames().begin(), opt.get_lnames().end(),
                                        [](const std::string& n) { return kRepeatableOptions.count(n) > 0; });
    if (!earlier.empty() && !repeatable)
        throw UserError(name + " is given twice ('" + analytics::shortened_text(earlier.front(), 100) + "' and '" +
                        analytics::shortened_text(value, 100) + "'): give it once" +
                        (opt.get_items_expected_max() > 1 ? ", with all its values in one list" : ""));
    if (std::find(earlier.begin(), earlier.end(), value) != earlier.end())
        throw UserError(name + " = '" + analytics::shortened_text(value, 100) + "' is given twice");
    earlier.push_back(value);
}

namespace {

// Refuses an option the command does not have, before `--`. CLI11 took it for a positional value of commands that
// pass arguments on (vibration, cutoff: `-j 2` became a silo option) and named other words than the one mistyped.
// Also refuses an option given twice (refuse_repeated_option).
void check_options_known(const CLI::App& app, int argc, const char* const* argv) {
    std::vector<const CLI::App*> chain{&app};
    int i = 1;
    for (; i < argc; ++i) {  // the command and its subcommands, as far as they are named
        const CLI::App* deeper = nullptr;
        for (const CLI::App* sub : chain.back()->get_subcommands([](const CLI::App*) { return true; }))
            if (sub->check_name(argv[i])) deeper = sub;
        if (!deeper) break;
        chain.push_back(deeper);
    }
    if (chain.size() < 2) return;  // no command: CLI11 and the check above say so
    auto option_named = [&chain](const std::string& name) -> const CLI::Option* {
        for (const CLI::App* a : chain)
            for (const CLI::Option* opt : a->get_options())
                if (opt->check_name(name)) return opt;
        return nullptr;
    };
    std::map<const CLI::Option*, std::vector<std::string>> given;  // each option's values as typed, in order
    for (; i < argc; ++i) {
        const std::string_view arg(argv[i]);
        if (arg == "--") break;  // a run's own options, checked by that run's command line
        if (arg.size() < 2 || arg[0] != '-' || looks_like_number(arg)) continue;
        if (std::isdigit(static_cast<unsigned char>(arg[1])) || arg[1] == '.') continue;  // "-10,400": a value
        std::string name(arg.substr(0, arg.find('=')));
        if (arg[1] != '-') name = std::string(arg.substr(0, 2));  // -j2: the short option -j with its value
        // "-campaign": a long option typed with one dash, read as -c with the value "ampaign" (a campaign ran into
        // ./ampaign, probe 63); a value glued to a short option is never a long option's whole name. (A flag takes
        // no value: `-help` is CLI11's, as before.)
        const CLI::Option* short_option = arg[1] != '-' && arg.size() > 2 ? option_named(name) : nullptr;
        if (const std::string long_name = "-" + std::string(arg.substr(0, arg.find('=')));
            short_option && short_option->get_items_expected_min() > 0 && option_named(long_name))
            throw UserError("'" + analytics::shortened_text(arg) + "': a long option takes two dashes: " + long_name +
                            " (a value glued to " + name + " is written apart: " + name + " " +
                            analytics::shortened_text(arg.substr(2)) + ")");
        if (const CLI::Option* opt = option_named(name)) {
            // its value, whatever it looks like, is the option's to check ("--partition -x")
            std::string value = name.size() < arg.size() ? std::string(arg.substr(name.size() + (arg[1] == '-'))) : "";
            if (opt->get_items_expected_min() > 0 && name.size() == arg.size() && i + 1 < argc) value = argv[++i];
            // (a flag given twice says the same thing twice: harmless, and it has no value to name)
            if (opt->get_expected_max() > 0 && opt->get_type_size_max() > 0)
                refuse_repeated_option(*opt, value, given[opt]);
            continue;
        }
        std::string command;
        for (std::size_t k = 1; k < chain.size(); ++k) command += (k > 1 ? " " : "") + chain[k]->get_name();
        // "-geo.json": a file whose name starts with -, read as the option -g (probe 61 named '-g')
        const bool word = arg[1] != '-' && arg.size() > 2 && arg.find_first_of("./") != std::string_view::npos;
        // "-engine": a long option typed with one dash, read as -e (probe 62b named '-e' and no more)
        const std::string long_name = "-" + std::string(arg.substr(0, arg.find('=')));
        const bool one_dash_long = arg[1] != '-' && !word && long_name.size() > 3 && option_named(long_name);
        const std::string shown = word ? std::string(arg) : one_dash_long ? long_name.substr(1) : name;
        throw UserError(command + ": '" + analytics::shortened_text(shown) +
                        "' is not an option of this command (see demcal " + command + " --help" +
                        (passes_arguments_on(*chain.back()) ? "; options for the runs go after --" : "") +
                        (word ? "; a file named so is given as ./" + analytics::shortened_text(arg) : "") +
                        (one_dash_long ? "; a long option takes two dashes: " + long_name : "") + ")");
    }
}

}  // namespace

void check_command_line_shape(const CLI::App& app, int argc, const char* const* argv) {
    // the command, and the subcommand of a command that has them (crosscheck shear|silo: "crosscheck sheer" said
    // only "A subcommand is required")
    const CLI::App* level = &app;
    std::string path = "demcal";
    for (int i = 1; i < argc && argv[i][0] != '-'; ++i) {
        const auto subs = level->get_subcommands([](const CLI::App*) { return true; });
        if (subs.empty()) break;
        std::string known;
        const CLI::App* found = nullptr;
        for (const CLI::App* sub : subs) {
            if (!found && sub->check_name(argv[i])) found = sub;
            known += (known.empty() ? "" : ", ") + sub->get_name();
        }
        if (!found)
            throw UserError("'" + analytics::shortened_text(argv[i]) + "' is not a " +
                            (level == &app ? "demcal command" : "subcommand of " + path) + " (" + known + ")");
        level = found;
        path += " " + found->get_name();
    }
    check_options_known(app, argc, argv);
    std::map<std::string, std::string> lists;
    collect_list_options(app, lists);
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg(argv[i]);
        if (arg == "--") break;  // a run's own options, checked by that run's command line
        const auto eq = arg.find('=');
        const std::string name(arg.substr(0, eq));
        if (!lists.count(name)) continue;
        std::string_view value;
        if (eq != std::string_view::npos) value = arg.substr(eq + 1);
        else if (i + 1 < argc) value = argv[i + 1];
        else continue;
        if (value.find(',') != std::string_view::npos && analytics::has_empty_list_item(value))
            throw UserError(lists.at(name) + ": '" + analytics::shortened_text(value) +
                            "' has an empty item (two commas in a row, one at an end, or blanks only)");
    }
}

std::string shell_word(const std::string& word) {
    const bool literal = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("_./-:@%+=,").find(c) != std::string_view::npos;
    });
    if (literal) return word;
    std::string quoted = "'";
    for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

}  // namespace demcal
