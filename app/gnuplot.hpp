// Renders plots with gnuplot (Debian package gnuplot-nox): the caller writes data files and a script body,
// this writes the script beside the output and runs gnuplot on it. The terminal follows the output's
// extension (.png -> pngcairo, .svg -> svg). Throws std::runtime_error naming the script when gnuplot fails.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace demcal {

// Writes `body` (gnuplot commands, without `set terminal`/`set output`) to OUTPUT.gp and renders OUTPUT: gnuplot is
// started without a shell (a quote or a space in a path is the path's), its messages go to OUTPUT.gp.log.
void render_gnuplot(const std::filesystem::path& output, const std::string& body, int width = 900,
                    int height = 650);

// Every file render_gnuplot(output, ...) writes: OUTPUT, OUTPUT.gp and gnuplot's log OUTPUT.gp.log (for the check
// that no output lands on an input or another output).
std::vector<std::filesystem::path> gnuplot_files(const std::filesystem::path& output);

// Quotes a path for use inside a gnuplot script (single quotes, ' doubled: gnuplot expands no backquote inside).
// Throws UserError for a path with a control character (a newline would end the script's line).
std::string gnuplot_quote(const std::filesystem::path& p);
// Quotes a user's text (a CSV column name, a category) for a title or label: as gnuplot_quote, with control
// characters shown as spaces, so that no text of an input can end a line of the script and start a command.
std::string gnuplot_text(const std::string& text);

// Whether gnuplot can be started (on PATH and executable). Commands whose plots are part of their output call
// require_gnuplot before any work: a missing gnuplot is said at once, not after the run.
bool gnuplot_available();
// Throws UserError naming `option` (the flag that turns the plots off) when gnuplot is not available.
void require_gnuplot(const std::string& option);

}  // namespace demcal
