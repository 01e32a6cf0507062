// The cohesive hopper case (kernel/cases/cohesive_hopper.hpp) and `demcal cutoff`: a cohesionless bed flows out of
// the hopper, a cohesive one (Bo = 10) arches, strong vibration breaks the arch; bad settings are refused with the
// field named before any run.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "kernel/cases/cohesive_hopper.hpp"
#include "test_files.hpp"

using namespace demcal::kernel::cases;
namespace fs = std::filesystem;

TEST_CASE("cohesive hopper: a cohesionless bed flows, a cohesive one arches, strong vibration breaks the arch",
          "[kernel][cohesion][vibration]") {
  CohesiveHopperCase c;
  c.grains = 400;
  c.window = 0.5;
  c.amplitude = 1e-4;
  c.bond_number = 0;
  const CohesiveHopperOutcome free = run_cohesive_hopper(c);
  CHECK(free.flows());
  c.bond_number = 10;
  const CohesiveHopperOutcome arched = run_cohesive_hopper(c);
  CHECK(arched.discharged_fraction < 0.05);
  c.frequency = 400;  // 64 g at 0.1 mm
  const CohesiveHopperOutcome shaken = run_cohesive_hopper(c);
  CHECK(shaken.discharged_fraction > 5 * arched.discharged_fraction + 0.05);
  CHECK(shaken.peak_acceleration_g == Approx(1e-4 * std::pow(2 * M_PI * 400, 2) / 9.81));
}

TEST_CASE("cohesive hopper: bad settings and searches name the field and the value", "[kernel][cohesion]") {
  CohesiveHopperCase c;
  c.bond_number = -1;
  CHECK_THROWS_WITH(validate(c), Catch::Matchers::Contains("bond_number = -1"));
  c = {};
  c.frequency = 1e-310;
  CHECK_THROWS_WITH(validate(c), Catch::Matchers::Contains("frequency"));
  c = {};
  c.frequency = 900;
  c.young = 5e4;  // a long time step: too few steps per period
  CHECK_THROWS_WITH(validate(c), Catch::Matchers::Contains("20 time steps per period"));
  c = {};
  CutoffSearch s;
  s.lo = 300;
  s.hi = 100;
  CHECK_THROWS_WITH(validate(c, s), Catch::Matchers::Contains("bracket"));
  s = {};
  s.tol = 1000;
  CHECK_THROWS_WITH(validate(c, s), Catch::Matchers::Contains("tol"));
  s = {};
  s.seeds.clear();
  CHECK_THROWS_WITH(validate(c, s), Catch::Matchers::Contains("seeds"));
}

TEST_CASE("demcal cutoff: bad input exits 2 naming the option before any run or file", "[kernel][cohesion][cli]") {
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-cutoff-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string json = (dir / "cutoff.json").string();
  const std::pair<std::string, std::string> cases[] = {
      {"--bracket 400,0", "bracket"},     {"--bracket 0,x", "--bracket"}, {"--tol 1000", "tol"},
      {"--bond-number nan", "--bond-number"}, {"--seeds -1", "--seeds"},   {"--amplitude 1", "--amplitude"},
      {"--json " + dir.string(), "--json"},
      // the silo case (options after --): its own options stay with demcal silo, the search's with cutoff
      {"--bond-number 5 -- --theta 30", "--bond-number applies to the small hopper"},
      {"-- --theta 30 --seed 3", "silo option --seed after --: demcal cutoff sets it"},
      {"-- --theta 30 --vibration-frequency 50", "--vibration-frequency after --"},
      {"-- --theta 30 --out " + dir.string(), "--out does not apply to demcal cutoff"},
      {"-- --theta 30 --colour red", "silo options of demcal cutoff"},
      {"-- --theta 95", "theta"},
      {"--bracket 0,5000 -- --theta 30", "bracket"},
      {"--bracket 0,900 -- --theta 30 --stiffness-scale 1e-3", "vibration_frequency"},
      {"--bracket 0,400 -- --theta 30 --stiffness-scale 1e-6", "--stiffness-scale = 1e-06"}};
  for (const auto& [args, expect] : cases) {
    INFO(args);
    // --json first: after -- every word is a silo option
    const std::string run = std::string("'") + DEMCAL_BINARY + "' cutoff " +
                            (args.rfind("--json", 0) == 0 ? "" : "--json '" + json + "' ") + args + " > '" +
                            (dir / "out.log").string() + "' 2>&1";
    const int status = std::system(run.c_str());
    CHECK((WIFEXITED(status) ? WEXITSTATUS(status) : -1) == 2);
    CHECK_THAT(demcal::test::read_file(dir / "out.log"), Catch::Matchers::Contains(expect));
    CHECK_FALSE(fs::exists(json));
  }
  fs::remove_all(dir);
}
