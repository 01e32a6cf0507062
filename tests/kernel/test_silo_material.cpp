// demcal silo --material FILE.json: the seed's Table 2.1 as a file gives the built-in default's run to the bit; a
// file with another material changes the run; bad files exit 2 naming the file, the field and the value, before
// anything is written.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "test_files.hpp"

namespace fs = std::filesystem;

namespace {

int run_silo(const std::string& args, const fs::path& log) {
  const std::string cmd = std::string("'") + DEMCAL_BINARY + "' silo " + args + " > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

const std::string kTiny = "--geometry '" + std::string(DEMCAL_SOURCE_DIR) +
                          "/examples/silo/reduced_conical_70deg.json' --theta 45 --particles 300 "
                          "--stiffness-scale 0.001 --fill-time 0.3 --max-time 0.2 --threads 1 --no-plots";
const std::string kTable21 = std::string(DEMCAL_SOURCE_DIR) + "/examples/materials/silo_wheat_table21.json";

// discharge.csv of a tiny run with `extra` options
std::string tiny_run(const fs::path& dir, const std::string& name, const std::string& extra) {
  const fs::path out = dir / name;
  const int rc = run_silo(kTiny + " " + extra + " --out '" + out.string() + "'", dir / (name + ".log"));
  INFO(demcal::test::read_file(dir / (name + ".log")));
  REQUIRE(rc == 0);
  return demcal::test::read_file(out / "discharge.csv");
}

}  // namespace

TEST_CASE("demcal silo --material: the Table 2.1 file is the default, bit for bit - another material changes the run",
          "[silo][cli][material]") {
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-silo-material-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string builtin = tiny_run(dir, "builtin", "");
  CHECK(tiny_run(dir, "file", "--material '" + kTable21 + "'") == builtin);
  // the same material with E instead of G (E = 2 G (1 + nu), exact in binary for these values) and a rougher wall
  std::ofstream(dir / "rough.json") << R"({"grain": {"young_Pa": 1.0024e9, "poisson": 0.4, "density_kg_m3": 1430},
    "wall": {"shear_modulus_Pa": 8e8, "poisson": 0.3, "density_kg_m3": 7500},
    "grain_grain": {"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01},
    "grain_wall": {"restitution": 0.6, "friction": 0.6, "rolling_friction": 0.01}})";
  CHECK(tiny_run(dir, "rough", "--material '" + (dir / "rough.json").string() + "'") != builtin);
  // a cohesion of 0 said aloud is no cohesion: the Hertz-Mindlin law, the same bits
  std::ofstream(dir / "dry.json") << R"({"grain": {"shear_modulus_Pa": 3.58e8, "poisson": 0.4, "density_kg_m3": 1430},
    "wall": {"shear_modulus_Pa": 8e8, "poisson": 0.3, "density_kg_m3": 7500},
    "grain_grain": {"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01, "surface_energy_J_m2": 0},
    "grain_wall": {"restitution": 0.6, "friction": 0.25, "rolling_friction": 0.01, "surface_energy_J_m2": 0}})";
  CHECK(tiny_run(dir, "dry", "--material '" + (dir / "dry.json").string() + "'") == builtin);
  // the seed grain's aspect ratio said aloud (11/6, shortest decimal) is the seed's grain: the same bits, and the
  // summary's material stays as the seed's (no aspect_ratio field); another one changes the run and is written back
  std::ofstream(dir / "seed_shape.json") << R"({"grain": {"shear_modulus_Pa": 3.58e8, "poisson": 0.4,
    "density_kg_m3": 1430, "shape": "wheat-clump", "aspect_ratio": 1.8333333333333333},
    "wall": {"shear_modulus_Pa": 8e8, "poisson": 0.3, "density_kg_m3": 7500},
    "grain_grain": {"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01},
    "grain_wall": {"restitution": 0.6, "friction": 0.25, "rolling_friction": 0.01}})";
  CHECK(tiny_run(dir, "seed_shape", "--material '" + (dir / "seed_shape.json").string() + "'") == builtin);
  CHECK_THAT(demcal::test::read_file(dir / "seed_shape" / "summary.json"), !Catch::Matchers::Contains("aspect_ratio"));
  std::ofstream(dir / "long.json") << R"({"grain": {"shear_modulus_Pa": 3.58e8, "poisson": 0.4,
    "density_kg_m3": 1430, "aspect_ratio": 2.25},
    "wall": {"shear_modulus_Pa": 8e8, "poisson": 0.3, "density_kg_m3": 7500},
    "grain_grain": {"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01},
    "grain_wall": {"restitution": 0.6, "friction": 0.25, "rolling_friction": 0.01}})";
  CHECK(tiny_run(dir, "long", "--material '" + (dir / "long.json").string() + "'") != builtin);
  CHECK_THAT(demcal::test::read_file(dir / "long" / "summary.json"),
             Catch::Matchers::Contains("\"aspect_ratio\": 2.25"));
  // a cohesive one runs on the JKR law, says so and writes its cohesion back
  std::ofstream(dir / "meal.json") << R"({"grain": {"shear_modulus_Pa": 3.58e8, "poisson": 0.4, "density_kg_m3": 1430},
    "wall": {"shear_modulus_Pa": 8e8, "poisson": 0.3, "density_kg_m3": 7500},
    "grain_grain": {"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01, "surface_energy_J_m2": 0.25},
    "grain_wall": {"restitution": 0.6, "friction": 0.25, "rolling_friction": 0.01}})";
  CHECK(tiny_run(dir, "meal", "--material '" + (dir / "meal.json").string() + "'") != builtin);
  const std::string summary = demcal::test::read_file(dir / "meal" / "summary.json");
  CHECK_THAT(summary, Catch::Matchers::Contains("JKR"));
  CHECK_THAT(summary, Catch::Matchers::Contains("\"surface_energy_J_m2\": 0.25"));
  CHECK_THAT(demcal::test::read_file(dir / "builtin" / "summary.json"),
             !Catch::Matchers::Contains("surface_energy") && !Catch::Matchers::Contains("JKR"));
  fs::remove_all(dir);
}

TEST_CASE("demcal silo --material: bad files name the file, the field and the value - nothing is written",
          "[silo][cli][material]") {
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-silo-material-bad-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string good_solid = R"({"shear_modulus_Pa": 3.58e8, "poisson": 0.4, "density_kg_m3": 1430})";
  const std::string good_pair = R"({"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01})";
  auto file = [&](const std::string& grain, const std::string& gg, const std::string& extra = "") {
    return "{\"grain\": " + grain + ", \"wall\": " + good_solid + ", \"grain_grain\": " + gg +
           ", \"grain_wall\": " + good_pair + extra + "}";
  };
  const std::pair<std::string, std::string> cases[] = {
      {file(good_solid, good_pair, ", \"colour\": 1"), "unknown key 'colour'"},
      {file(R"({"shear_modulus_Pa": 3.58e8, "young_Pa": 1e9, "poisson": 0.4, "density_kg_m3": 1430})", good_pair),
       "exactly one of shear_modulus_Pa and young_Pa"},
      {file(R"({"shear_modulus_Pa": 3.58e8, "density_kg_m3": 1430})", good_pair), "grain.poisson is missing"},
      {file(good_solid, R"({"restitution": 0.5, "friction": 20, "rolling_friction": 0.01})"),
       "grain_grain.friction = 20"},
      {file(good_solid, R"({"restitution": 0, "friction": 0.3, "rolling_friction": 0.01})"),
       "grain_grain.restitution = 0"},
      {file(R"({"shear_modulus_Pa": -1, "poisson": 0.4, "density_kg_m3": 1430})", good_pair), "grain.shear_modulus"},
      {file(R"({"shape": "sphere", "shear_modulus_Pa": 3.58e8, "poisson": 0.4, "density_kg_m3": 1430})", good_pair),
       "grain.shape"},
      {file(good_solid, R"({"restitution": "high", "friction": 0.3, "rolling_friction": 0.01})"), "must be a number"},
      {file(good_solid, R"({"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01,
                             "surface_energy_J_m2": -0.5})"), "grain_grain.surface_energy_J_m2 = -0.5"},
      {file(good_solid, R"({"restitution": 0.5, "friction": 0.3, "rolling_friction": 0.01,
                             "surface_energy_J_m2": "sticky"})"), "surface_energy_J_m2 = \"sticky\": must be a number"},
      {file(R"({"aspect_ratio": 3, "shear_modulus_Pa": 3.58e8, "poisson": 0.4, "density_kg_m3": 1430})", good_pair),
       "grain.aspect_ratio = 3: must lie in [1, 2.6]"},
      {file(R"({"aspect_ratio": 0.5, "shear_modulus_Pa": 3.58e8, "poisson": 0.4, "density_kg_m3": 1430})", good_pair),
       "grain.aspect_ratio = 0.5"},
      {file(R"({"aspect_ratio": "long", "shear_modulus_Pa": 3.58e8, "poisson": 0.4, "density_kg_m3": 1430})",
            good_pair), "grain.aspect_ratio = \"long\": must be a number"},
      {"[1, 2]", "': the top level must be a JSON object"}};
  int k = 0;
  for (const auto& [text, expect] : cases) {
    INFO(text);
    const fs::path f = dir / ("m" + std::to_string(k++) + ".json");
    std::ofstream(f) << text;
    const fs::path out = dir / "never";
    CHECK(run_silo(kTiny + " --material '" + f.string() + "' --out '" + out.string() + "'", dir / "log") == 2);
    const std::string log = demcal::test::read_file(dir / "log");
    CHECK_THAT(log, Catch::Matchers::Contains(expect) && Catch::Matchers::Contains("--material = '" + f.string()));
    CHECK_FALSE(fs::exists(out));
  }
  CHECK(run_silo(kTiny + " --material '" + dir.string() + "' --out '" + (dir / "never").string() + "'", dir / "log") == 2);
  CHECK_FALSE(fs::exists(dir / "never"));
  fs::remove_all(dir);
}
