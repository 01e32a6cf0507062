// The silo case's ContactsAtOpening switch (demcal silo --forget-contact-history, --start-as-yade-import): the
// contacts' memory is forgotten at the opening and only then, as in a bed another code imports (and with
// yade_import the discharge starts as YADE's leapfrog does); the run resumes from checkpoints bit for bit, the choice
// stored in them. That yade_import follows YADE's own run of the bed: test_silo_yade_trajectory.cpp.
#include "kernel/silo/silo_case.hpp"
#include "silo_resume_check.hpp"

#include "tiny_silo.hpp"

#include <catch2/catch.hpp>

using namespace demcal::kernel::silo;

namespace {

SiloCaseSettings tiny_case() { return demcal::test::tiny_silo_case(); }

}  // namespace

TEST_CASE("silo case: forgetting the contact history at the opening leaves the filling and changes the discharge",
          "[silo]") {
    SiloCaseSettings s = tiny_case();
    const SiloCaseResult kept = run_silo_case(s);
    s.contacts_at_opening = ContactsAtOpening::forget_history;
    const SiloCaseResult forgotten = run_silo_case(s);
    // the same filled bed (the switch acts at the opening), and then the grains move otherwise
    demcal::test::check_same_fill_other_discharge(forgotten, kept);
    CHECK(forgotten.grains_discharged > 0);
}

TEST_CASE("silo case: a run forgetting its contact history at the opening resumes bit for bit",
          "[silo][checkpoint]") {
    SiloCaseSettings s = tiny_case();
    s.contacts_at_opening = ContactsAtOpening::forget_history;
    // killed while filling (before the opening: the resumed session must still forget), then after it
    const SiloCaseSettings stored = demcal::test::check_resumes_bit_for_bit(s, "forget-history", 0.05);
    CHECK(stored.contacts_at_opening == ContactsAtOpening::forget_history);
}

TEST_CASE("silo case: starting the discharge as YADE's import leaves the filling and the rate", "[silo]") {
    demcal::test::check_discharge_switch_keeps_rate(
        tiny_case(), [](SiloCaseSettings& s) { s.contacts_at_opening = ContactsAtOpening::yade_import; }, 0.15);
}

TEST_CASE("silo case: a run started as YADE's import resumes bit for bit", "[silo][checkpoint]") {
    SiloCaseSettings s = tiny_case();
    s.contacts_at_opening = ContactsAtOpening::yade_import;
    // killed while filling: the resumed session opens and starts as YADE's import itself
    const SiloCaseSettings stored = demcal::test::check_resumes_bit_for_bit(s, "yade-import", 0.05);
    CHECK(stored.contacts_at_opening == ContactsAtOpening::yade_import);
}

TEST_CASE("silo case: a contacts-at-opening value that is not a choice is refused by name", "[silo]") {
    SiloCaseSettings s = tiny_case();
    s.contacts_at_opening = static_cast<ContactsAtOpening>(7);
    CHECK_THROWS_WITH(validate(s), Catch::Contains("contacts_at_opening") && Catch::Contains("7"));
}
