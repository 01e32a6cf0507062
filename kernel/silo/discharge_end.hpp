// How a discharge run ended, and the rule that says its flow stopped: shared by the silo case and the small cohesive
// hopper (kernel/cases/cohesive_hopper.hpp), so that "the flow stopped" means one thing in both, and a cut-off search
// (kernel/cases/cutoff_search.hpp) reads the end as a state, not as the text of a stop reason.
#pragma once
#include <algorithm>
#include <optional>
#include <string_view>
#include <utility>

namespace demcal::kernel::silo {

enum class DischargeEnd {
    running,        // not ended (a result of a suspended session carries `suspended`)
    emptied,        // no grain left in the bin
    stop_fraction,  // the asked fraction of the filled mass is out
    flow_stopped,   // no grain out for kFlowStallTime with grains left: an arch stands (the seed's 3.6)
    time_limit,     // the run's simulated time limit, grains still leaving
    suspended,      // the session's wall limit or a stop request: resumed from its checkpoint
};

inline constexpr std::pair<DischargeEnd, std::string_view> kDischargeEndNames[] = {
    {DischargeEnd::running, "running"},         {DischargeEnd::emptied, "emptied"},
    {DischargeEnd::stop_fraction, "stop_fraction"}, {DischargeEnd::flow_stopped, "flow_stopped"},
    {DischargeEnd::time_limit, "time_limit"},   {DischargeEnd::suspended, "suspended"}};

inline std::string_view discharge_end_name(DischargeEnd e) {
    for (const auto& [end, name] : kDischargeEndNames)
        if (end == e) return name;
    return "?";
}

inline std::optional<DischargeEnd> discharge_end_from_name(std::string_view text) {
    for (const auto& [end, name] : kDischargeEndNames)
        if (name == text) return end;
    return std::nullopt;
}

/// No grain out for this long, with grains left, is a flow that has stopped [s]. A free outlet of the silo cases lets
/// hundreds of grains a second through; 0.5 s without one is no slow flow but a standing arch.
inline constexpr double kFlowStallTime = 0.5;

/// The stall rule's clock, in time since the opening: the stall counts from the last grain out, and not before
/// `quiet_from` (a bin whose vibration starts later has not had its chance yet).
struct FlowStallClock {
    double quiet_from = 0;
    double last_out = 0;
    void grains_left_at(double t) { last_out = t; }
    bool stopped_at(double t) const { return t - std::max(last_out, quiet_from) > kFlowStallTime; }
};

}  // namespace demcal::kernel::silo
