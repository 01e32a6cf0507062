#include "app/result_files.hpp"

#include "orchestrator/run_identity.hpp"  // write_text_file_atomically

#include <mutex>
#include <vector>

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
