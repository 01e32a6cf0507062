// Runs the demcal program the tests were built with (DEMCAL_BINARY) through the shell: `args` as one command-line
// string (quote paths in it), stdout and stderr into `log`. Returns the exit status, -1 when a signal ended it.
#pragma once
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace demcal::test {

inline int run_demcal_command(const std::string& args, const std::filesystem::path& log) {
    const std::string cmd = std::string("'") + DEMCAL_BINARY + "' " + args + " > '" + log.string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace demcal::test
