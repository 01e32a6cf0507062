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
  using demcal::kernel::silo::DischargeEnd;
  CohesiveHopperCase c;
  c.grains = 400;
  c.window = 1;
  c.amplitude = 1e-4;
  c.bond_number = 0;
  const CohesiveHopperOutcome free = run_cohesive_hopper(c);
  CHECK(free.end == DischargeEnd::stop_fraction);  // half the mass out: the run ends there
  CHECK(free.discharged_fraction >= 0.5);
  CHECK(free.flows(FlowCriterion::flow_stops));
  CHECK(free.flows(FlowCriterion::half_within_window));
  c.bond_number = 10;
  const CohesiveHopperOutcome arched = run_cohesive_hopper(c);
  INFO("arched: " << arched.discharged_fraction << " out in " << arched.discharge_s << " s");
  CHECK(arched.discharged_fraction < 0.05);
  // its flow stopped: no grain for the stall time, ended well before the window (its last grain within the stall
  // time of the opening plus the check interval of 500 steps)
  CHECK(arched.end == DischargeEnd::flow_stopped);
  CHECK(arched.discharge_s < c.window);
  CHECK(arched.discharge_s > demcal::kernel::silo::kFlowStallTime);
  CHECK_FALSE(arched.flows(FlowCriterion::flow_stops));
  c.frequency = 400;  // 64 g at 0.1 mm
  const CohesiveHopperOutcome shaken = run_cohesive_hopper(c);
  CHECK(shaken.discharged_fraction > 5 * arched.discharged_fraction + 0.05);
  CHECK(shaken.end != DischargeEnd::flow_stopped);
  CHECK(shaken.flows(FlowCriterion::flow_stops));
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
  // grains that a wall or a fall pushes more than a radius into another body pass through it (Hertz's impact overlap)
  c = {};
  c.frequency = 1000;
  c.amplitude = 0.01;  // walls at 63 m/s
  CHECK_THROWS_WITH(validate(c), Catch::Matchers::Contains("amplitude = 0.01: at 1000 Hz the walls move at up to") &&
                                     Catch::Matchers::Contains("radii and pass through"));
  c.amplitude = 1.1e-4;  // the seed's amplitude at the same frequency: 0.7 m/s
  CHECK_NOTHROW(validate(c));
  c = {};
  c.young = 1e3;
  CHECK_THROWS_WITH(validate(c), Catch::Matchers::Contains("young = 1000: the grains are so soft that one falling"));
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
  // a window in which no stall can be seen would call every arch flowing
  s = {};
  c.window = 0.6;
  CHECK_THROWS_WITH(validate(c, s), Catch::Matchers::Contains("window = 0.6 s: shorter than 1 s"));
  s.criterion = FlowCriterion::half_within_window;
  CHECK_NOTHROW(validate(c, s));
  // up to a minute (a broken arch near the cut-off drains slowly), not beyond
  s = {};
  c.window = 60;
  CHECK_NOTHROW(validate(c, s));
  c.window = 61;
  CHECK_THROWS_WITH(validate(c, s), Catch::Matchers::Contains("window = 61: must be in [0.05, 60] s"));
}

TEST_CASE("demcal cutoff: bad input exits 2 naming the option before any run or file", "[kernel][cohesion][cli]") {
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-cutoff-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string json = (dir / "cutoff.json").string();
  const std::pair<std::string, std::string> cases[] = {
      {"--bracket 400,0", "bracket"},     {"--bracket 0,x", "--bracket"}, {"--tol 1000", "--tol = 1000 Hz"},
      {"--bond-number nan", "--bond-number"}, {"--seeds -1", "--seeds"},   {"--amplitude 1", "--amplitude"},
      {"--json " + dir.string(), "--json"},
      {"--window 0.5", "window = 0.5 s: shorter than 1 s"},  {"--criterion half", "--criterion"},
      // an empty value is named as one, before the option's list of names ("--criterion:  not in {...}")
      {"--criterion ''", "--criterion: an empty value"},
      {"--window 0.5 -- --theta 30", "window = 0.5 s"},
      // the longest window: not below the first, and only by the criterion a longer window can decide
      {"--window 5 --max-window 2", "--max-window = 2 s: must be in [window, 60] s"},
      {"--criterion half-within-window --max-window 10", "--max-window = 10 s: a longer window decides runs by"},
      {"--max-window 61", "--max-window"},
      {"--window 5 --max-window 2 -- --theta 30", "--max-window = 2 s"},
      // the silo case (options after --): its own options stay with demcal silo, the search's with cutoff
      {"--bond-number 5 -- --theta 30", "--bond-number applies to the small hopper"},
      {"-- --theta 30 --seed 3", "silo option --seed after --: demcal cutoff sets it"},
      {"-- --theta 30 --vibration-frequency 50", "--vibration-frequency after --"},
      {"-- --theta 30 --out " + dir.string(), "--out does not apply to demcal cutoff"},
      {"-- --theta 30 --colour red", "silo options of demcal cutoff"},
      {"-- --theta 95", "theta"},
      {"--bracket 0,5000 -- --theta 30", "bracket"},
      // walls shaking at 63 m/s through 5 MPa grains: they passed through, and a cut-off was reported
      {"--amplitude 0.01 --grains 200 --window 1 --max-window 1 --bracket 0,1000 --tol 400",
       "--amplitude = 0.01: at 1000 Hz the walls move at up to 62.8"},
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
