// The cut-off frequency of vibration (the seed's section 3.6): the lowest frequency at which an arched bed flows,
// found by bracketing [lo, hi] and bisection down to `tol` Hz. The case is the caller's (a small cohesive hopper,
// the silo): it answers "does the bed flow at this frequency with this seed" by its own stated criterion.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "kernel/silo/discharge_end.hpp"

namespace demcal::kernel::cases {

/// What "the bed flows" means for one run, fixed before any run. Every run ends once half the mass is out, when its
/// flow stops (no grain out for silo::kFlowStallTime) or at the window's end.
enum class FlowCriterion {
  /// The seed's 3.6: an arch is a flow that stopped. Arched: the flow stopped before half the mass was out; flows
  /// otherwise, a run still discharging at the window's end included (its flow had not stopped; the search counts
  /// such runs: a longer window decides them). Does not depend on the window once no run reaches its end.
  flow_stops,
  /// Flows: half the mass out within the window (the criterion until 2026-12-06). A rate: a broken arch that drains
  /// slowly counts as arched, and the cut-off depends on the window.
  half_within_window,
};

inline constexpr std::pair<FlowCriterion, std::string_view> kFlowCriterionNames[] = {
    {FlowCriterion::flow_stops, "flow-stops"}, {FlowCriterion::half_within_window, "half-within-window"}};
std::string_view flow_criterion_name(FlowCriterion c);
/// The criterion in words, for reports.
std::string flow_criterion_text(FlowCriterion c);
/// The shortest window in which the criterion can see an arch [s]: a flow-stops run needs kFlowStallTime without a
/// grain after the opening's first grains; twice that leaves the bed as long again to arch.
double shortest_window(FlowCriterion c);
/// Throws std::invalid_argument naming the window when it is shorter than shortest_window(c).
void validate_window(double window, FlowCriterion c);

/// Whether a run that ended so flows by the criterion; a run that has not ended (running, suspended) is a caller's
/// error (std::logic_error).
bool flows(FlowCriterion c, silo::DischargeEnd end);

/// The bounds of a run's window (the small hopper's and the silo search's) [s]: a guard against typos. Up to a minute:
/// near the cut-off a broken arch drains slowly (the meal's silo at 40 deg and 50 Hz let out a third in 5 s, and a
/// run still discharging at the window's end is decided only by a longer window).
inline constexpr double kWindowMin = 0.05, kWindowMax = 60;

/// Whether the criterion has decided a run that ended so. Not decided: a run still discharging at its window's end by
/// flow-stops (its flow may yet stop: a longer window decides it); by half-within-window such a run has arched.
bool decided(FlowCriterion c, silo::DischargeEnd end);

/// The windows a run is tried in [s]: `first`, then twice the last while the run is not decided, the last one
/// `longest` (a rung above it is cut to it). longest <= first (0 included), or first <= 0: the first window only.
std::vector<double> window_ladder(double first, double longest);

/// Throws std::invalid_argument naming max_window unless it is 0 (the first window only) or first <= longest <=
/// kWindowMax, and longest == first by a criterion that a run's window end decides (half-within-window: a longer
/// window would change the criterion, not decide a run).
void validate_window_ladder(double first, double longest, FlowCriterion c);

/// Runs `seeds` in the ladder's windows in turn, each window with the seeds it has not decided yet
/// (`ends_in(window, seeds)` answers their ends in order, side by side if it can), and returns each seed's end in the
/// first window that decided it, or in the last one.
using EndsInWindow =
    std::function<std::vector<silo::DischargeEnd>(double window, const std::vector<unsigned>& seeds)>;
std::vector<silo::DischargeEnd> deciding_ends(FlowCriterion c, const std::vector<double>& ladder,
                                              const std::vector<unsigned>& seeds, const EndsInWindow& ends_in);

struct CutoffSearch {
  double lo = 0, hi = 400, tol = 25;  ///< the bracket and the final width [Hz]
  std::vector<unsigned> seeds{1};     ///< repeats: each frequency runs once per seed
  FlowCriterion criterion = FlowCriterion::flow_stops;
  /// [s] a run still discharging at its window's end (flow-stops) runs again in twice the window, up to this one
  /// (window_ladder); 0: the case's window only
  double longest_window = 0;
};

/// One run of the search: a frequency, a seed and its answer.
struct CutoffRun {
  double frequency = 0;
  unsigned seed = 0;
  bool flows = false;
};

/// What the runs of one seed say on their own: the highest frequency at which it arched below the lowest at which it
/// flowed (its own bracket), either missing when no run gave it. inconsistent: it arched at some frequency above one
/// at which it flowed (the bed's answer is not monotone in the frequency there).
struct SeedBracket {
  unsigned seed = 0;
  std::optional<double> arched_up_to, flows_from;
  bool inconsistent = false;
};

struct CutoffResult {
  bool found = false;
  double lo = 0, hi = 0;    ///< the bracket: arched at lo, flows at hi [Hz]
  const char* reason = "";  ///< when not found: which end failed
  std::vector<CutoffRun> runs;  ///< in the order run
};

/// Each seed's own bracket from the runs (in the order of first appearance). The search's bracket is the majority's:
/// where the seeds' own brackets do not overlap it, the cut-off differs from bed to bed by more than the tolerance.
std::vector<SeedBracket> seed_brackets(const std::vector<CutoffRun>& runs);

/// True when the seed's own bracket overlaps [lo, hi] (a bound it did not reach counts as open).
bool overlaps(const SeedBracket& b, double lo, double hi);

/// Bisections that halve HI - LO down to the tolerance at most: below 2^-30 of the bracket the frequencies no longer
/// differ in any digit a run could resolve, and near 2^-52 the midpoint equals an end and the search never ends.
inline constexpr int kMaxBisections = 30;

/// Throws std::invalid_argument naming the setting: 0 <= lo < hi <= 1000 Hz, 2^-kMaxBisections (hi - lo) <= tol <
/// hi - lo, a seed at least.
void validate(const CutoffSearch& s);

/// A frequency flows when at least half of the seeds flow there (a majority; a tie counts as flowing).
/// `flows(frequency, seed)` runs the case once.
CutoffResult find_cutoff(const CutoffSearch& s, const std::function<bool(double frequency, unsigned seed)>& flows);

/// The same search with every seed of a frequency asked at once (`flows_at(frequency, seeds)` answers in the seeds'
/// order), so that a caller can run them side by side.
using FlowsAtFrequency = std::function<std::vector<bool>(double frequency, const std::vector<unsigned>& seeds)>;
CutoffResult find_cutoff_batched(const CutoffSearch& s, const FlowsAtFrequency& flows_at);

}  // namespace demcal::kernel::cases
