// The kernel's copies of the random numbers YADE's shear-box script draws (kernel/cases/yade_random.hpp) give YADE's
// numbers exactly: makeCloud's spheres (Boost's mt19937 and generate_canonical, started afresh by each call, the stop
// at the first sphere without room) and Python's random.Random. The reference files were written by real YADE
// (yade_scripts/random_numbers.py); the [yade] case writes them again and must find them unchanged.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include "kernel/cases/yade_random.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;
using namespace demcal::kernel;
using namespace demcal::kernel::cases;

namespace {

std::string g17(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// What yade_scripts/random_numbers.py writes for `seed`, computed by the kernel's copies.
std::string kernel_numbers(long seed) {
  std::ostringstream o;
  const auto first = make_cloud(Vec3(0.001, 0.002, 0.003), Vec3(0.02, 0.015, 0.03), 0.0012, 0.3, 60, seed);
  const auto second = make_cloud(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.001, 0.1, 400, seed);
  for (const auto* cloud : {&first, &second}) {
    o << "placed " << cloud->size() << "\n";
    for (const CloudSphere& s : *cloud)
      o << g17(s.centre.x()) << " " << g17(s.centre.y()) << " " << g17(s.centre.z()) << " " << g17(s.radius) << "\n";
  }
  PythonRandom rng(static_cast<std::uint64_t>(seed));
  for (int k = 0; k < 20; ++k) o << "random " << g17(rng.random()) << "\n";
  for (int k = 0; k < 5; ++k) o << "uniform " << g17(rng.uniform(-1, 1)) << "\n";
  return o.str();
}

const long kSeeds[] = {0, 7, 2147483647};

// The first line where two texts differ ("" when they are equal), for a readable failure.
std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ga = bool(std::getline(sa, la)), gb = bool(std::getline(sb, lb));
    if (!ga && !gb) return "";
    if (la != lb || ga != gb) return "line " + std::to_string(line) + ": kernel '" + la + "', YADE '" + lb + "'";
  }
}

fs::path reference(long seed) {
  return fs::path(DEMCAL_SOURCE_DIR) / "tests/data/yade_random" / ("seed_" + std::to_string(seed) + ".txt");
}

}  // namespace

TEST_CASE("makeCloud and Python's random give YADE's numbers to the last digit", "[kernel][yade_random]") {
  for (long seed : kSeeds) {
    INFO("seed " << seed);
    const std::string expected = demcal::test::read_file(reference(seed));
    REQUIRE(!expected.empty());
    CHECK(first_difference(kernel_numbers(seed), expected) == "");
  }
}

TEST_CASE("a cloud with no room left stops at the first sphere that finds none", "[kernel][yade_random]") {
  const auto cloud = make_cloud(Vec3::Zero(), Vec3(0.02, 0.02, 0.02), 0.002, 0.0, 1000, 3);
  CHECK(cloud.size() < 1000);
  CHECK(cloud.size() > 20);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    for (std::size_t j = i + 1; j < cloud.size(); ++j)
      CHECK((cloud[i].centre - cloud[j].centre).norm() > cloud[i].radius + cloud[j].radius);
}

TEST_CASE("the committed random numbers are what real YADE draws today", "[yade]") {
  const fs::path src = fs::path(DEMCAL_SOURCE_DIR);
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-yade-random-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (long seed : kSeeds) {
    INFO("seed " << seed);
    const fs::path out = dir / ("seed_" + std::to_string(seed) + ".txt");
    const std::string cmd = "cd '" + dir.string() + "' && yade -n -j1 -x '" +
                            (src / "yade_scripts/run_clean.py").string() + "' '" +
                            (src / "yade_scripts/random_numbers.py").string() + "' " + std::to_string(seed) + " '" +
                            out.string() + "' > '" + (dir / "yade.log").string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    INFO(demcal::test::read_file(dir / "yade.log"));
    REQUIRE((WIFEXITED(status) ? WEXITSTATUS(status) : -1) == 0);
    CHECK(demcal::test::read_file(out) == demcal::test::read_file(reference(seed)));
  }
  fs::remove_all(dir);
}
