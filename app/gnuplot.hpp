// Renders plots with gnuplot (Debian package gnuplot-nox): the caller writes data files and a script body,
// this writes the script beside the output and runs gnuplot on it. The terminal follows the output's
// extension (.png -> pngcairo, .svg -> svg). Throws std::runtime_error naming the script when gnuplot fails.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace demcal {

// Writes `body` (gnuplot commands, without `set terminal`/`set output`) to OUTPUT.gp and renders OUTPUT.
void render_gnuplot(const std::filesystem::path& output, const std::string& body, int width = 900,
                    int height = 650);

// Every file render_gnuplot(output, ...) writes: OUTPUT, OUTPUT.gp and gnuplot's log OUTPUT.gp.log (for the check
// that no output lands on an input or another output).
std::vector<std::filesystem::path> gnuplot_files(const std::filesystem::path& output);

// Quotes a path for use inside a gnuplot script.
std::string gnuplot_quote(const std::filesystem::path& p);

}  // namespace demcal
