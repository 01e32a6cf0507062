#include "app/gnuplot.hpp"

#include "analytics/number_text.hpp"
#include "app/commands.hpp"  // UserError

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace demcal {

namespace {

std::string single_quoted(const std::string& text) {
    std::string s = "'";
    for (char c : text) s += (c == '\'') ? std::string("''") : std::string(1, c);
    return s + "'";
}

}  // namespace

std::string gnuplot_quote(const std::filesystem::path& p) {
    if (analytics::has_control_character(p.string()))
        throw UserError("the plot path '" + p.string().substr(0, 200) +
                        "' holds a control character (a newline, a tab): gnuplot cannot be given it");
    return single_quoted(p.string());
}

std::string gnuplot_text(const std::string& text) {
    std::string shown = text;
    for (char& c : shown)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
    return single_quoted(shown);
}

std::vector<std::filesystem::path> gnuplot_files(const std::filesystem::path& output) {
    std::filesystem::path script = output, log = output;
    script += ".gp";
    log += ".gp.log";
    return {output, script, log};
}

bool gnuplot_available() {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path ? path : "");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        if (dir.empty()) dir = ".";
        const std::filesystem::path candidate = std::filesystem::path(dir) / "gnuplot";
        std::error_code ec;
        if (std::filesystem::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return true;
    }
    return false;
}

void require_gnuplot(const std::string& option) {
    if (!gnuplot_available())
        throw UserError("gnuplot is not on PATH, and this command's plots need it: install gnuplot-nox "
                        "(scripts/setup.sh) or pass " + option);
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
    std::filesystem::path script = output, log = output;
    script += ".gp";
    log += ".gp.log";
    {
        std::ofstream f(script);
        f << "set terminal " << terminal << "\nset output " << gnuplot_quote(output) << "\n" << body << "\n";
        if (!f) throw std::runtime_error("cannot write gnuplot script " + script.string());
    }
    // gnuplot without a shell: the script's path is one argument, whatever it holds
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::string program = "gnuplot", script_arg = script.string();
    char* argv[] = {program.data(), script_arg.data(), nullptr};
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    int status = 0;
    if (spawned != 0)
        throw std::runtime_error("cannot start gnuplot for " + script.string() + " (is gnuplot-nox installed?)");
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) throw std::runtime_error("lost gnuplot while it rendered " + script.string());
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw std::runtime_error("gnuplot failed on " + script.string() + " (see " + log.string() + ")");
}

}  // namespace demcal
