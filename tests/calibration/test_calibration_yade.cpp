// `demcal sensitivity` over real YADE runs of the tiny box (examples/materials/sand-tiny.json): one parameter at three
// levels at three stresses (9 runs), killed with SIGKILL half-way and resumed by running the same command again.
#include "test_files.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

// Counts finished runs: each writes result.json in its run directory.
int finished_runs(const fs::path& dir) {
    int n = 0;
    if (!fs::exists(dir / "runs")) return 0;
    for (const auto& e : fs::directory_iterator(dir / "runs")) n += fs::exists(e.path() / "result.json");
    return n;
}

}  // namespace

TEST_CASE("a sensitivity study on real YADE runs, killed with SIGKILL, resumes re-using every finished run",
          "[yade][slow]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-sensitivity-yade-" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    // Three stresses (a line needs 3 points), three friction levels, the base (0.5) in the middle: 9 tiny runs.
    const std::string args = std::string(" sensitivity ") + DEMCAL_SOURCE_DIR +
                             "/examples/materials/sand-tiny.json --params friction_coefficient --levels 3 --span 0.4"
                             " --normal-stress 2e3,4e3,6e3 --jobs 2 --campaign " + dir.string();
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        const std::string cmd = std::string("exec ") + DEMCAL_BINARY + args + " > " + (dir / "first.log").string() + " 2>&1";
        execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    // Kill once two runs are done (and others are running).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(10);
    while (finished_runs(dir) < 2 && std::chrono::steady_clock::now() < deadline && waitpid(pid, nullptr, WNOHANG) == 0)
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const int done_before_kill = finished_runs(dir);
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    REQUIRE(done_before_kill >= 2);

    const std::string cmd = std::string(DEMCAL_BINARY) + args + " > " + (dir / "second.log").string() + " 2>&1";
    const int rc = std::system(cmd.c_str());
    const std::string second = demcal::test::read_file(dir / "second.log");
    INFO(demcal::test::read_file(dir / "first.log") << "\n----\n" << second);
    REQUIRE(WEXITSTATUS(rc) == 0);
    const auto study = nlohmann::json::parse(demcal::test::read_file(dir / "sensitivity.json"));
    // Every run finished before the kill is reused, none computed twice.
    CHECK(study.at("simulations_reused").get<int>() >= done_before_kill);
    CHECK(study.at("simulations_run").get<int>() + done_before_kill <= 9 + 4);  // 3 levels x 3 stresses (+ running at the kill)
    const auto& p = study.at("parameters").at(0);
    CHECK(p.at("name") == "friction_coefficient");
    REQUIRE(p.at("levels").size() == 3);
    for (const auto& l : p.at("levels")) CHECK(std::isfinite(l.at("mu_b").get<double>()));
    CHECK(p.at("mu_b").contains("shape"));
    CHECK(fs::exists(dir / "sensitivity_friction_coefficient.png"));
    CHECK(demcal::test::read_file(dir / "sensitivity_table.txt").find("friction_coefficient") != std::string::npos);
    fs::remove_all(dir);
}
