// Helpers for tests that drive the real `demcal` binary over real YADE runs.
#pragma once
#include "orchestrator/campaign_store.hpp"
#include "test_files.hpp"  // read_file

#include <filesystem>
#include <string>
#include <vector>

namespace demcal::test {

std::filesystem::path fresh_test_dir(const std::string& name);
std::filesystem::path source_path(const std::string& relative);  // a file of the source tree
// A stand-in for YADE in `dir` (returned): writes the run's started marker and a fixed result, as a finished run does.
std::filesystem::path write_stand_in_yade(const std::filesystem::path& dir);
// Runs demcal with arguments (shell-quoted here); stdout+stderr go to `log`. Returns the exit code.
int run_demcal(const std::vector<std::string>& args, const std::filesystem::path& log);
// Starts demcal in the background; returns its pid.
int spawn_demcal(const std::vector<std::string>& args, const std::filesystem::path& log);
// The first file in `dir` whose name starts with `prefix` and ends with `suffix` (empty path if none).
std::filesystem::path find_file(const std::filesystem::path& dir, const std::string& prefix, const std::string& suffix);
// All runs of all campaigns in a campaign directory's store.
std::vector<orchestrator::RunRecord> stored_runs(const std::filesystem::path& campaign_dir);
// Processes whose working directory lies under `dir`.
std::vector<int> processes_under(const std::filesystem::path& dir);

}  // namespace demcal::test
