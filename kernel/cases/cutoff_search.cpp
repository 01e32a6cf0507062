#include "kernel/cases/cutoff_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "kernel/silo/input_error.hpp"

namespace demcal::kernel::cases {

std::string_view flow_criterion_name(FlowCriterion c) {
  for (const auto& [criterion, name] : kFlowCriterionNames)
    if (criterion == c) return name;
  return "?";
}

std::string flow_criterion_text(FlowCriterion c) {
  return c == FlowCriterion::flow_stops
             ? "arched: the flow stopped (no grain out for " + silo::setting_text(silo::kFlowStallTime) +
                   " s) before half of the mass was out; flows otherwise (half the mass out, or still "
                   "discharging at the window's end)"
             : "flows: at least half of the mass out within window_s of the opening";
}

double shortest_window(FlowCriterion c) { return c == FlowCriterion::flow_stops ? 2 * silo::kFlowStallTime : 0.05; }

void validate_window(double window, FlowCriterion c) {
  if (!(window >= shortest_window(c)))
    throw std::invalid_argument("window = " + silo::setting_text(window) + " s: shorter than " +
                                silo::setting_text(shortest_window(c)) + " s, in which the criterion " +
                                std::string(flow_criterion_name(c)) + " can see an arch");
}

bool flows(FlowCriterion c, silo::DischargeEnd end) {
  using silo::DischargeEnd;
  switch (end) {
    case DischargeEnd::emptied:
    case DischargeEnd::stop_fraction: return true;
    case DischargeEnd::flow_stopped: return false;
    case DischargeEnd::time_limit: return c == FlowCriterion::flow_stops;
    case DischargeEnd::running:
    case DischargeEnd::suspended: break;
  }
  throw std::logic_error("flows: a run that has not ended (" + std::string(silo::discharge_end_name(end)) + ")");
}

bool decided(FlowCriterion c, silo::DischargeEnd end) {
  (void)flows(c, end);  // a run that has not ended is a caller's error here too
  return !(c == FlowCriterion::flow_stops && end == silo::DischargeEnd::time_limit);
}

std::vector<double> window_ladder(double first, double longest) {
  std::vector<double> ladder{first};
  if (!(first > 0)) return ladder;  // (doubling 0 never reaches the longest)
  while (ladder.back() < longest) ladder.push_back(std::min(2 * ladder.back(), longest));
  return ladder;
}

void validate_window_ladder(double first, double longest, FlowCriterion c) {
  if (longest == 0) return;  // the first window only
  const std::string shown = "max_window = " + silo::setting_text(longest) + " s";
  if (!(longest >= first && longest <= kWindowMax))
    throw std::invalid_argument(shown + ": must be in [window, " + silo::setting_text(kWindowMax) + "] s (window " +
                                silo::setting_text(first) + " s)");
  if (c != FlowCriterion::flow_stops && longest != first)
    throw std::invalid_argument(shown + ": a longer window decides runs by flow-stops only; by " +
                                std::string(flow_criterion_name(c)) + " the window is part of the criterion");
}

std::vector<silo::DischargeEnd> deciding_ends(FlowCriterion c, const std::vector<double>& ladder,
                                              const std::vector<unsigned>& seeds, const EndsInWindow& ends_in) {
  std::vector<silo::DischargeEnd> ends(seeds.size(), silo::DischargeEnd::running);
  std::vector<std::size_t> open(seeds.size());  // indices of the seeds not decided yet
  for (std::size_t k = 0; k < seeds.size(); ++k) open[k] = k;
  for (double window : ladder) {
    if (open.empty()) break;
    std::vector<unsigned> batch;
    for (std::size_t k : open) batch.push_back(seeds[k]);
    const std::vector<silo::DischargeEnd> got = ends_in(window, batch);
    if (got.size() != batch.size())
      throw std::logic_error("deciding_ends: " + std::to_string(got.size()) + " ends for " +
                             std::to_string(batch.size()) + " seeds");
    std::vector<std::size_t> still_open;
    for (std::size_t i = 0; i < open.size(); ++i) {
      ends[open[i]] = got[i];
      if (!decided(c, got[i])) still_open.push_back(open[i]);
    }
    open = std::move(still_open);
  }
  return ends;
}

void validate(const CutoffSearch& s) {
  if (!(s.lo >= 0 && s.lo < s.hi && s.hi <= 1000))
    throw std::invalid_argument("bracket = [" + silo::setting_text(s.lo) + ", " + silo::setting_text(s.hi) +
                                "]: needs 0 <= LO < HI <= 1000 Hz");
  if (!(s.tol > 0 && s.tol < s.hi - s.lo))
    throw std::invalid_argument("tol = " + silo::setting_text(s.tol) + " Hz: must be > 0 and below the bracket's width (" +
                                silo::setting_text(s.hi - s.lo) + " Hz for bracket " + silo::setting_text(s.lo) + "," +
                                silo::setting_text(s.hi) + ")");
  if (s.tol < std::ldexp(s.hi - s.lo, -kMaxBisections))
    throw std::invalid_argument("tol = " + silo::setting_text(s.tol) + ": finer than 2^-" +
                                std::to_string(kMaxBisections) + " of the bracket: the bisection would not end");
  if (s.seeds.empty()) throw std::invalid_argument("seeds: give at least one");
}

CutoffResult find_cutoff(const CutoffSearch& s, const std::function<bool(double, unsigned)>& flows) {
  return find_cutoff_batched(s, [&](double f, const std::vector<unsigned>& seeds) {
    std::vector<bool> answers;
    for (unsigned seed : seeds) answers.push_back(flows(f, seed));
    return answers;
  });
}

CutoffResult find_cutoff_batched(const CutoffSearch& s, const FlowsAtFrequency& flows) {
  validate(s);
  CutoffResult r;
  auto flows_at = [&](double f) {
    const std::vector<bool> answers = flows(f, s.seeds);
    if (answers.size() != s.seeds.size())
      throw std::logic_error("find_cutoff_batched: " + std::to_string(answers.size()) + " answers for " +
                             std::to_string(s.seeds.size()) + " seeds");
    std::size_t flowing = 0;
    for (std::size_t k = 0; k < answers.size(); ++k) {
      r.runs.push_back({f, s.seeds[k], answers[k]});
      flowing += answers[k];
    }
    return 2 * flowing >= s.seeds.size();
  };
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

std::vector<SeedBracket> seed_brackets(const std::vector<CutoffRun>& runs) {
  std::vector<SeedBracket> out;
  for (const CutoffRun& run : runs) {
    auto it = std::find_if(out.begin(), out.end(), [&](const SeedBracket& b) { return b.seed == run.seed; });
    if (it == out.end()) it = out.insert(out.end(), SeedBracket{run.seed, std::nullopt, std::nullopt, false});
    if (run.flows && (!it->flows_from || run.frequency < *it->flows_from)) it->flows_from = run.frequency;
  }
  for (SeedBracket& b : out)
    for (const CutoffRun& run : runs) {
      if (run.seed != b.seed || run.flows) continue;
      if (b.flows_from && run.frequency > *b.flows_from) {
        b.inconsistent = true;
        continue;
      }
      if (!b.arched_up_to || run.frequency > *b.arched_up_to) b.arched_up_to = run.frequency;
    }
  return out;
}

bool overlaps(const SeedBracket& b, double lo, double hi) {
  const double own_lo = b.arched_up_to.value_or(-std::numeric_limits<double>::infinity());
  const double own_hi = b.flows_from.value_or(std::numeric_limits<double>::infinity());
  return own_lo < hi && own_hi > lo;
}

}  // namespace demcal::kernel::cases
