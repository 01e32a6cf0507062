// A command's result files (reports, tables, plot data, plots): each written whole or not at all, and the ones this
// command created removed again when it fails before the result they belong to is whole (keep_results). A failure
// part way through a report (a full disk, a plot gnuplot could not finish) then leaves no part of the result behind:
// no report beside plots of another run, no plot data whose plot is missing, and the retry finds the names free (a
// side file left alone blocks it: see check_side_files_free). Files the command replaced keep their new text (the old one is gone either way).
// Campaign state (stores, run folders, checkpoints) and a silo run's data are not results in this sense: they are
// kept for `resume` and never pass through here.
#pragma once
#include <filesystem>
#include <streambuf>
#include <string>

namespace demcal {

// Writes `text` to `path` whole or not at all (a temporary file renamed over it), noting the file as this command's
// result; the folders its path names are made. Throws std::runtime_error naming the file and the system's reason (a
// full disk is exit 1, not bad input).
void write_result_file(const std::filesystem::path& path, const std::string& text);

// `--json -`: the JSON alone on standard output, for a pipe (`demcal predict g.json --json - | jq .`).
inline constexpr const char* kStandardOutputName = "-";
// "-", a name of standard output (/dev/stdout, /dev/fd/1, /proc/self/fd/1) or the file it is redirected to: as a
// file, a pipe was refused and a redirect's file was replaced whole (through a temporary file and a rename), its
// earlier lines lost.
bool names_standard_output(const std::string& path);

// Whether standard output and standard error are the same regular file (`> log 2>&1`): a JSON result sent to
// standard output would be mixed into the text report sent to stderr.
bool standard_output_shares_stderr_file();

// Whether `path` is the regular file open as descriptor `fd` (a redirect's file, by its name or through a link).
bool same_file_as_descriptor(const std::string& path, int fd);

// While it lives, with `json_path` "-": every text the command prints on std::cout goes to stderr instead, so that
// standard output carries the JSON alone (write_json_result). With any other path it does nothing.
class JsonOnStandardOutput {
public:
    explicit JsonOnStandardOutput(const std::string& json_path);  // (names_standard_output)
    ~JsonOnStandardOutput();
    JsonOnStandardOutput(const JsonOnStandardOutput&) = delete;
    JsonOnStandardOutput& operator=(const JsonOnStandardOutput&) = delete;
    bool active() const { return saved_stdout_ != nullptr; }

private:
    std::streambuf* saved_stdout_ = nullptr;
};

// A JSON result: to `path` as write_result_file writes it, or to standard output (names_standard_output); a standard
// output that does not take it all is a std::runtime_error with the reason.
void write_json_result(const std::string& path, const std::string& text);

// Whether a report sent to stderr by a JsonOnStandardOutput was not all written there (`2>/dev/full`): the command
// then fails, as for a lost standard output (main).
bool report_on_stderr_lost();

// Whether write_json_result found standard output refusing the JSON (and said so, with the reason).
bool json_on_stdout_lost();

// Notes `path` as this command's result before another program (gnuplot) writes it.
void note_result_file(const std::filesystem::path& path);

// The result files written so far form a whole result (a campaign's report, a study's tables and plots): they are kept
// whatever happens next, also when the command then ends with a failure that is its verdict on them (calibrate's
// "unreachable", scale's undetermined laws) or fails on a later result.
void keep_results();

// Removes the result files this command created (not those that were there before it started); main() calls it
// once a command has failed. Returns how many it removed.
int discard_unfinished_results();

}  // namespace demcal
