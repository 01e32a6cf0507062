// The cut-off search (kernel/cases/cutoff_search.hpp) on cases whose answer is known: a bed that flows from a set
// frequency on (per seed), so that the bracket, the majority rule over seeds, the run count and the failures at the
// ends can be checked without a simulation.
#include "kernel/cases/cutoff_search.hpp"

#include <catch2/catch.hpp>

#include <map>
#include <stdexcept>
#include <vector>

using namespace demcal::kernel::cases;

TEST_CASE("cut-off search: the bracket holds the threshold and is at most tol wide", "[kernel][cohesion][cutoff]") {
    for (double threshold : {1.0, 137.0, 250.0, 399.0}) {
        CutoffSearch s;  // [0, 400] Hz to 25 Hz, one seed
        int runs = 0;
        const CutoffResult r = find_cutoff(s, [&](double f, unsigned) {
            ++runs;
            return f >= threshold;
        });
        INFO("threshold " << threshold);
        REQUIRE(r.found);
        CHECK(r.lo < threshold);
        CHECK(r.hi >= threshold);
        CHECK(r.hi - r.lo <= s.tol);
        CHECK(runs == 2 + 4);  // both ends, then 400 -> 200 -> 100 -> 50 -> 25 Hz
    }
}

TEST_CASE("cut-off search: a frequency flows when at least half of the seeds flow there", "[kernel][cohesion][cutoff]") {
    // three seeds with thresholds 100, 200 and 300 Hz: the majority (two of three) flows from 200 Hz on
    const std::map<unsigned, double> threshold{{1, 100}, {2, 200}, {3, 300}};
    CutoffSearch s;
    s.seeds = {1, 2, 3};
    s.tol = 5;
    std::map<unsigned, int> runs_per_seed;
    const CutoffResult r = find_cutoff(s, [&](double f, unsigned seed) {
        ++runs_per_seed[seed];
        return f >= threshold.at(seed);
    });
    REQUIRE(r.found);
    CHECK(r.lo < 200);
    CHECK(r.hi >= 200);
    CHECK(runs_per_seed[1] == runs_per_seed[3]);  // every seed runs at every frequency
    // two seeds: one of two flowing is half, which counts as flowing (the lower seed's threshold wins)
    s.seeds = {1, 3};
    const CutoffResult tie = find_cutoff(s, [&](double f, unsigned seed) { return f >= threshold.at(seed); });
    REQUIRE(tie.found);
    CHECK(tie.lo < 100);
    CHECK(tie.hi >= 100);
}

TEST_CASE("cut-off search: a bed that flows at the low end or holds at the high end is reported, not bisected",
          "[kernel][cohesion][cutoff]") {
    CutoffSearch s;
    int runs = 0;
    const CutoffResult always = find_cutoff(s, [&](double, unsigned) { return ++runs, true; });
    CHECK_FALSE(always.found);
    CHECK(std::string(always.reason) == "flows at the low end of the bracket");
    CHECK(runs == 1);
    runs = 0;
    const CutoffResult never = find_cutoff(s, [&](double, unsigned) { return ++runs, false; });
    CHECK_FALSE(never.found);
    CHECK(std::string(never.reason) == "arched at the high end of the bracket");
    CHECK(runs == 2);
    s.lo = 500;
    s.hi = 100;
    CHECK_THROWS_AS(find_cutoff(s, [](double, unsigned) { return true; }), std::invalid_argument);
}

TEST_CASE("cut-off search: each seed's own bracket from the runs, and whether it meets the majority's",
          "[kernel][cohesion][cutoff]") {
    // seed 1 flows from 100 Hz, seed 2 from 300 Hz, seed 3 only at 400 Hz: the majority from 300 Hz
    const std::map<unsigned, double> threshold{{1, 100}, {2, 300}, {3, 400}};
    CutoffSearch s;
    s.seeds = {1, 2, 3};
    const CutoffResult r = find_cutoff(s, [&](double f, unsigned seed) { return f >= threshold.at(seed); });
    REQUIRE(r.found);
    CHECK(r.runs.size() == 3 * (2 + 4));  // every run recorded: both ends and four bisections, three seeds each
    const auto brackets = seed_brackets(r.runs);
    REQUIRE(brackets.size() == 3);
    CHECK(brackets[0].seed == 1);
    CHECK(*brackets[0].arched_up_to < 100);
    CHECK(*brackets[0].flows_from >= 100);
    CHECK_FALSE(overlaps(brackets[0], r.lo, r.hi));  // seed 1's cut-off lies well below the majority's
    CHECK(overlaps(brackets[1], r.lo, r.hi));        // seed 2 decides the majority
    CHECK(*brackets[2].arched_up_to >= r.hi);        // seed 3 arched at every frequency but the top
    CHECK(*brackets[2].flows_from == 400);
    for (const auto& b : brackets) CHECK_FALSE(b.inconsistent);

    // a seed that arched above a frequency at which it flowed is marked; its own bracket ends below that
    const auto odd = seed_brackets({{100, 7, false}, {200, 7, true}, {300, 7, false}, {400, 7, true}});
    REQUIRE(odd.size() == 1);
    CHECK(odd[0].inconsistent);
    CHECK(*odd[0].arched_up_to == 100);
    CHECK(*odd[0].flows_from == 200);
    // never flowed: no upper end, which overlaps any bracket above what it ran
    const auto never = seed_brackets({{0, 2, false}, {50, 2, false}});
    CHECK_FALSE(never[0].flows_from);
    CHECK(overlaps(never[0], 25, 60));
    CHECK_FALSE(overlaps(never[0], 10, 40));
}

TEST_CASE("cut-off criteria: how a run ended decides whether it flows, the same in both names",
          "[kernel][cohesion][cutoff]") {
    using demcal::kernel::silo::DischargeEnd;
    for (FlowCriterion c : {FlowCriterion::flow_stops, FlowCriterion::half_within_window}) {
        INFO(flow_criterion_name(c));
        CHECK(flows(c, DischargeEnd::stop_fraction));
        CHECK(flows(c, DischargeEnd::emptied));
        CHECK_FALSE(flows(c, DischargeEnd::flow_stopped));
        CHECK_THROWS_AS(flows(c, DischargeEnd::running), std::logic_error);
        CHECK_THROWS_AS(flows(c, DischargeEnd::suspended), std::logic_error);
    }
    // still discharging at the window's end: its flow had not stopped, but half the mass was not out
    CHECK(flows(FlowCriterion::flow_stops, DischargeEnd::time_limit));
    CHECK_FALSE(flows(FlowCriterion::half_within_window, DischargeEnd::time_limit));
    // the names a user types and reports show are the enum's, both ways
    for (const auto& [end, name] : demcal::kernel::silo::kDischargeEndNames)
        CHECK(demcal::kernel::silo::discharge_end_from_name(name) == end);
    CHECK_FALSE(demcal::kernel::silo::discharge_end_from_name("flow stopped"));
    CHECK(flow_criterion_name(FlowCriterion::flow_stops) == "flow-stops");
    // a window shorter than twice the stall time cannot see an arch by flow-stops
    CHECK_THROWS_WITH(validate_window(0.99, FlowCriterion::flow_stops), Catch::Matchers::Contains("window = 0.99 s"));
    CHECK_NOTHROW(validate_window(1, FlowCriterion::flow_stops));
    CHECK_NOTHROW(validate_window(0.3, FlowCriterion::half_within_window));
}

TEST_CASE("cut-off windows: a run still discharging at its window's end runs again in twice the window, up to the "
          "longest, with only the seeds it has not decided", "[kernel][cohesion][cutoff]") {
    using demcal::kernel::silo::DischargeEnd;
    CHECK(window_ladder(5, 20) == std::vector<double>{5, 10, 20});
    CHECK(window_ladder(5, 15) == std::vector<double>{5, 10, 15});  // the last rung cut to the longest
    CHECK(window_ladder(5, 5) == std::vector<double>{5});
    CHECK(window_ladder(5, 0) == std::vector<double>{5});
    CHECK(window_ladder(0, 20) == std::vector<double>{0});  // no endless doubling of 0
    // decided: every end but a flow still running at the window's end by flow-stops
    CHECK_FALSE(decided(FlowCriterion::flow_stops, DischargeEnd::time_limit));
    CHECK(decided(FlowCriterion::half_within_window, DischargeEnd::time_limit));
    for (DischargeEnd e : {DischargeEnd::flow_stopped, DischargeEnd::stop_fraction, DischargeEnd::emptied})
        CHECK(decided(FlowCriterion::flow_stops, e));
    CHECK_THROWS_AS(decided(FlowCriterion::flow_stops, DischargeEnd::running), std::logic_error);

    // seed 1 half out in the first window, seed 2 stops in the second, seed 3 still discharging in every window
    const std::map<unsigned, std::map<double, DischargeEnd>> end_of{
        {1, {{5, DischargeEnd::stop_fraction}}},
        {2, {{5, DischargeEnd::time_limit}, {10, DischargeEnd::flow_stopped}}},
        {3, {{5, DischargeEnd::time_limit}, {10, DischargeEnd::time_limit}, {20, DischargeEnd::time_limit}}}};
    std::vector<std::pair<double, std::vector<unsigned>>> asked;
    const auto ends = deciding_ends(FlowCriterion::flow_stops, window_ladder(5, 20), {1, 2, 3},
                                    [&](double window, const std::vector<unsigned>& seeds) {
                                        asked.emplace_back(window, seeds);
                                        std::vector<DischargeEnd> out;
                                        for (unsigned s : seeds) out.push_back(end_of.at(s).at(window));
                                        return out;
                                    });
    CHECK(ends == std::vector<DischargeEnd>{DischargeEnd::stop_fraction, DischargeEnd::flow_stopped,
                                            DischargeEnd::time_limit});
    REQUIRE(asked.size() == 3);
    CHECK(asked[0].second == std::vector<unsigned>{1, 2, 3});
    CHECK(asked[1] == std::make_pair(10.0, std::vector<unsigned>{2, 3}));
    CHECK(asked[2] == std::make_pair(20.0, std::vector<unsigned>{3}));
    // half-within-window: the window's end decides, one window only
    asked.clear();
    deciding_ends(FlowCriterion::half_within_window, window_ladder(5, 20), {2},
                  [&](double window, const std::vector<unsigned>& seeds) {
                      asked.emplace_back(window, seeds);
                      return std::vector<DischargeEnd>{DischargeEnd::time_limit};
                  });
    CHECK(asked.size() == 1);
    // an answer per seed asked, or a caller's error
    CHECK_THROWS_AS(deciding_ends(FlowCriterion::flow_stops, {5}, {1, 2},
                                  [](double, const std::vector<unsigned>&) {
                                      return std::vector<DischargeEnd>{DischargeEnd::stop_fraction};
                                  }),
                    std::logic_error);

    // the longest window: 0 (none) or between the first and kWindowMax; longer only by flow-stops
    CHECK_NOTHROW(validate_window_ladder(5, 0, FlowCriterion::half_within_window));
    CHECK_NOTHROW(validate_window_ladder(5, 60, FlowCriterion::flow_stops));
    CHECK_THROWS_WITH(validate_window_ladder(5, 4, FlowCriterion::flow_stops),
                      Catch::Matchers::Contains("max_window = 4 s"));
    CHECK_THROWS_WITH(validate_window_ladder(5, 61, FlowCriterion::flow_stops),
                      Catch::Matchers::Contains("max_window = 61 s"));
    CHECK_THROWS_WITH(validate_window_ladder(5, 10, FlowCriterion::half_within_window),
                      Catch::Matchers::Contains("half-within-window"));
}

TEST_CASE("flow stall clock: the stall counts from the last grain out, not before the vibration starts",
          "[kernel][cohesion][cutoff]") {
    using demcal::kernel::silo::FlowStallClock;
    using demcal::kernel::silo::kFlowStallTime;
    FlowStallClock still;
    CHECK_FALSE(still.stopped_at(kFlowStallTime));  // exactly the stall time: not yet
    CHECK(still.stopped_at(kFlowStallTime + 1e-9));
    still.grains_left_at(0.25);  // binary fractions: the sums below are exact
    CHECK_FALSE(still.stopped_at(0.25 + kFlowStallTime));
    CHECK(still.stopped_at(0.26 + kFlowStallTime));
    FlowStallClock late{.quiet_from = 0.6};  // a vibration from 0.6 s: a bed that let nothing out is not stopped at 0.5 s
    CHECK_FALSE(late.stopped_at(1.0));
    CHECK(late.stopped_at(1.11));
}
