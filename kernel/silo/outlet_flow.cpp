#include "kernel/silo/outlet_flow.hpp"

#include <cmath>
#include <cstdint>
#include <string>

namespace demcal::kernel::silo {

OutletFlowMeter::OutletFlowMeter(const SiloGeometry& g, double grain_mass)
    : g_(g), grain_mass_(grain_mass), zone_height_(g.outlet_half()),
      outlet_area_(g.shape == SiloShape::conical ? 3.14159265358979323846 * g.outlet_half() * g.outlet_half()
                                                 : g.outlet * g.depth) {}

bool OutletFlowMeter::in_zone(const Eigen::Vector3d& p) const {
    if (!(p.z() >= 0 && p.z() < zone_height_)) return false;
    const double h = g_.outlet_half();
    if (g_.shape == SiloShape::conical) return p.x() * p.x() + p.y() * p.y() < h * h;
    return std::abs(p.x()) < h && std::abs(p.y()) < 0.5 * g_.depth;
}

void OutletFlowMeter::add_frame(const std::vector<Eigen::Vector3d>& pos, const std::vector<Eigen::Vector3d>& vel,
                                double tag) {
    Frame f;
    f.tag = tag;
    for (size_t i = 0; i < pos.size(); ++i)
        if (in_zone(pos[i])) {
            f.grains += 1;
            f.downward_sum -= vel[i].z();
        }
    frames_.push_back(f);
}

OutletFlowResult OutletFlowMeter::result(double tag_low, double tag_high) const {
    OutletFlowResult r;
    r.zone_height = zone_height_;
    r.zone_volume = outlet_area_ * zone_height_;
    double grains = 0, downward = 0;
    for (const Frame& f : frames_)
        if (f.tag >= tag_low && f.tag <= tag_high) {
            ++r.frames;
            grains += f.grains;
            downward += f.downward_sum;
        }
    if (r.frames == 0) return r;
    r.mean_grains = grains / double(r.frames);
    r.solid_density = r.mean_grains * grain_mass_ / r.zone_volume;
    r.downward_speed = grains > 0 ? downward / grains : 0;
    r.flux_rate = r.solid_density * r.downward_speed * outlet_area_;
    return r;
}

void OutletFlowMeter::save(StateWriter& w) const { w.array(frames_); }

void OutletFlowMeter::load(StateReader& r) {
    r.array(frames_, "outlet-flow frames");
    for (const Frame& f : frames_)
        if (!(f.grains >= 0 && std::isfinite(f.grains) && std::isfinite(f.downward_sum) && std::isfinite(f.tag)))
            r.fail("outlet-flow frames", "a frame that is no count of grains");
}

}  // namespace demcal::kernel::silo
