// demcal silo end to end: bad input exits 2 naming the field and the value, before anything is written; a tiny run
// writes discharge.csv and summary.json. Needs the demcal binary (built with the project; skipped with a warning if
// it is missing, since test_kernel does not link it).
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

struct Run {
    int rc;
    std::string err;
};

Run demcal(const std::string& args, const fs::path& dir) {
    fs::create_directories(dir);
    const std::string cmd = std::string("'") + DEMCAL_BINARY + "' silo " + args + " > '" + (dir / "out.log").string() +
                            "' 2> '" + (dir / "err.log").string() + "'";
    const int status = std::system(cmd.c_str());
    std::ifstream e(dir / "err.log");
    std::stringstream s;
    s << e.rdbuf();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, s.str()};
}

}  // namespace

TEST_CASE("demcal silo: bad input exits 2 naming the field and the value", "[silo][cli]") {
    if (!fs::exists(DEMCAL_BINARY)) {
        WARN("demcal not built: " << DEMCAL_BINARY);
        return;
    }
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_bad";
    fs::remove_all(dir);
    const fs::path out = dir / "never";
    struct Case {
        std::string args, expect;
    };
    for (const Case& c : {Case{"--theta 95", "theta = 95"}, Case{"--theta 0", "theta = 0"},
                          Case{"--theta 30 --outlet 0.01", "outlet = 0.01"},
                          Case{"--theta 30 --diameter 0.02", "diameter = 0.02"},
                          Case{"--theta 30 --rect --c 0.02", "c (width) = 0.02"},
                          Case{"--theta 30 --rect --b 0.01", "b (depth) = 0.01"},
                          Case{"--theta 30 --particles 0", "particles = 0"},
                          Case{"--theta 30 --stiffness-scale -1", "stiffness_scale = -1"},
                          Case{"--theta 30 --stop-fraction 2", "stop_fraction = 2"},
                          Case{"--theta 30 --b 0.05", "--b applies to a rectangular hopper"},
                          Case{"", "theta: missing"}}) {
        INFO(c.args);
        const Run r = demcal(c.args + " --out '" + out.string() + "'", dir);
        CHECK(r.rc == 2);
        CHECK_THAT(r.err, Catch::Matchers::Contains(c.expect));
        CHECK_FALSE(fs::exists(out));
    }
    std::ofstream(dir / "g.json") << R"({"shape": "conical", "theta_deg": 30, "outlet_mm": 35})";
    const Run r = demcal("--geometry '" + (dir / "g.json").string() + "' --out '" + out.string() + "'", dir);
    CHECK(r.rc == 2);
    CHECK_THAT(r.err, Catch::Matchers::Contains("unknown key 'outlet_mm'"));
    fs::remove_all(dir);
}

TEST_CASE("demcal silo: a tiny run writes discharge.csv and summary.json", "[silo][cli]") {
    if (!fs::exists(DEMCAL_BINARY)) {
        WARN("demcal not built: " << DEMCAL_BINARY);
        return;
    }
    const fs::path dir = fs::temp_directory_path() / "demcal_test_silo_cli_run";
    fs::remove_all(dir);
    const Run r = demcal("--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                             "/examples/silo/reduced_conical_70deg.json' --theta 45 --particles 300 "
                             "--stiffness-scale 0.001 --fill-time 0.3 --max-time 0.2 --threads 1 --no-plots --out '" +
                             (dir / "out").string() + "'",
                         dir);
    INFO(r.err);
    REQUIRE(r.rc == 0);
    CHECK(fs::exists(dir / "out" / "discharge.csv"));
    std::ifstream f(dir / "out" / "summary.json");
    std::stringstream s;
    s << f.rdbuf();
    CHECK_THAT(s.str(), Catch::Matchers::Contains("\"wall_to_axis_velocity_ratio\""));
    CHECK_THAT(s.str(), Catch::Matchers::Contains("\"grains\": 300"));
    fs::remove_all(dir);
}
