#include "kernel/cases/cutoff_search.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kernel/silo/input_error.hpp"

namespace demcal::kernel::cases {

void validate(const CutoffSearch& s) {
  if (!(s.lo >= 0 && s.lo < s.hi && s.hi <= 1000))
    throw std::invalid_argument("bracket = [" + silo::setting_text(s.lo) + ", " + silo::setting_text(s.hi) +
                                "]: needs 0 <= LO < HI <= 1000 Hz");
  if (!(s.tol > 0 && s.tol < s.hi - s.lo))
    throw std::invalid_argument("tol = " + silo::setting_text(s.tol) + ": must be > 0 and below HI - LO");
  if (s.tol < std::ldexp(s.hi - s.lo, -kMaxBisections))
    throw std::invalid_argument("tol = " + silo::setting_text(s.tol) + ": finer than 2^-" +
                                std::to_string(kMaxBisections) + " of the bracket: the bisection would not end");
  if (s.seeds.empty()) throw std::invalid_argument("seeds: give at least one");
}

CutoffResult find_cutoff(const CutoffSearch& s, const std::function<bool(double, unsigned)>& flows) {
  validate(s);
  auto flows_at = [&](double f) {
    std::size_t flowing = 0;
    for (unsigned seed : s.seeds) flowing += flows(f, seed);
    return 2 * flowing >= s.seeds.size();
  };
  CutoffResult r;
  double lo = s.lo, hi = s.hi;
  if (flows_at(lo)) { r.reason = "flows at the low end of the bracket"; return r; }
  if (!flows_at(hi)) { r.reason = "arched at the high end of the bracket"; return r; }
  while (hi - lo > s.tol) {
    const double mid = 0.5 * (lo + hi);
    (flows_at(mid) ? hi : lo) = mid;
  }
  r.found = true;
  r.lo = lo;
  r.hi = hi;
  return r;
}

}  // namespace demcal::kernel::cases
