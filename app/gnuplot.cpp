#include "app/gnuplot.hpp"

#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace demcal {

std::string gnuplot_quote(const std::filesystem::path& p) {
    std::string s = "'";
    for (char c : p.string()) s += (c == '\'') ? std::string("''") : std::string(1, c);
    return s + "'";
}

std::vector<std::filesystem::path> gnuplot_files(const std::filesystem::path& output) {
    std::filesystem::path script = output, log = output;
    script += ".gp";
    log += ".gp.log";
    return {output, script, log};
}

void render_gnuplot(const std::filesystem::path& output, const std::string& body, int width, int height) {
    const std::string ext = output.extension().string();
    std::string terminal;
    if (ext == ".png")
        terminal = "pngcairo enhanced font 'Sans,10' size " + std::to_string(width) + "," + std::to_string(height);
    else if (ext == ".svg")
        terminal = "svg enhanced font 'Sans,10' size " + std::to_string(width) + "," + std::to_string(height);
    else
        throw std::runtime_error("plot output must end in .png or .svg, got '" + output.string() + "'");
    std::filesystem::path script = output;
    script += ".gp";
    {
        std::ofstream f(script);
        f << "set terminal " << terminal << "\nset output " << gnuplot_quote(output) << "\n" << body << "\n";
        if (!f) throw std::runtime_error("cannot write gnuplot script " + script.string());
    }
    const std::string cmd = "gnuplot " + gnuplot_quote(script) + " 2>" + gnuplot_quote(script.string() + ".log");
    if (std::system(cmd.c_str()) != 0)
        throw std::runtime_error("gnuplot failed on " + script.string() + " (see " + script.string() + ".log)");
}

}  // namespace demcal
