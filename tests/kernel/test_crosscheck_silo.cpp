// demcal crosscheck silo end to end with real YADE: the kernel fills and discharges a tiny reduced silo, YADE
// discharges the same bed; the report holds both rates (within 25 % of each other on 300 grains), the curve gap, the
// costs; the same command again reuses both runs (nothing started: they are in the campaign store, which `demcal
// status` lists; a run whose output is gone runs again, alone); a deliberate mismatch of the grains' friction is
// flagged; a bad angle is refused before anything runs. YADE's flow pattern is measured by the kernel's classifier on
// YADE's frames: on 600 grains in a 20 deg hopper both codes give mass flow. --fill both: YADE also fills the silo
// itself from the kernel's generated cloud, to the kernel's rest rule, and discharges that bed. --kernel-law yade: the
// kernel runs YADE's own Hertz-Mindlin, and the report says so.
#include "slurm_for_test.hpp"
#include "demcal_cli.hpp"
#include "test_files.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using demcal::test::read_file;

namespace {
int run_demcal(const std::string& args, const fs::path& log) { return demcal::test::run_demcal_command(args, log); }
}  // namespace

TEST_CASE("crosscheck silo runs the kernel and YADE on one bed and reports both", "[yade]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-xsilo-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string args = "crosscheck silo --theta 45 --particles 300 --stiffness-scale 1e-3 --geometry '" +
                             (fs::path(DEMCAL_SOURCE_DIR) / "examples/silo/reduced_conical_70deg.json").string() +
                             "' --max-time 3 --jobs 1 -c '" + (dir / "c").string() + "'";
    REQUIRE(run_demcal(args, dir / "first.log") == 0);
    INFO(read_file(dir / "first.log"));
    const auto report = nlohmann::json::parse(read_file(dir / "c" / "crosscheck_silo.json"));
    REQUIRE(report["angles"].size() == 1);
    const auto& a = report["angles"][0];
    CHECK(a["kernel"]["rate_kg_s"].get<double>() > 0);
    CHECK(a["yade"]["rate_kg_s"].get<double>() > 0);
    CHECK(a["rate_ratio_yade_over_kernel"].get<double>() > 0.8);
    CHECK(a["rate_ratio_yade_over_kernel"].get<double>() < 1.25);
    CHECK(a["largest_curve_gap_of_filled_mass"].get<double>() < 0.2);
    CHECK(a["cpu_ratio_yade_over_kernel"].get<double>() > 1);
    // like for like: YADE's discharge against the kernel's discharge, a part of the kernel's whole run
    CHECK(a["kernel"]["discharge_cpu_s"].get<double>() > 0);
    CHECK(a["kernel"]["discharge_cpu_s"].get<double>() < a["kernel"]["cpu_s"].get<double>());
    CHECK(a["discharge_cpu_ratio_yade_over_kernel"].get<double>() > a["cpu_ratio_yade_over_kernel"].get<double>());
    CHECK(fs::exists(dir / "c" / "theta_45" / "bed.json"));
    CHECK(fs::exists(dir / "c" / "crosscheck_silo.md"));
    // the same command again: both runs reused
    REQUIRE(run_demcal(args, dir / "second.log") == 0);
    CHECK(read_file(dir / "second.log").find("started") == std::string::npos);
    // the runs live in the campaign store: status lists them
    REQUIRE(run_demcal("status '" + (dir / "c").string() + "'", dir / "status.log") == 0);
    CHECK_THAT(read_file(dir / "status.log"), Catch::Contains("[complete] crosscheck_silo: 2 runs, 2 done"));
    // a run's output gone: that run again, and only it (the kernel rebuilds the same bed bit for bit, so YADE's run
    // of it is still the one in the store)
    fs::remove(dir / "c" / "theta_45" / "bed.json");
    REQUIRE(run_demcal(args, dir / "again.log") == 0);
    CHECK_THAT(read_file(dir / "again.log"), Catch::Contains("started  theta_45 kernel"));
    CHECK(read_file(dir / "again.log").find("started  theta_45 yade") == std::string::npos);
    CHECK(report["rates_agree"] == true);
    // a deliberate mismatch (YADE's grains far more frictional) on the same bed: flagged
    auto material = nlohmann::json::parse(
        read_file(fs::path(DEMCAL_SOURCE_DIR) / "examples/materials/silo_wheat_table21.json"));
    material["grain_grain"]["friction"] = 1.0;
    {
        std::ofstream f(dir / "mismatch.json");
        f << material.dump();
    }
    REQUIRE(run_demcal(args + " --yade-material '" + (dir / "mismatch.json").string() + "'", dir / "third.log") == 0);
    const auto mismatch = nlohmann::json::parse(read_file(dir / "c" / "crosscheck_silo.json"));
    CHECK(mismatch["rates_agree"] == false);
    CHECK(mismatch["angles"][0]["rates_agree"] == false);
    CHECK(mismatch["angles"][0]["yade_material_as_bed"] == false);
    CHECK(read_file(dir / "third.log").find("DIFFER") != std::string::npos);
    // the same file for both codes is no mismatch: a void option, refused
    CHECK(run_demcal(args + " --material '" + (dir / "mismatch.json").string() + "' --yade-material '" +
                         (dir / "mismatch.json").string() + "'",
                     dir / "same.log") == 2);
    CHECK_THAT(read_file(dir / "same.log"), Catch::Contains("the same material as --material"));
    // YADE killed at its timeout: nothing compared, and the report says so (it said "rates agree" and exit 1)
    const std::string timed_out = "crosscheck silo --theta 45 --particles 200 --stiffness-scale 1e-3 --max-time 1 "
                                  "--timeout 1 --jobs 1 -c '" + (dir / "t").string() + "'";
    CHECK(run_demcal(timed_out, dir / "timeout.log") == 1);
    CHECK_THAT(read_file(dir / "timeout.log"), Catch::Contains("retry later theta_45 yade"));
    const auto none = nlohmann::json::parse(read_file(dir / "t" / "crosscheck_silo.json"));
    CHECK(none["angles_compared"] == 0);
    CHECK(none["complete"] == false);
    CHECK(none["rates_agree"].is_null());
    CHECK(none["patterns_agree"].is_null());
    CHECK_THAT(read_file(dir / "t" / "crosscheck_silo.md"), Catch::Contains("No angle could be compared"));
    // a bad angle: exit 2, named, nothing run
    CHECK(run_demcal("crosscheck silo --theta 95 -c '" + (dir / "bad").string() + "'", dir / "bad.log") == 2);
    CHECK(read_file(dir / "bad.log").find("theta") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "bad"));
    fs::remove_all(dir);
}

TEST_CASE("crosscheck silo --kernel-law yade: the kernel runs YADE's Hertz-Mindlin (and with --kernel-rotation yade its "
          "clump rotation, with --wall-facets YADE's walls), the report says so", "[yade]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-xsilo-law-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto material = nlohmann::json::parse(
        read_file(fs::path(DEMCAL_SOURCE_DIR) / "examples/materials/silo_wheat_table21.json"));
    material["grain_grain"]["rolling_friction"] = 0;  // YADE's law has none: refused otherwise
    material["grain_wall"]["rolling_friction"] = 0;
    {
        std::ofstream f(dir / "no_rolling.json");
        f << material.dump();
    }
    const std::string args = "crosscheck silo --theta 45 --particles 300 --stiffness-scale 1e-3 --geometry '" +
                             (fs::path(DEMCAL_SOURCE_DIR) / "examples/silo/reduced_conical_70deg.json").string() +
                             "' --max-time 3 --jobs 1 --material '" + (dir / "no_rolling.json").string() +
                             "' --kernel-law yade -c '" + (dir / "c").string() + "'";
    REQUIRE(run_demcal(args, dir / "first.log") == 0);
    INFO(read_file(dir / "first.log"));
    const auto report = nlohmann::json::parse(read_file(dir / "c" / "crosscheck_silo.json"));
    CHECK(report["kernel_contact_law"] == "yade");
    CHECK_THAT(report["known_differences"].dump(), Catch::Contains("YADE 2023.02a's Hertz-Mindlin"));
    const auto summary =
        nlohmann::json::parse(read_file(dir / "c" / "theta_45_law-yade" / "kernel" / "summary.json"));
    CHECK(summary["settings"]["contact_law_family"] == "yade");
    CHECK_THAT(summary["settings"]["contact_law"].get<std::string>(), Catch::Contains("YADE"));
    const auto& a = report["angles"][0];
    CHECK(a["rate_ratio_yade_over_kernel"].get<double>() > 0.8);
    CHECK(a["rate_ratio_yade_over_kernel"].get<double>() < 1.25);
    CHECK(report["kernel_discharge_rotation"] == "richardson");
    // the kernel discharging with YADE's clump rotation from the same bed: the kernel runs again, YADE's run of that
    // bed is reused, and the report names the scheme in place of the integrators' difference
    REQUIRE(run_demcal(args + " --kernel-rotation yade", dir / "rotation.log") == 0);
    CHECK_THAT(read_file(dir / "rotation.log"), Catch::Contains("started  theta_45_law-yade kernel-rotation-yade"));
    CHECK(read_file(dir / "rotation.log").find("started  theta_45_law-yade yade") == std::string::npos);
    const auto rotated = nlohmann::json::parse(read_file(dir / "c" / "crosscheck_silo.json"));
    CHECK(rotated["kernel_discharge_rotation"] == "yade");
    CHECK_THAT(rotated["known_differences"].dump(), Catch::Contains("YADE's aspherical clump rotation"));
    const auto rotated_summary = nlohmann::json::parse(
        read_file(dir / "c" / "theta_45_law-yade" / "kernel-rotation-yade" / "summary.json"));
    CHECK(rotated_summary["settings"]["discharge_clump_rotation"] == "yade");
    CHECK(rotated_summary["filled_mass_kg"] == summary["filled_mass_kg"]);
    // and between silo.py's walls too (72 facets, YADE's own count): the kernel runs again on the same bed, YADE's run
    // is reused, the report names the walls as the same
    REQUIRE(run_demcal(args + " --kernel-rotation yade --wall-facets 72", dir / "facets.log") == 0);
    CHECK_THAT(read_file(dir / "facets.log"),
               Catch::Contains("started  theta_45_law-yade kernel-rotation-yade-facets-72"));
    CHECK(read_file(dir / "facets.log").find("started  theta_45_law-yade yade") == std::string::npos);
    const auto faceted = nlohmann::json::parse(read_file(dir / "c" / "crosscheck_silo.json"));
    CHECK(faceted["wall_facets"] == 72);
    CHECK_THAT(faceted["known_differences"].dump(), Catch::Contains("the same 72-sided facet polygons"));
    const auto faceted_summary = nlohmann::json::parse(
        read_file(dir / "c" / "theta_45_law-yade" / "kernel-rotation-yade-facets-72" / "summary.json"));
    CHECK(faceted_summary["settings"]["discharge_wall_facets"] == 72);
    CHECK(faceted_summary["filled_mass_kg"] == summary["filled_mass_kg"]);
    CHECK(faceted["angles"][0]["kernel"]["rate_kg_s"] != rotated["angles"][0]["kernel"]["rate_kg_s"]);
    // back to the kernel's own rotation in the same campaign: nothing runs, and the report is the first one's, not
    // built from the other scheme's run
    REQUIRE(run_demcal(args, dir / "back.log") == 0);
    CHECK(read_file(dir / "back.log").find("started") == std::string::npos);
    const auto back = nlohmann::json::parse(read_file(dir / "c" / "crosscheck_silo.json"));
    CHECK(back["kernel_discharge_rotation"] == "richardson");
    CHECK(back["angles"][0]["kernel"]["rate_kg_s"] == a["kernel"]["rate_kg_s"]);
    CHECK(back["angles"][0]["kernel"]["rate_kg_s"] != rotated["angles"][0]["kernel"]["rate_kg_s"]);
    // the default material (rolling friction 0.01) on YADE's law: refused before anything runs, the field named
    const std::string bad = "crosscheck silo --theta 45 --particles 300 --kernel-law yade -c '" +
                            (dir / "bad").string() + "'";
    CHECK(run_demcal(bad, dir / "bad.log") == 2);
    CHECK_THAT(read_file(dir / "bad.log"), Catch::Contains("rolling_friction"));
    CHECK_FALSE(fs::exists(dir / "bad"));
    fs::remove_all(dir);
}

TEST_CASE("crosscheck silo classifies YADE's flow pattern with the kernel's classifier, and YADE fills on its own",
          "[yade]") {
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-xsilo-pattern-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const std::string args = "crosscheck silo --theta 20 --particles 600 --stiffness-scale 1e-3 --geometry '" +
                             (fs::path(DEMCAL_SOURCE_DIR) / "examples/silo/reduced_conical_70deg.json").string() +
                             "' --max-time 3 --jobs 1 --fill both -c '" + (dir / "c").string() + "'";
    REQUIRE(run_demcal(args, dir.string() + ".log") == 0);
    const auto report = nlohmann::json::parse(read_file(dir / "c" / "crosscheck_silo.json"));
    const auto& a = report["angles"][0];
    INFO(a.dump(1));
    const auto& kernel = a["kernel"]["flow_pattern"];
    const auto& yade = a["yade"]["flow_pattern"];
    // YADE wrote frames at the kernel's interval over the same window of the discharge
    CHECK(fs::file_size(dir / "c" / "theta_20" / "yade" / "frames.bin") > 1000);
    CHECK(yade["frames"].get<int>() >= kernel["frames"].get<int>() - 3);
    CHECK(yade["frames"].get<int>() <= kernel["frames"].get<int>() + 3);
    CHECK(yade["wall_samples"].get<long>() > 100);
    CHECK(kernel["pattern"] == "mass");
    CHECK(yade["pattern"] == "mass");
    CHECK(std::abs(yade["wall_to_axis_velocity_ratio"].get<double>() -
                   kernel["wall_to_axis_velocity_ratio"].get<double>()) < 0.2);
    CHECK(a["patterns_agree"] == true);
    CHECK(report["patterns_agree"] == true);
    CHECK(read_file(dir / "c" / "crosscheck_silo.md").find("YADE pattern (wall/axis)") != std::string::npos);
    // YADE's own filling: the same cloud, the kernel's rest rule; a bed like the kernel's that discharges like it
    const auto& own = a["yade_own_fill"];
    REQUIRE(own.is_object());
    CHECK(own["fill"]["at_rest"] == true);
    CHECK(own["fill"]["grains_lost"] == 0);
    CHECK(own["fill"]["bed_height_m"].get<double>() ==
          Approx(own["kernel_fill"]["height_m"].get<double>()).epsilon(0.1));
    CHECK(own["rate_ratio_yade_over_kernel"].get<double>() > 0.8);
    CHECK(own["rate_ratio_yade_over_kernel"].get<double>() < 1.25);
    CHECK(own["filling_share_of_rate_ratio"].get<double>() ==
          Approx(own["rate_ratio_yade_over_kernel"].get<double>() - a["rate_ratio_yade_over_kernel"].get<double>()));
    CHECK(own["flow_pattern"]["pattern"] == "mass");
    CHECK(fs::exists(dir / "c" / "theta_20" / "cloud.json"));
    CHECK(read_file(dir / "c" / "crosscheck_silo.md").find("Each code fills on its own") != std::string::npos);
    fs::remove_all(dir);
    fs::remove(dir.string() + ".log");
}

TEST_CASE("crosscheck silo --executor slurm: both codes' runs as SLURM array tasks give the local report's rates",
          "[yade][slurm]") {
    if (::geteuid() != 0) {
        WARN("not root: cannot start SLURM daemons here, skipped");
        return;
    }
    const std::string source = DEMCAL_SOURCE_DIR;
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-xsilo-slurm-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string args = "crosscheck silo --theta 45 --particles 300 --stiffness-scale 1e-3 --geometry '" +
                             (fs::path(source) / "examples/silo/reduced_conical_70deg.json").string() +
                             "' --max-time 3 --jobs 1 ";
    REQUIRE(run_demcal(args + "-c '" + (dir / "local").string() + "'", dir / "local.log") == 0);
    demcal::test::SlurmForTest cluster;
    REQUIRE(cluster.up());
    const int rc = run_demcal(args + "--executor slurm -c '" + (dir / "slurm").string() + "'", dir / "slurm.log");
    cluster.stop();
    INFO(read_file(dir / "slurm.log"));
    REQUIRE(rc == 0);
    const auto local = nlohmann::json::parse(read_file(dir / "local" / "crosscheck_silo.json"));
    const auto slurm = nlohmann::json::parse(read_file(dir / "slurm" / "crosscheck_silo.json"));
    // the same bed (the kernel is deterministic) and the same YADE discharge of it, wherever they ran
    CHECK(slurm["angles"][0]["kernel"]["rate_kg_s"] == local["angles"][0]["kernel"]["rate_kg_s"]);
    CHECK(slurm["angles"][0]["yade"]["rate_kg_s"] == local["angles"][0]["yade"]["rate_kg_s"]);
    CHECK(fs::exists(dir / "slurm" / "slurm"));     // the executor's batch scripts
    CHECK(fs::exists(dir / "slurm" / ".program"));  // the pinned program the kernel tasks ran
    fs::remove_all(dir);
}
