#include "app/result_files.hpp"

#include "analytics/number_text.hpp"
#include "app/cli_support.hpp"  // names_process_stream
#include "app/commands.hpp"     // UserError
#include "orchestrator/run_identity.hpp"  // write_text_file_atomically

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>  // getpid

namespace demcal {

namespace {

std::mutex journal_mutex;
std::vector<std::filesystem::path> created_results;  // in the order they were noted

}  // namespace

void note_result_file(const std::filesystem::path& path) {
    std::error_code ec;
    // there before: not ours (or ours already, noted when this command created it)
    if (std::filesystem::exists(std::filesystem::symlink_status(path, ec))) return;
    const std::lock_guard<std::mutex> lock(journal_mutex);
    created_results.push_back(path);
}

void write_result_file(const std::filesystem::path& path, const std::string& text) {
    // the folders an output path names are made (the commands check them creatable before any work)
    if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
    note_result_file(path);
    orchestrator::write_text_file_atomically(path, text);
}

namespace {
std::streambuf* json_stdout = nullptr;  // standard output's own buffer while a JsonOnStandardOutput lives
bool report_to_stderr_lost = false;     // (report_on_stderr_lost)
bool json_to_stdout_lost = false;       // (json_on_stdout_lost)
}  // namespace

bool same_file_as_descriptor(const std::string& path, int fd) {
    struct stat named {}, open_file {};
    return !path.empty() && ::stat(path.c_str(), &named) == 0 && ::fstat(fd, &open_file) == 0 &&
           S_ISREG(named.st_mode) && named.st_dev == open_file.st_dev && named.st_ino == open_file.st_ino;
}

bool names_standard_output(const std::string& path) {
    if (path == kStandardOutputName) return true;
    if (path.empty()) return false;
    std::error_code ec;
    const std::string absolute = std::filesystem::absolute(path, ec).lexically_normal().string();
    const std::string own = "/proc/" + std::to_string(::getpid()) + "/fd/1";
    for (const char* name : {"/dev/stdout", "/dev/fd/1", "/proc/self/fd/1", "/proc/thread-self/fd/1"})
        if (absolute == name) return true;
    if (absolute == own) return true;
    // the file standard output is redirected to, by its name or a link (`--json r.json > r.json`: the JSON was
    // written over the text printed there, probe 63); but /dev/stderr named is stderr, whatever file it shares with
    // standard output (`> log 2>&1`)
    return !names_process_stream(absolute) && same_file_as_descriptor(path, 1);
}

bool standard_output_shares_stderr_file() {
    struct stat out {}, err {};
    return ::fstat(1, &out) == 0 && ::fstat(2, &err) == 0 && S_ISREG(out.st_mode) && out.st_dev == err.st_dev &&
           out.st_ino == err.st_ino;
}

JsonOnStandardOutput::JsonOnStandardOutput(const std::string& json_path) {
    if (!names_standard_output(json_path) || json_stdout) return;
    // (`--json out.json > out.json 2>&1` wrote the text and the JSON into one file that no longer parses)
    if (standard_output_shares_stderr_file())
        throw UserError("--json = '" + analytics::shortened_text(json_path, 200) +
                        "' is standard output, and standard error is the same file here (> FILE 2>&1): the JSON "
                        "would be mixed into the text report; send stderr elsewhere, or give --json a file of its own");
    std::cout.flush();
    saved_stdout_ = std::cout.rdbuf(std::cerr.rdbuf());
    json_stdout = saved_stdout_;
}

JsonOnStandardOutput::~JsonOnStandardOutput() {
    if (!saved_stdout_) return;
    // (rdbuf() clears the stream's state: a stderr that took none of the report, `2>/dev/full`, ended with exit 0)
    if (!std::cout.good()) report_to_stderr_lost = true;
    std::cout.rdbuf(saved_stdout_);
    json_stdout = nullptr;
}

void write_json_result(const std::string& path, const std::string& text) {
    if (!names_standard_output(path)) return write_result_file(path, text);
    std::ostream out(json_stdout ? json_stdout : std::cout.rdbuf());
    errno = 0;
    out << text << std::flush;
    // A full disk, a closed pipe: said here, while errno still tells the reason. (The stream's own state did not show
    // a write the system refused; stdio's does.)
    if (!out.good() || std::fflush(stdout) != 0 || std::ferror(stdout)) {
        const int why = errno;
        keep_results();  // the reports and plots written before it are whole (as for any lost standard output)
        json_to_stdout_lost = true;
        throw std::runtime_error("the JSON result could not be written to standard output" +
                                 (why != 0 ? " (" + std::string(std::strerror(why)) + ")" : std::string()));
    }
}

bool report_on_stderr_lost() { return report_to_stderr_lost; }

bool json_on_stdout_lost() { return json_to_stdout_lost; }

void keep_results() {
    const std::lock_guard<std::mutex> lock(journal_mutex);
    created_results.clear();
}

int discard_unfinished_results() {
    const std::lock_guard<std::mutex> lock(journal_mutex);
    int removed = 0;
    for (auto it = created_results.rbegin(); it != created_results.rend(); ++it) {
        std::error_code ec;
        if (std::filesystem::remove(*it, ec)) ++removed;
    }
    created_results.clear();
    return removed;
}

}  // namespace demcal
