// A command's result files (reports, tables, plot data, plots): each written whole or not at all, and the ones this
// command created removed again when it fails before the result they belong to is whole (keep_results). A failure
// part way through a report (a full disk, a plot gnuplot could not finish) then leaves no part of the result behind:
// no report beside plots of another run, no plot data whose plot is missing, and the retry finds the names free (a
// side file left alone blocks it: see check_side_files_free). Files the command replaced keep their new text (the old one is gone either way).
// Campaign state (stores, run folders, checkpoints) and a silo run's data are not results in this sense: they are
// kept for `resume` and never pass through here.
#pragma once
#include <filesystem>
#include <string>

namespace demcal {

// Writes `text` to `path` whole or not at all (a temporary file renamed over it), noting the file as this command's
// result; the folders its path names are made. Throws std::runtime_error naming the file and the system's reason (a
// full disk is exit 1, not bad input).
void write_result_file(const std::filesystem::path& path, const std::string& text);

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
