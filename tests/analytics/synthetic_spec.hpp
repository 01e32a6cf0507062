// The synthetic measured set the diagnosis tests draw (analytics/diagnose_synthetic.hpp), in one call.
#pragma once
#include <cstdint>
#include <string>

#include "analytics/diagnose_synthetic.hpp"

namespace demcal::analytics::test {

inline SyntheticSpec spec(const std::string& model, const std::string& effect, double size, std::uint64_t seed,
                          double noise = 0.03, int replicates = 2) {
  SyntheticSpec s;
  s.model = model;
  s.effect = effect;
  s.effect_size = size;
  s.seed = seed;
  s.noise = noise;
  s.replicates = replicates;
  return s;
}

}  // namespace demcal::analytics::test
