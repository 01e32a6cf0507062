// The cut-off search (kernel/cases/cutoff_search.hpp) on cases whose answer is known: a bed that flows from a set
// frequency on (per seed), so that the bracket, the majority rule over seeds, the run count and the failures at the
// ends can be checked without a simulation.
#include "kernel/cases/cutoff_search.hpp"

#include <catch2/catch.hpp>

#include <map>
#include <stdexcept>

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
