// A checkpoint's state is closed by a checksum: any damaged byte is refused with the file named, never resumed.
#include <catch2/catch.hpp>

#include <sstream>
#include <string>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

TEST_CASE("a kernel state with any one byte damaged is refused, never loaded", "[kernel][checkpoint]") {
  auto make = [] {
    Simulation sim;
    const int a = sim.add_material({1e8, 0.3, 1500, "grain"});
    sim.set_pair(a, a, {{0.5}, {0.4}, {0.01}});
    sim.add_wall(Wall::plane({0, 0, 0}, {0, 0, 1}, a));
    for (int k = 0; k < 20; ++k) sim.add_sphere({0.003 * (k % 5), 0.003 * (k / 5), 0.002 + 0.0001 * k}, 1e-3, a);
    sim.set_timestep(0.2 * sim.rayleigh_timestep());
    return sim;
  };
  Simulation sim = make();
  sim.step(200);
  std::ostringstream os;
  sim.save_state(os);
  const std::string good = os.str();
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
