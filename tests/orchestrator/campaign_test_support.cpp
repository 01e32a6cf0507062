#include "campaign_test_support.hpp"

#include <fcntl.h>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

namespace demcal::test {

namespace fs = std::filesystem;

fs::path fresh_test_dir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("demcal-test-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

fs::path source_path(const std::string& relative) { return fs::path(DEMCAL_SOURCE_DIR) / relative; }

fs::path write_stand_in_yade(const fs::path& dir) {
    const fs::path yade = dir / "stand-in-yade";
    // as YADE with yade_scripts/run_clean.py: the started marker in the run's folder, then the result (schema /1: a
    // template older than the result's seal, still read) into the file named by the last argument
    std::ofstream(yade) << "#!/bin/sh\n: > yade_started\nfor last; do :; done\n"
                           "echo '{\"schema\": \"demcal.shear_result/1\", \"peak_shear_stress\": 1000, "
                           "\"residual_shear_stress\": 800}' > \"$last\"\n";
    fs::permissions(yade, fs::perms::owner_all);
    return yade;
}

namespace {
std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}
}  // namespace

int run_demcal(const std::vector<std::string>& args, const fs::path& log) {
    std::string cmd = quote(DEMCAL_BINARY);
    for (const auto& a : args) cmd += " " + quote(a);
    cmd += " >" + quote(log.string()) + " 2>&1 </dev/null";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int spawn_demcal(const std::vector<std::string>& args, const fs::path& log) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        std::vector<char*> argv{const_cast<char*>(DEMCAL_BINARY)};
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(DEMCAL_BINARY, argv.data());
        ::_exit(127);
    }
    return pid;
}

fs::path find_file(const fs::path& dir, const std::string& prefix, const std::string& suffix) {
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string n = e.path().filename().string();
        if (n.rfind(prefix, 0) == 0 && n.size() >= suffix.size() &&
            n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
            return e.path();
    }
    return {};
}

std::vector<orchestrator::RunRecord> stored_runs(const fs::path& campaign_dir) {
    orchestrator::CampaignStore store(campaign_dir / "campaign.sqlite");
    std::vector<orchestrator::RunRecord> all;
    for (const auto& c : store.campaigns())
        for (auto& r : store.campaign_runs(c.id)) all.push_back(std::move(r));
    return all;
}

std::vector<int> processes_under(const fs::path& dir) {
    std::vector<int> pids;
    const std::string root = fs::weakly_canonical(dir).string();
    for (const auto& e : fs::directory_iterator("/proc")) {
        const std::string name = e.path().filename().string();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        std::error_code ec;
        const auto cwd = fs::read_symlink(e.path() / "cwd", ec);
        if (!ec && cwd.string().rfind(root, 0) == 0) pids.push_back(std::stoi(name));
    }
    return pids;
}

}  // namespace demcal::test
