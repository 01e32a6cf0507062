// The kernel and real YADE follow one trajectory: a tiny reduced silo filled by the kernel, discharged for 0.035 s
// (540 steps, the first grains leaving the silo and removed) by the kernel with YADE's Hertz-Mindlin, YADE's clump
// rotation, silo.py's 72-facet walls and YADE's start (demcal silo --start-as-yade-import), and by
// yade_scripts/silo.py from the exported bed: every grain ends where the other code put it, to 1e-4 of the grains'
// median displacement (measured 5e-6, the rest of a 1e-9 start grown by the flow's chaos). Without YADE's start the
// same kernel run misses by far more. Before 2026-12-04 the kernel evaluated every force again after a removal, and
// the two codes parted at the first grain removed (examples/crosscheck/README.md).
#include "demcal_cli.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using demcal::test::read_file;
using nlohmann::json;

namespace {

json read_json(const fs::path& p) { return json::parse(read_file(p)); }

void write_json(const fs::path& p, const json& j) {
    std::ofstream f(p);
    f << j.dump(1);
}

std::vector<std::vector<double>> positions(const json& bed) {
    return bed.at("grains").at("position_m").get<std::vector<std::vector<double>>>();
}

double distance(const std::vector<double>& a, const std::vector<double>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// The largest distance between the two codes' grains over the median displacement of the kernel's grains.
double largest_miss(const json& start, const json& kernel_end, const json& yade_end) {
    const auto x0 = positions(start), xk = positions(kernel_end), xy = positions(yade_end);
    const auto index = yade_end.at("bed_index").get<std::vector<std::size_t>>();
    REQUIRE(xk.size() == xy.size());
    REQUIRE(index.size() == xy.size());
    std::vector<double> moved;
    double miss = 0;
    for (std::size_t k = 0; k < xy.size(); ++k) {
        moved.push_back(distance(xk[k], x0.at(index[k])));
        miss = std::max(miss, distance(xk[k], xy[k]));
    }
    std::nth_element(moved.begin(), moved.begin() + std::ptrdiff_t(moved.size() / 2), moved.end());
    const double median = moved[moved.size() / 2];
    REQUIRE(median > 0);
    return miss / median;
}

}  // namespace

TEST_CASE("kernel and YADE follow one trajectory from the same bed once the kernel starts as YADE's import does",
          "[yade]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-yade-trajectory-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path src(DEMCAL_SOURCE_DIR);
    json material = read_json(src / "examples/materials/silo_wheat_table21.json");
    material["grain_grain"]["rolling_friction"] = 0;  // YADE's law has none
    material["grain_wall"]["rolling_friction"] = 0;
    write_json(dir / "material.json", material);
    // the time limit is checked at the end of each record interval (0.002 s): 18 intervals, 540 steps
    const std::string common = "silo --theta 45 --particles 300 --stiffness-scale 1e-3 --seed 3 --max-time 0.035 "
                               "--threads 1 --no-plots --no-checkpoint --geometry '" +
                               (src / "examples/silo/reduced_conical_70deg.json").string() + "' --material '" +
                               (dir / "material.json").string() +
                               "' --contact-law yade --discharge-rotation yade --discharge-wall-facets 72";
    REQUIRE(demcal::test::run_demcal_command(common + " --start-as-yade-import --export-bed '" +
                                                 (dir / "bed.json").string() + "' --export-final-bed '" +
                                                 (dir / "kernel_end.json").string() + "' --out '" +
                                                 (dir / "kernel").string() + "'",
                                             dir / "kernel.log") == 0);
    REQUIRE(demcal::test::run_demcal_command(common + " --export-final-bed '" + (dir / "plain_end.json").string() +
                                                 "' --out '" + (dir / "plain").string() + "'",
                                             dir / "plain.log") == 0);
    const json bed = read_json(dir / "bed.json");
    // silo.py's params for the bed, as demcal crosscheck silo writes them, and the grains left at the end
    json geometry = json::object();
    for (const char* k : {"shape", "theta_deg", "outlet_m", "D_m", "body_height_m"}) geometry[k] = bed["geometry"][k];
    const json params = {{"bed_file", "bed.json"},
                         {"geometry", geometry},
                         {"material", bed["material"]},
                         {"run",
                          {{"stiffness_scale", bed["stiffness_scale"]},
                           {"time_step_fraction", bed["time_step_fraction"]},
                           {"discharge_time_s", 0.035},
                           {"sample_interval_s", bed["record_interval_s"]},
                           {"removal_depth_m", bed["removal_depth_m"]},
                           {"final_bed_file", "yade_end.json"}}}};
    write_json(dir / "params.json", params);
    const std::string yade = "cd '" + dir.string() + "' && yade -n -j1 -x '" + (src / "yade_scripts/run_clean.py").string() +
                             "' '" + (src / "yade_scripts/silo.py").string() +
                             "' params.json result.json > yade.log 2>&1";
    const int status = std::system(yade.c_str());
    INFO(read_file(dir / "yade.log"));
    REQUIRE((WIFEXITED(status) ? WEXITSTATUS(status) : -1) == 0);
    const json kernel_end = read_json(dir / "kernel_end.json"), yade_end = read_json(dir / "yade_end.json");
    const json summary = read_json(dir / "kernel" / "summary.json");
    CHECK(summary["settings"]["contacts_at_opening"] == "yade_import");
    CHECK(kernel_end["moment"] == "end");
    // the same number of steps after the opening in both codes
    const double dt = bed["time_step_s"];
    const double kernel_steps = (kernel_end["time_s"].get<double>() - bed["opening_time_s"].get<double>()) / dt;
    CHECK(std::lround(kernel_steps) == yade_end["steps"].get<long>());
    CHECK(yade_end["steps"].get<long>() >= 40);
    const double same_start = largest_miss(bed, kernel_end, yade_end);
    const double plain_start = largest_miss(bed, read_json(dir / "plain_end.json"), yade_end);
    INFO("largest miss over the median displacement: YADE's start " << same_start << ", the kernel's own " << plain_start);
    CHECK(same_start < 1e-4);
    CHECK(plain_start > 1e-2);
    // grains left the silo and were removed in both codes: the trajectories agree through removals
    CHECK(yade_end["grains"]["count"].get<int>() < 300);
    CHECK(yade_end["grains"]["count"] == kernel_end["grains"]["count"]);
    fs::remove_all(dir);
}
