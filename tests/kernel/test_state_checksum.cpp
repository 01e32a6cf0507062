// A checkpoint's state is closed by a checksum: any damaged byte is refused with the file named, never resumed.
#include <catch2/catch.hpp>

#include <sstream>
#include <string>

#include "kernel/simulation.hpp"
#include "small_state.hpp"

using namespace demcal::kernel;

TEST_CASE("a kernel state with any one byte damaged is refused, never loaded", "[kernel][checkpoint]") {
  const auto make = demcal::test::small_state_simulation;
  const std::string good = demcal::test::small_saved_state();
  {
    Simulation fresh = make();
    std::istringstream is(good);
    REQUIRE_NOTHROW(fresh.load_state(is, "ckpt.bin"));
  }
  int refused = 0, tried = 0;
  for (std::size_t at = 0; at < good.size(); at += 1 + good.size() / 400) {
    std::string bad = good;
    bad[at] = char(bad[at] ^ 0x10);
    Simulation fresh = make();
    std::istringstream is(bad);
    ++tried;
    try {
      fresh.load_state(is, "ckpt.bin");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()).find("ckpt.bin") != std::string::npos);
      ++refused;
    }
  }
  CHECK(refused == tried);
}
