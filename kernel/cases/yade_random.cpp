#include "kernel/cases/yade_random.hpp"

#include <cmath>

namespace demcal::kernel::cases {

namespace {
constexpr int kStateWords = 624;

std::vector<std::uint32_t> python_seed_key(std::uint64_t seed) {
  // CPython's random_seed: the absolute value split into 32-bit words, least significant first; 0 is one word 0
  std::vector<std::uint32_t> key;
  do {
    key.push_back(std::uint32_t(seed & 0xffffffffu));
    seed >>= 32;
  } while (seed != 0);
  return key;
}
}  // namespace

Mt19937::Mt19937(std::uint32_t seed) {
  mt_[0] = seed;
  for (int i = 1; i < kStateWords; ++i) mt_[i] = 1812433253u * (mt_[i - 1] ^ (mt_[i - 1] >> 30)) + std::uint32_t(i);
}

Mt19937::Mt19937(const std::vector<std::uint32_t>& key) : Mt19937(19650218u) {
  int i = 1, j = 0;
  const int len = int(key.size());
  for (int k = kStateWords > len ? kStateWords : len; k > 0; --k) {
    mt_[i] = (mt_[i] ^ ((mt_[i - 1] ^ (mt_[i - 1] >> 30)) * 1664525u)) + key[j] + std::uint32_t(j);
    ++i;
    ++j;
    if (i >= kStateWords) {
      mt_[0] = mt_[kStateWords - 1];
      i = 1;
    }
    if (j >= len) j = 0;
  }
  for (int k = kStateWords - 1; k > 0; --k) {
    mt_[i] = (mt_[i] ^ ((mt_[i - 1] ^ (mt_[i - 1] >> 30)) * 1566083941u)) - std::uint32_t(i);
    ++i;
    if (i >= kStateWords) {
      mt_[0] = mt_[kStateWords - 1];
      i = 1;
    }
  }
  mt_[0] = 0x80000000u;
}

void Mt19937::reload() {
  constexpr int m = 397;
  constexpr std::uint32_t upper = 0x80000000u, lower = 0x7fffffffu, matrix = 0x9908b0dfu;
  for (int k = 0; k < kStateWords; ++k) {
    const std::uint32_t y = (mt_[k] & upper) | (mt_[(k + 1) % kStateWords] & lower);
    mt_[k] = mt_[(k + m) % kStateWords] ^ (y >> 1) ^ ((y & 1u) ? matrix : 0u);
  }
  index_ = 0;
}

std::uint32_t Mt19937::operator()() {
  if (index_ >= kStateWords) reload();
  std::uint32_t y = mt_[index_++];
  y ^= y >> 11;
  y ^= (y << 7) & 0x9d2c5680u;
  y ^= (y << 15) & 0xefc60000u;
  y ^= y >> 18;
  return y;
}

double CloudRandom::operator()() {
  // Boost's generate_canonical_impl for 53 bits from 32-bit words: S = w1 + w2 R, R = 2^32, S / R^2 (and a result
  // that rounded up to 1 is moved just below it)
  constexpr double R = 4294967296.0;
  double s = double(mt_());
  double mult = R;
  while (mult < 9007199254740992.0) {  // 2^53
    s += double(mt_()) * mult;
    mult *= R;
  }
  double result = s / mult;
  if (result == 1.0) result -= 0.5 * 2.220446049250313e-16;
  return result;
}

PythonRandom::PythonRandom(std::uint64_t seed) : mt_(python_seed_key(seed)) {}

double PythonRandom::random() {
  const std::uint32_t a = mt_() >> 5, b = mt_() >> 6;
  return (double(a) * 67108864.0 + double(b)) * (1.0 / 9007199254740992.0);
}

std::vector<CloudSphere> make_cloud(const Vec3& min_corner, const Vec3& max_corner, double r_mean, double rel_fuzz,
                                    int num, std::uint32_t seed) {
  constexpr int kMaxTries = 1000;  // YADE's maxTry
  CloudRandom rnd(seed);
  const Vec3 size = max_corner - min_corner;
  std::vector<CloudSphere> pack;
  for (int i = 0; i < num; ++i) {
    const double u = (double(num) - double(i) + 0.5) / (double(num) + 1.0);
    const double r = r_mean * (2 * (u - 0.5) * rel_fuzz + 1);
    bool placed = false;
    for (int t = 0; t < kMaxTries && !placed; ++t) {
      Vec3 c;
      // (this grouping is what YADE's output says it computes: mn + (r + (size - 2 r) u), not (mn + r) + ...)
      for (int axis = 0; axis < 3; ++axis) c[axis] = min_corner[axis] + (r + (size[axis] - 2 * r) * rnd());
      bool overlap = false;
      for (const CloudSphere& s : pack) {
        const double reach = s.radius + r;
        if (reach * reach >= (s.centre - c).squaredNorm()) {
          overlap = true;
          break;
        }
      }
      if (!overlap) {
        pack.push_back({c, r});
        placed = true;
      }
    }
    if (!placed) break;
  }
  return pack;
}

}  // namespace demcal::kernel::cases
