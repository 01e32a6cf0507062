#include "app/silo_flow_pattern.hpp"

#include "kernel/silo/flow_frames.hpp"

#include <cmath>
#include <stdexcept>

namespace demcal {

namespace ks = kernel::silo;
using json = nlohmann::json;

json flow_pattern_json(const ks::FlowPatternResult& r) {
    json j = {{"pattern", ks::to_string(r.pattern)},
              {"wall_to_axis_velocity_ratio", r.ratio},
              {"wall_speed_m_s", r.wall_speed},
              {"axis_speed_m_s", r.axis_speed},
              {"wall_samples", r.wall_samples},
              {"frames", r.frames},
              {"measure", r.measure}};
    if (!r.message.empty()) j["message"] = r.message;
    return j;
}

namespace {

// Every field once: its JSON key and where it lives in FlowPatternSampling.
struct SamplingField {
    const char* key;
    double FlowPatternSampling::*top = nullptr;
    double ks::FlowPatternSettings::*classifier = nullptr;
};
const SamplingField kSamplingFields[] = {
    {"frame_interval_s", &FlowPatternSampling::frame_interval},
    {"steady_lower", &FlowPatternSampling::steady_lower},
    {"steady_upper", &FlowPatternSampling::steady_upper},
    {"wall_layer_m", nullptr, &ks::FlowPatternSettings::wall_layer},
    {"edge_clearance_m", nullptr, &ks::FlowPatternSettings::edge_clearance},
    {"axis_fraction", nullptr, &ks::FlowPatternSettings::axis_fraction},
    {"axis_min_m", nullptr, &ks::FlowPatternSettings::axis_min},
    {"bin_height_m", nullptr, &ks::FlowPatternSettings::bin_height},
    {"min_axis_speed_m_s", nullptr, &ks::FlowPatternSettings::min_axis_speed},
    {"mass_threshold", nullptr, &ks::FlowPatternSettings::mass_threshold},
    {"funnel_threshold", nullptr, &ks::FlowPatternSettings::funnel_threshold},
};

}  // namespace

json flow_pattern_sampling_json(const ks::SiloCaseSettings& s) {
    FlowPatternSampling sampling{s.flow, s.frame_interval, s.steady_lower, s.steady_upper};
    json j = json::object();
    for (const auto& f : kSamplingFields) j[f.key] = f.top ? sampling.*f.top : sampling.classifier.*f.classifier;
    return j;
}

FlowPatternSampling flow_pattern_sampling_from_json(const json& j, const std::string& where) {
    if (!j.is_object()) throw std::invalid_argument(where + ": flow_pattern_sampling must be an object");
    FlowPatternSampling s;
    for (const auto& f : kSamplingFields) {
        const auto it = j.find(f.key);
        if (it == j.end() || !it->is_number() || !std::isfinite(it->get<double>()) || it->get<double>() < 0)
            throw std::invalid_argument(where + ": flow_pattern_sampling." + f.key +
                                        " is missing or not a finite number >= 0");
        (f.top ? s.*f.top : s.classifier.*f.classifier) = it->get<double>();
    }
    if (!(s.frame_interval > 0) || !(s.steady_lower < s.steady_upper) || s.steady_upper > 1)
        throw std::invalid_argument(where + ": flow_pattern_sampling needs frame_interval_s > 0 and "
                                            "steady_lower < steady_upper <= 1");
    return s;
}

ks::FlowPatternResult flow_pattern_of_frames(const std::filesystem::path& frames, const ks::SiloGeometry& geometry,
                                             const FlowPatternSampling& sampling, double filled_mass,
                                             double discharged_mass) {
    ks::FlowPatternClassifier classifier(geometry, sampling.classifier);
    ks::read_flow_frames(frames, filled_mass, sampling.steady_lower, sampling.steady_upper, classifier);
    return classifier.result(sampling.steady_lower * discharged_mass, sampling.steady_upper * discharged_mass);
}

}  // namespace demcal
