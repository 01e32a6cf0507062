#include "kernel/silo/flow_pattern.hpp"

#include <cmath>
#include <sstream>

namespace demcal::kernel::silo {

std::string to_string(FlowPattern p) {
    switch (p) {
        case FlowPattern::mass: return "mass";
        case FlowPattern::mixed: return "mixed";
        case FlowPattern::funnel: return "funnel";
        default: return "undetermined";
    }
}

bool gathers_frame(double fraction_out, double steady_lower, double steady_upper) {
    return fraction_out >= steady_lower * 0.5 && fraction_out <= steady_upper;
}

FlowPatternClassifier::FlowPatternClassifier(const SiloGeometry& g, FlowPatternSettings s) : g_(g), s_(s) {}

void FlowPatternClassifier::add_frame(const std::vector<Eigen::Vector3d>& pos, const std::vector<Eigen::Vector3d>& vel,
                                      double tag) {
    const double hh = g_.hopper_height();
    const int nb = std::max(1, int(std::ceil(hh / s_.bin_height)));
    const double th = g_.half_angle_deg * 3.14159265358979323846 / 180;
    Frame f;
    f.tag = tag;
    f.bins.resize(nb);
    for (size_t i = 0; i < pos.size(); ++i) {
        const Eigen::Vector3d& p = pos[i];
        const double z = p.z();
        if (z <= 0 || z >= hh) continue;
        const int b = std::min(nb - 1, int(z / s_.bin_height));
        const double half = g_.half_size_at(z), s = g_.transverse(p);
        const double down = -vel[i].z();
        // distance to the slanted wall, perpendicular to it, and the distance along the wall from the outlet edge
        const double wall_dist = (half - s) * std::cos(th);
        const double along = z / std::cos(th);
        if (wall_dist >= 0 && wall_dist <= s_.wall_layer && along >= s_.edge_clearance) {
            f.bins[b].wall_sum += down;
            ++f.bins[b].wall_n;
        } else if (s <= std::max(s_.axis_fraction * half, s_.axis_min)) {
            f.bins[b].axis_sum += down;
            ++f.bins[b].axis_n;
        }
    }
    frames_.push_back(std::move(f));
}

FlowPatternResult FlowPatternClassifier::result(double tag_low, double tag_high) const {
    FlowPatternResult r;
    std::ostringstream m;
    m << "ratio of the mean downward velocity of the grains within " << s_.wall_layer * 1e3
      << " mm of the hopper wall (at least " << s_.edge_clearance * 1e3
      << " mm from the outlet edge along the wall) to that of the grains near the axis (r < "
      << s_.axis_fraction << " of the local half size) at the same height (bins of " << s_.bin_height * 1e3
      << " mm), over the steady discharge; mass flow >= " << s_.mass_threshold << ", funnel flow < "
      << s_.funnel_threshold << ", mixed in between";
    r.measure = m.str();
    double ratio_sum = 0, wall_sum = 0, axis_sum = 0;
    long used = 0;
    for (const auto& f : frames_) {
        if (f.tag < tag_low || f.tag > tag_high) continue;
        ++r.frames;
        for (const auto& b : f.bins) {
            if (b.wall_n == 0 || b.axis_n == 0) continue;
            const double axis = b.axis_sum / b.axis_n;
            if (axis < s_.min_axis_speed) continue;
            ratio_sum += b.wall_sum / axis;  // sum over the bin's wall samples of v_wall / v_axis
            wall_sum += b.wall_sum;
            axis_sum += axis * b.wall_n;
            used += b.wall_n;
            r.axis_samples += b.axis_n;
        }
    }
    r.wall_samples = used;
    if (used == 0) {
        r.message = r.frames == 0 ? "no frame of the steady discharge was sampled"
                                    : "no hopper height had both wall grains and moving axis grains";
        return r;
    }
    r.ratio = ratio_sum / used;
    r.wall_speed = wall_sum / used;
    r.axis_speed = axis_sum / used;
    r.pattern = r.ratio >= s_.mass_threshold    ? FlowPattern::mass
                : r.ratio < s_.funnel_threshold ? FlowPattern::funnel
                                                : FlowPattern::mixed;
    return r;
}

}  // namespace demcal::kernel::silo

namespace demcal::kernel::silo {

void FlowPatternClassifier::save(StateWriter& w) const {
    w.value(std::uint64_t(frames_.size()));
    for (const Frame& f : frames_) {
        w.value(f.tag);
        w.array(f.bins);
    }
}

void FlowPatternClassifier::load(StateReader& r) {
    const auto n = r.value<std::uint64_t>("flow-pattern frames");
    if (n > 100000000) r.fail("flow-pattern frames", "implausible count " + std::to_string(n));
    frames_.assign(n, Frame{});
    for (Frame& f : frames_) {
        r.value(f.tag, "flow-pattern frame");
        r.array(f.bins, "flow-pattern bins");
    }
}

}  // namespace demcal::kernel::silo
