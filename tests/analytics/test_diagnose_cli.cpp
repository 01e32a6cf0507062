// demcal diagnose end to end: regime and outlier options that do not suit the data exit 2 naming the field and the
// value, before anything is written; a run on the shipped sets names the flow-mode effect and the outlier's line in
// the console, the JSON and the Markdown report. Needs the demcal binary (built with the project).
#include "test_files.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using demcal::test::read_file;

struct Run {
    int rc;
    std::string out, err;
};

Run run_diagnose(const std::string& args, const fs::path& dir) {
    fs::create_directories(dir);
    const std::string cmd = std::string("'") + DEMCAL_BINARY + "' diagnose " + args + " > '" +
                            (dir / "out.log").string() + "' 2> '" + (dir / "err.log").string() + "'";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(dir / "out.log"), read_file(dir / "err.log")};
}

std::string example(const std::string& name) { return std::string(DEMCAL_SOURCE_DIR) + "/examples/diagnose/" + name; }

}  // namespace

TEST_CASE("diagnose CLI: bad regime and outlier options exit 2 naming the field and value, writing nothing",
          "[diagnose]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal_test_diagnose_cli_bad_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const std::string outputs = " --json '" + (dir / "r.json").string() + "' --report '" + (dir / "rep/r.md").string() +
                                "' --model oldal --data '" + example("oldal_vibration_by_mode.csv") + "'";
    struct Case {
        std::string args, message;
    };
    const std::vector<Case> cases{
        {"--regime-column flow_regime", "--regime-column 'flow_regime' is not in"},
        {"--regime-column run_order", "--regime-column 'run_order' has 84 values"},
        {"--wall-friction-deg 20", "--wall-friction-deg=20 given, --effective-friction-deg missing"},
        {"--effective-friction-deg 30", "--effective-friction-deg=30 given, --wall-friction-deg missing"},
        {"--wall-friction-deg 35 --effective-friction-deg 30", "phi_w_deg=35 is not below delta_e_deg=30"},
        {"--wall-friction-deg 95 --effective-friction-deg 30", "--wall-friction-deg: 95"},
        {"--outlier-alpha 0.9", "--outlier-alpha: 0.9"}};
    for (const auto& c : cases) {
        const auto r = run_diagnose(c.args + outputs, dir);
        INFO(c.args << "\nstderr: " << r.err);
        CHECK(r.rc == 2);
        CHECK(r.err.find(c.message) != std::string::npos);
        CHECK(!fs::exists(dir / "r.json"));
        CHECK(!fs::exists(dir / "rep"));
    }
    fs::remove_all(dir);
}

TEST_CASE("diagnose CLI: the flow-mode effect and the outlier are named in console, JSON and report", "[diagnose]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal_test_diagnose_cli_run_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const auto vibration = run_diagnose("--model oldal --no-plots --data '" + example("oldal_vibration_by_mode.csv") +
                                            "' --json '" + (dir / "v.json").string() + "' --report '" +
                                            (dir / "v.md").string() + "'",
                                        dir);
    REQUIRE(vibration.rc == 0);
    CHECK(vibration.out.find("+ vibration_Hz by flow_mode (regime)") != std::string::npos);
    const auto j = nlohmann::json::parse(read_file(dir / "v.json"));
    REQUIRE(j.at("effects").size() == 1);
    CHECK(j.at("effects")[0].at("regime") == "flow_mode");
    CHECK(j.at("flow_mode_rule").get<std::string>().find("seed classes") != std::string::npos);
    CHECK(read_file(dir / "v.md").find("**vibration_Hz by flow_mode** (regime)") != std::string::npos);

    // The shipped outlier set: its 17th run (file line 19, below the comment and the header) is 30 % off.
    const auto outlier = run_diagnose("--model oldal --no-plots --drop-outliers --data '" +
                                          example("oldal_outlier.csv") + "' --json '" + (dir / "o.json").string() +
                                          "' --report '" + (dir / "o.md").string() + "'",
                                      dir);
    REQUIRE(outlier.rc == 0);
    CHECK(outlier.out.find("outlier: line 19:") != std::string::npos);
    CHECK(outlier.out.find("no effect added") != std::string::npos);
    const auto o = nlohmann::json::parse(read_file(dir / "o.json")).at("outliers");
    REQUIRE(o.at("rows").size() == 1);
    CHECK(o.at("rows")[0].at("line") == 19);
    CHECK(o.at("dropped") == true);
    CHECK(o.at("without_outliers").at("rmse").get<double>() < o.at("with_outliers").at("rmse").get<double>());
    CHECK(read_file(dir / "o.md").find("| 19 |") != std::string::npos);
    fs::remove_all(dir);
}

TEST_CASE("diagnose CLI: a two-row failure line is refused, naming the file", "[diagnose]") {
    // held-back probe of stop 64: two rows of a failure line were refused as "failure line: needs at least 3 points"
    // without the file that held them
    const fs::path dir = fs::temp_directory_path() / ("demcal_test_diagnose_cli_two_rows_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path two_rows = dir / "two_rows.csv";
    std::ofstream(two_rows) << "sigma_Pa,tau_Pa\n4000,3000\n8000,5000\n";
    const auto short_line = run_diagnose("--model failure-line --data '" + two_rows.string() + "'", dir);
    INFO("stderr: " << short_line.err);
    CHECK(short_line.rc == 2);
    CHECK(short_line.err.find(two_rows.string()) != std::string::npos);
    CHECK(short_line.err.find("2 rows") != std::string::npos);
    fs::remove_all(dir);
}
