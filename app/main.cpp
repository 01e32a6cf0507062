#include "analytics/number_text.hpp"
#include "app/cli_support.hpp"
#include "app/commands.hpp"
#include "app/result_files.hpp"
#include "app/silo_campaign.hpp"

#include <gsl/gsl_errno.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <sys/prctl.h>
#include <unistd.h>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

namespace {

// Every message names values a user typed; one holding a newline or an escape sequence ('new\nline' as a path) split
// the message over lines and could move the terminal's cursor. The whole message is escaped here, once, as
// analytics::shortened_text escapes a value (and bounded: a message is one line a person reads).
constexpr std::size_t kMaxMessageChars = 4000;
std::string one_line(std::string_view message) { return demcal::analytics::shortened_text(message, kMaxMessageChars); }

// A command that ended with an exception: its message on one line, and the result files it had begun removed
// (app/result_files.hpp), said when there were any.
int failed(int status, const char* kind, const std::string& message) {
    std::string text = one_line(message);
    if (const int removed = demcal::discard_unfinished_results(); removed > 0)
        text += "; removed the " + std::to_string(removed) + " result file" + (removed == 1 ? "" : "s") +
                " this command had begun (its result is whole or absent)";
    std::cerr << "demcal: " << kind << ": " << text << "\n";
    return status;
}

int run_command(int argc, char** argv) {
    CLI::App app{"demcal: DEM calibration, YADE campaigns, discharge models and a native DEM kernel"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "demcal 0.1");
    // A malformed command line is refused like any other bad input: one line, "demcal: error: ", the option and the
    // rule, and where the options are listed (CLI11's own text took two lines without the prefix)
    app.failure_message([](const CLI::App* a, const CLI::Error& e) {
        std::string command = "demcal";
        const CLI::App* innermost = a;
        for (const CLI::App* sub = a; sub;) {  // the subcommands given so far: the help that lists the options
            const auto given = sub->get_subcommands();
            sub = given.empty() ? nullptr : given.front();
            if (sub) command += " " + sub->get_name(), innermost = sub;
        }
        // words left over are mostly a list typed with spaces (-s 5e3 10e3 15e3: "not expected: 15e3 10e3"), where
        // the command takes a list (predict g.json g.json was told about -s, which predict does not have)
        const auto options = innermost->get_options();
        const bool takes_lists = std::any_of(options.begin(), options.end(),
                                             [](const CLI::Option* o) { return o->get_delimiter() == ','; });
        const std::string list_hint = dynamic_cast<const CLI::ExtrasError*>(&e) && takes_lists
                                          ? "; a list is one word, its values separated by commas without spaces "
                                            "(-s 5e3,10e3,15e3)"
                                          : "";
        return "demcal: error: " + one_line(e.what()) + list_hint + " (the options: " + command + " --help)\n";
    });
    demcal::add_shear_commands(app);
    demcal::add_shear_run_command(app);
    demcal::add_crosscheck_command(app);
    demcal::add_silo_command(app);
    demcal::add_cutoff_command(app);
    demcal::add_vibration_command(app);
    demcal::add_discharge_commands(app);
    demcal::add_calibration_commands(app);
    demcal::add_scale_command(app);
    demcal::refuse_empty_values(app);
    demcal::read_values_strictly(app);
    demcal::refuse_inapplicable_options(app);
    try {
        demcal::check_argument_lengths(argc, argv);
        demcal::check_command_line_shape(app, argc, argv);
        app.parse(argc, argv);
    } catch (const CLI::RuntimeError& e) {  // a command's own exit status (75: suspended, resume it)
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; a malformed command line is bad input like any other: exit 2
        return app.exit(e) == 0 ? 0 : 2;
    } catch (const demcal::UserError& e) {
        return failed(2, "error", demcal::with_option_name(app, e.what()));
    } catch (const demcal::orchestrator::CampaignSuspended& e) {
        return failed(demcal::orchestrator::kExitCampaignSuspended, "stopped", e.what());
    } catch (const std::filesystem::filesystem_error& e) {
        const int code = e.code().value();
        if (code == ENOSPC || code == EDQUOT || code == EIO)  // the machine's state, not the path the user gave
            return failed(1, "failed", "'" + e.path1().string() + "': " + e.code().message());
        // a path the user gave that the file system will not take (a file where a folder belongs, a link loop, a
        // read-only folder): the path and the reason, not the library's text
        return failed(2, "error", "'" + e.path1().string() + "': " + e.code().message() +
                                      " (a file where a folder belongs, a link loop or a read-only folder in the path?)");
    } catch (const std::invalid_argument& e) {  // the libraries' word for bad input
        return failed(2, "error", demcal::with_option_name(app, e.what()));
    } catch (const std::exception& e) {
        return failed(1, "failed", e.what());
    }
    return 0;
}

// A result printed into a full disk or a closed file is lost: say so and fail, whatever the command's own status
// (`demcal predict geometry.json > /dev/full` printed nothing and exited 0).
int with_standard_output_checked(int status) {
    errno = 0;
    std::cout.flush();
    const bool flushed = std::fflush(stdout) == 0 && !std::ferror(stdout) && std::cout.good();
    if (demcal::report_on_stderr_lost()) return status == 0 ? 1 : status;  // (no message: stderr is what failed)
    if (demcal::json_on_stdout_lost()) return status == 0 ? 1 : status;    // (said when it happened)
    if (flushed) return status;
    const int why = errno;
    std::cerr << "demcal: error: the standard output could not be written"
              << (why != 0 ? std::string(" (") + std::strerror(why) + ")" : std::string()) << "; what was printed is incomplete\n";
    return status == 0 ? 1 : status;
}

}  // namespace

// A demcal started by a sweep (app/silo_campaign.cpp spawn_demcal) gets SIGTERM when the sweep dies, even by kill -9:
// it checkpoints and stops, where it ran on as an orphan in the run folder the sweep, run again, needed. The variable
// names the parent; a parent already gone before the link was made is caught by comparing it.
void end_with_parent_if_asked() {
    const char* parent = std::getenv(demcal::kDieWithParentVariable);
    if (!parent) return;
    const long expected = std::strtol(parent, nullptr, 10);
    ::unsetenv(demcal::kDieWithParentVariable);  // (not passed on to anything this process starts)
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != expected) ::raise(SIGTERM);
}

int main(int argc, char** argv) {
    end_with_parent_if_asked();
    // GSL's default error handler aborts the process (its F quantile did, on valid input: analytics/dem_diagnosis.cpp
    // f1_quantile). A command checks what the numerics return (a fit not converged, a value not finite) and says so;
    // an abort says nothing and leaves a core.
    gsl_set_error_handler_off();
    return with_standard_output_checked(run_command(argc, argv));
}
