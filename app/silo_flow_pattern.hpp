// The silo's flow pattern as JSON (summary.json of `demcal silo`, the cross-check's report), and the kernel's flow
// pattern sampling carried in the bed file so another code's frames are sampled and classified as the kernel's are.
#pragma once
#include "kernel/silo/silo_case.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace demcal {

/// The measure's result: pattern, wall-to-axis velocity ratio, speeds, samples, frames, the measure in words.
nlohmann::json flow_pattern_json(const kernel::silo::FlowPatternResult& r);

/// How the kernel gathered and classified its frames: frame interval, the steady window, the classifier's settings.
struct FlowPatternSampling {
    kernel::silo::FlowPatternSettings classifier;
    double frame_interval = 0, steady_lower = 0, steady_upper = 0;
};
nlohmann::json flow_pattern_sampling_json(const kernel::silo::SiloCaseSettings& s);
/// Reads flow_pattern_sampling_json's block back; throws std::invalid_argument naming `where` and the field.
FlowPatternSampling flow_pattern_sampling_from_json(const nlohmann::json& j, const std::string& where);

/// The flow pattern of another code's discharge from its frames file (kernel/silo/flow_frames.hpp), by the kernel's
/// classifier with the kernel's sampling: `filled_mass` the bed's mass, `discharged_mass` the mass out at the end.
kernel::silo::FlowPatternResult flow_pattern_of_frames(const std::filesystem::path& frames,
                                                       const kernel::silo::SiloGeometry& geometry,
                                                       const FlowPatternSampling& sampling, double filled_mass,
                                                       double discharged_mass);

}  // namespace demcal
