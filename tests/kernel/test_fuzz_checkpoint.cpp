// The kernel state reader (what every checkpoint holds: kernel/state_io.hpp's length-prefixed arrays closed by a
// checksum) fed seeded mutations of a valid state: truncations, inserted bytes and slices, flipped bits. Each is
// refused with the file named, or is the valid state itself; never a crash, never a damaged state loaded.
#include <catch2/catch.hpp>

#include <sstream>
#include <stdexcept>
#include <string>

#include "fuzz_mutations.hpp"
#include "kernel/simulation.hpp"
#include "small_state.hpp"

using namespace demcal::kernel;

TEST_CASE("fuzz: the kernel state reader reads or refuses every mutation", "[kernel][checkpoint][fuzz][input]") {
  const auto make = demcal::test::small_state_simulation;
  const std::string good = demcal::test::small_saved_state();
  int loaded = 0, refused = 0;
  for (std::uint32_t seed = 1; seed <= 1500; ++seed) {
    const std::string bad = demcal::test::mutated(good, seed);
    Simulation fresh = make();
    std::istringstream is(bad);
    try {
      fresh.load_state(is, "ckpt.bin");
      ++loaded;
      CHECK(bad == good);  // only an edit that changed nothing may load (e.g. a truncation at the very end)
    } catch (const std::runtime_error& e) {
      ++refused;
      CHECK(std::string(e.what()).find("ckpt.bin") != std::string::npos);
    }
  }
  CHECK(refused > 1400);
  INFO("loaded " << loaded);
}
