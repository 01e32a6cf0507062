// Flow-pattern frames of a silo discharge run by another code (yade_scripts/silo.py writes them), read into the
// kernel's FlowPatternClassifier: the flow pattern of both codes is measured by one classifier, not by two copies.
//
// File "demcal.silo_frames/1" (little-endian): the line "demcal.silo_frames/1\n", then per frame: float64 time [s],
// float64 discharged mass [kg], uint32 grain count n, then n x 4 float32: x, y, z [m] of the grain's centre of mass
// and its vertical velocity vz [m/s] (the classifier uses no other component). The writer may leave out grains outside
// the hopper (0 < z < hopper height): the classifier ignores them.
#pragma once
#include "kernel/silo/flow_pattern.hpp"

#include <filesystem>

namespace demcal::kernel::silo {

inline constexpr const char* kFlowFramesSchema = "demcal.silo_frames/1";

struct FlowFramesRead {
    long frames_in_file = 0;  // every frame of the file
    long frames_gathered = 0;  // those the kernel's rule gathers (gathers_frame)
};

// Adds to `classifier` every frame of `file` that the kernel would have gathered (gathers_frame of the discharged
// fraction of `filled_mass`). Throws std::invalid_argument naming the file and what is wrong (not this format,
// truncated, a count larger than the file, a value not finite, a discharged mass outside [0, filled_mass], time
// running backwards); nothing is added to the classifier then.
FlowFramesRead read_flow_frames(const std::filesystem::path& file, double filled_mass, double steady_lower,
                                double steady_upper, FlowPatternClassifier& classifier);

}  // namespace demcal::kernel::silo
