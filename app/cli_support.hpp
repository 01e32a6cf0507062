// Small helpers every subcommand shares: reading a JSON input file, checking a number option, printing a duration.
#pragma once
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace demcal {

// Reads the JSON file at `path` through analytics::read_json_input; any refusal is a UserError naming `field`, the
// path and the rule.
nlohmann::json read_json_file(const std::string& path, const std::string& field);

// Checks of number options. CLI11's own Range and PositiveNumber let NaN through and print their bounds with 300
// digits; these refuse an empty value and what analytics::number_defect refuses (NaN, infinities, subnormals,
// implausibly large numbers), naming it, and state the bounds as a user would type them.
CLI::Validator number_in(double lo, double hi);  // lo <= x <= hi
CLI::Validator positive_number();                // x > 0
CLI::Validator non_negative_number();            // x >= 0
CLI::Validator integer_in(long long lo, long long hi);  // a whole integer, lo <= x <= hi (never clamped)

// A per-run wall-clock limit (--timeout) [s]: positive and at most kMaxRunTimeout (about 4 months): 1e99 passed, and
// SLURM's --time, the longest limit in minutes as a long, overflowed. (A short one is allowed: its runs end as
// timeouts, which a resume with a longer --timeout runs again.)
inline constexpr double kMaxRunTimeout = 1e7;
// and at least 1 s: 0.001 s killed every run in its start-up (YADE's alone takes seconds), and SLURM's limit is whole
// minutes (a 0.5 s timeout became --time=1 there: the two executors read it differently).
inline constexpr double kMinRunTimeout = 1;
CLI::Validator run_timeout();  // kMinRunTimeout <= x <= kMaxRunTimeout

// Adds to every option of `app` and its subcommands that takes a value a check refusing an empty one (CLI11 read
// `--replicates ""` as 0), to every number option the number rule (analytics::number_defect) and to every integer
// option the integer rule (integer_in, never clamped). Call once every command is registered.
void refuse_empty_values(CLI::App& app);

// How every option of `app` and its subcommands reads its value: a list option takes one value per occurrence (its
// items split at commas; `cutoff --seeds 1 -- --theta 50` took the -- as a second value, and the silo options after
// it as the small hopper's own), and a value that is one of the command's own option names, or --, is refused as a
// value left out (`silo --out --check` ran into a folder named --check). Call once every command is registered.
void read_values_strictly(CLI::App& app);

// Refuses, once the command line is parsed and before any command runs, an option the rest of the command line makes
// void, naming it and what it needs: --partition without --executor slurm, --yade with --engine kernel (both were
// silently ignored: a user who meant a SLURM campaign got a local one). One rule per pair, for every command that
// has both options. Call once every command is registered (it sets `app`'s parse-complete callback).
void refuse_inapplicable_options(CLI::App& app);

// Refuses `opt` given again (`earlier`: its values so far, as typed; `value` is appended): twice for an option that
// takes one value or one list (CLI11 kept the last value, or joined two lists, silently), or the same value twice for
// the options that may be repeated (--range, --bounds, --regime-column). Throws UserError naming the option and both
// values, shortened.
void refuse_repeated_option(const CLI::Option& opt, const std::string& value, std::vector<std::string>& earlier);

// The longest command-line argument demcal takes: a path (PATH_MAX) or a list of numbers.
inline constexpr std::size_t kMaxArgumentChars = 4096;

// Refuses, before CLI11 sees them: a first argument that is no command of `app` (CLI11 said only "A subcommand is
// required" for `demcal shaer`), and an empty item in the value of a list option ("5e3,,1e4": CLI11 dropped it, and
// the campaign ran the stresses left). Throws UserError naming the argument or the option.
void check_command_line_shape(const CLI::App& app, int argc, const char* const* argv);

// Refuses, before CLI11 sees them, arguments longer than kMaxArgumentChars, naming the option and the value
// shortened (CLI11 echoed a 100 kB value in full in its own messages).
void check_argument_lengths(int argc, const char* const* argv);

// Checks, before any work starts, that `path` can be written as an output file: not a folder, its folder exists and
// is writable (and the file itself, when it exists). Throws UserError naming `option`, the path and the rule.
void check_output_file(const std::string& path, const std::string& option);

// Whether `absolute` (a normalised absolute path) names a process's stream (/dev/stdout, /dev/fd/2, /proc/self/fd/1):
// an output there, when the stream was redirected to a file, replaced that file whole through a rename.
bool names_process_stream(const std::string& absolute);
// Refuses (UserError naming `option`) an output in a run folder of a campaign (DIR/runs/NAME/ beside
// DIR/campaign.sqlite or DIR/campaign.json): `scale -o DIR/runs/ID/result.json` replaced a stored run's result.
// Not for the runs' own outputs (shear-run's result.json, a silo run's files), which live there.
void check_output_outside_run_folders(const std::string& path, const std::string& option);

// Checks, before any work starts, that `path` can be used as an output folder: not a file, and files can be created
// in it (when it exists) or in the nearest existing folder above it (where it will be created). The check creates
// nothing (a probe file is removed at once). Throws UserError naming `option`, the path and the rule.
void check_output_folder(const std::string& path, const std::string& option);

// check_output_file for an output whose missing folders the command creates: the nearest existing folder above it
// must allow files to be created (check_output_folder; the file, when it exists, as above). An empty path (output
// not asked for) passes.
void check_output_file_in_new_folders(const std::string& path, const std::string& option);
// An output file that may lie in the campaign folder the command makes (or below it, made as it is written), or
// else in a folder that exists (a typo elsewhere is refused, not made after hours of work).
// The folder `p` names, written without a trailing separator ("out/" and "out/." are "out").
std::filesystem::path without_trailing_separator(const std::filesystem::path& p);
void check_output_in_campaign_or_existing_folder(const std::string& path, const std::string& option,
                                                 const std::string& campaign_dir);

// A path a command reads or writes, with the option (or field) that gave it, for the messages.
struct NamedPath {
    std::string path;    // empty: not given (skipped)
    std::string option;  // e.g. "--json", "geometry (the input file)"
};

// Files a command writes beside its output under derived names (a report's plots, their data): one that is already
// there while the output itself is not, was not written by an earlier run of the command but by someone else (a
// user's laws.png beside a new laws.json). Throws UserError naming `option`, the file and the way out.
void check_side_files_free(const std::string& output, const std::vector<std::string>& side_files,
                           const std::string& option);

// Refuses, before any work starts, an output that is one of the inputs (it would be overwritten) and two outputs on
// one path (one would overwrite the other, or a file would be written where a folder goes). Paths are compared as
// the file system resolves them: relative or absolute, "..", symbolic links. Throws UserError naming both options.
void check_paths_apart(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

// A reader's message about the measured-data file ("data file X is a folder") with the option that gave it, --data.
std::string with_data_option(const std::string& message);
// A library's refusal names its own field ("tol = 400 Hz: ...", "max_window = 2 s: ..."); where the command being run
// has an option of that name (tol -> --tol, max_window -> --max-window), the message names the option as typed
// instead. Only a message that starts with "FIELD = " or "FIELD: " changes; `app` is the parsed command line (its deepest
// subcommand decides).
std::string with_option_name(const CLI::App& app, const std::string& message);

// "42s", "3m05s", "2h10m": short enough for a progress line; "?" for a negative (unknown) duration.
std::string duration_text(double seconds);

/// `word` as a shell reads it back, for the commands a message tells a user to type: as it is when it holds only
/// characters the shell takes literally, else in single quotes (a path with a space printed bare failed when copied:
/// probe 61).
std::string shell_word(const std::string& word);

}  // namespace demcal
