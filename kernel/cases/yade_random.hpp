// The random numbers of YADE's shear-box script, number for number: SpherePack.makeCloud (YADE 2023.02a, Debian's)
// draws from Boost's mt19937 through generate_canonical<double, 53> (found in the library's symbols and confirmed on
// its output), the clump axes from Python's random.Random (MT19937 seeded by init_by_array, random() from two 32-bit
// draws). With them the kernel's shear box starts from the very cloud and
// clump orientations that yade_scripts/shear_box.py builds for the same seed (checked against real YADE in
// tests/kernel/test_yade_random.cpp), so the two engines are compared on one packing, not on two.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "kernel/types.hpp"

namespace demcal::kernel::cases {

/// MT19937's 32-bit words (the reference generator: Boost's and the standard library's mt19937, Python's core).
class Mt19937 {
 public:
  explicit Mt19937(std::uint32_t seed);            ///< init_genrand (Boost's and std's mt19937(seed))
  explicit Mt19937(const std::vector<std::uint32_t>& key);  ///< init_by_array (Python's random.seed)
  std::uint32_t operator()();

 private:
  void reload();
  std::array<std::uint32_t, 624> mt_{};
  int index_ = 624;
};

/// YADE's makeCloud generator: mt19937(seed) and Boost's generate_canonical<double, 53>: (w1 + w2 2^32) / 2^64.
class CloudRandom {
 public:
  explicit CloudRandom(std::uint32_t seed) : mt_(seed) {}
  double operator()();  ///< in [0, 1)

 private:
  Mt19937 mt_;
};

/// Python's random.Random(seed) for a non-negative integer seed: random() and uniform(a, b).
class PythonRandom {
 public:
  explicit PythonRandom(std::uint64_t seed);
  double random();  ///< 53-bit float in [0, 1), as CPython's random_random
  double uniform(double a, double b) { return a + (b - a) * random(); }

 private:
  Mt19937 mt_;
};

struct CloudSphere {
  Vec3 centre;
  double radius;
};

/// YADE's SpherePack.makeCloud(minCorner, maxCorner, rMean, rRelFuzz, num) for num > 0 in a box without periodicity:
/// radii deterministic and decreasing, r_i = rMean (1 + 2 (u_i - 1/2) rRelFuzz) with u_i = (num - i + 1/2)/(num + 1);
/// each sphere tried at up to 1000 uniform positions that keep it inside the box, rejected when it touches or
/// overlaps one already placed. Stops at the first sphere that finds no place (YADE returns the count placed so far).
/// Each call starts its own generator from `seed`, as YADE 2023's does (its output says so: a second call does not
/// continue the first).
std::vector<CloudSphere> make_cloud(const Vec3& min_corner, const Vec3& max_corner, double r_mean, double rel_fuzz,
                                    int num, std::uint32_t seed);

}  // namespace demcal::kernel::cases
