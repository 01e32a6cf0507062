#include "app/gnuplot.hpp"

#include "analytics/number_text.hpp"
#include "app/commands.hpp"  // UserError
#include "app/result_files.hpp"
#include "orchestrator/stop_signals.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace demcal {

namespace {

// Whether gnuplot finished the file: a PNG ends with its IEND chunk, an SVG with its closing tag. A full disk left
// gnuplot's output cut short while gnuplot itself exited 0.
bool plot_is_complete(const std::filesystem::path& file, const std::string& extension) {
    std::ifstream f(file, std::ios::binary | std::ios::ate);
    if (!f) return false;
    const std::streamoff size = f.tellg();
    const std::streamoff tail = std::min<std::streamoff>(size, 64);
    std::string end(static_cast<std::size_t>(tail), '\0');
    f.seekg(size - tail);
    f.read(end.data(), tail);
    if (!f) return false;
    if (extension == ".png") {
        static const std::string iend("\0\0\0\0IEND\xAE\x42\x60\x82", 12);
        return end.size() >= iend.size() && end.compare(end.size() - iend.size(), iend.size(), iend) == 0;
    }
    return end.find("</svg>") != std::string::npos;
}

std::string single_quoted(const std::string& text) {
    std::string s = "'";
    for (char c : text) s += (c == '\'') ? std::string("''") : std::string(1, c);
    return s + "'";
}

// The stop signal that arrived while gnuplot drew (0: none). A stop signal (a second Ctrl-C during a campaign's report,
// say) used to end demcal with gnuplot still drawing half a plot under its final name (probe 64 D2).
volatile std::sig_atomic_t stop_signal_while_drawing = 0;
void note_stop_signal_while_drawing(int sig) { stop_signal_while_drawing = sig; }

// Whether a stop signal would end demcal at once (its default action): only then is it caught while gnuplot draws. A
// command that handles stop signals itself (a silo run's checkpoint) keeps its own handling, and gnuplot finishes.
bool stop_signals_end_demcal() {
    for (const int sig : orchestrator::kStopSignals) {
        struct sigaction now {};
        if (::sigaction(sig, nullptr, &now) != 0) return false;
        if ((now.sa_flags & SA_SIGINFO) || (now.sa_handler != SIG_DFL && now.sa_handler != SIG_IGN)) return false;
    }
    return true;
}

// Ends demcal after a stop signal that came while gnuplot drew (gnuplot already ended): the unfinished plot, its run
// script and the result files this command had begun are removed (all noted result files: the report is whole or
// absent, app/result_files.hpp), then the signal's own default action ends demcal, as it would have without this.
[[noreturn]] void end_by_stop_signal(int sig, const std::filesystem::path& script,
                                     std::optional<orchestrator::StopSignalHandlers>& handlers) {
    const int removed = discard_unfinished_results();
    std::cerr << "demcal: stopped by " << orchestrator::stop_signal_name(sig) << " while gnuplot drew "
              << script.string() << "; removed the " << removed << " result file" << (removed == 1 ? "" : "s")
              << " this command had begun" << std::endl;
    handlers.reset();  // the default action back (stop_signals_end_demcal), then the signal as if it came to it
    std::raise(sig);
    throw std::runtime_error("stopped by " + orchestrator::stop_signal_name(sig) + " while gnuplot drew " +
                             script.string());  // (not reached: the default action ends the process)
}

// Waits for gnuplot; a stop signal meanwhile ends gnuplot and then demcal (end_by_stop_signal).
int wait_for_gnuplot(pid_t pid, const std::filesystem::path& script,
                     std::optional<orchestrator::StopSignalHandlers>& handlers) {
    int status = 0;
    for (;;) {
        const pid_t waited = ::waitpid(pid, &status, 0);
        if (const int sig = stop_signal_while_drawing; sig != 0) {
            if (waited < 0) {
                ::kill(pid, SIGTERM);
                while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
                }
            }
            end_by_stop_signal(sig, script, handlers);
        }
        if (waited >= 0) return status;
        if (errno != EINTR) throw std::runtime_error("lost gnuplot while it rendered " + script.string());
    }
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
    std::filesystem::path script = output, log = output, unfinished = output;
    script += ".gp";
    log += ".gp.log";
    // gnuplot draws into a file of its own, renamed over OUTPUT once complete: an existing plot is replaced whole or
    // not at all, whatever stops the drawing (a full disk, a signal)
    unfinished += ".part-" + std::to_string(::getpid());
    note_result_file(output);  // the two files gnuplot writes; the script is noted by write_result_file
    note_result_file(log);
    note_result_file(unfinished);
    // the script kept beside the plot draws the plot (`gnuplot OUTPUT.gp` redraws it); gnuplot is run here on a copy
    // that draws into the unfinished file, removed with it
    const std::string head = "set terminal " + terminal + "\nset output ";
    write_result_file(script, head + gnuplot_quote(output) + "\n" + body + "\n");
    std::filesystem::path run_script = unfinished;
    run_script += ".gp";
    write_result_file(run_script, head + gnuplot_quote(unfinished) + "\n" + body + "\n");
    const auto remove_run_files = [&] {
        std::error_code ignored;
        std::filesystem::remove(unfinished, ignored);
        std::filesystem::remove(run_script, ignored);
    };
    // gnuplot without a shell: the script's path is one argument, whatever it holds
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    // a relative name starting with - ("-r.md"'s plots) is gnuplot's option, not its script (probe 62b)
    std::string program = "gnuplot", script_arg = run_script.string();
    if (!script_arg.empty() && script_arg.front() == '-') script_arg = "./" + script_arg;
    char* argv[] = {program.data(), script_arg.data(), nullptr};
    stop_signal_while_drawing = 0;
    std::optional<orchestrator::StopSignalHandlers> handlers;
    if (stop_signals_end_demcal()) handlers.emplace(note_stop_signal_while_drawing);
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0) {
        remove_run_files();
        throw std::runtime_error("cannot start gnuplot for " + script.string() + " (is gnuplot-nox installed?)");
    }
    const int status = wait_for_gnuplot(pid, script, handlers);
    handlers.reset();  // (from here a stop signal takes its default action at once)
    // a signal between wait_for_gnuplot's last look and the reset: taken as one during the drawing (review of stop 65)
    if (const int sig = stop_signal_while_drawing; sig != 0) end_by_stop_signal(sig, script, handlers);
    std::error_code ec;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        remove_run_files();  // whatever gnuplot began is no plot
        throw std::runtime_error("gnuplot failed on " + script.string() + " (see " + log.string() + ")");
    }
    if (!plot_is_complete(unfinished, ext)) {
        remove_run_files();
        throw std::runtime_error("gnuplot did not finish " + output.string() +
                                 " (the file was cut short or not written: is the disk full?); it is not written");
    }
    std::filesystem::remove(run_script, ec);
    std::filesystem::rename(unfinished, output);
    // a log gnuplot left empty says nothing: one beside every plot was clutter (probe 61); a warning stays
    if (std::filesystem::is_regular_file(log, ec) && std::filesystem::file_size(log, ec) == 0 && !ec)
        std::filesystem::remove(log, ec);
}

}  // namespace demcal
