// The flow at the outlet, split into how densely and how fast the grains pass it: a discharge rate W = rho v A
// changes with the packing of the grains about to leave (rho) and with their speed (v), and a rate alone does not say
// which (a shaken bin may speed the grains up and still discharge less, by loosening them).
//
// Zone: the grains whose centre lies above the opening (r < d/2 for a cone, |x| < a/2 for a slot) and below half the
// outlet size (0 <= z < d/2, a/2): the free-fall arch region, whose height is about half the span (Beverloo's and
// Hagen's picture). Per frame the zone's grain count and their vertical velocities; over the steady window (frames
// tagged by the discharged mass, as the flow-pattern classifier's) the mean solid density (grain mass per zone
// volume), the mean downward velocity of the zone's grains, and their product with the outlet area, rho v A. rho v A
// is a flux estimate, not the rate (density and velocity vary inside the zone): compare it between runs of one
// geometry, where d(ln W) = d(ln rho) + d(ln v) splits a change of the rate.
#pragma once
#include "kernel/silo/silo_geometry.hpp"
#include "kernel/state_io.hpp"

#include <Eigen/Core>

#include <vector>

namespace demcal::kernel::silo {

struct OutletFlowResult {
    long frames = 0;                 // frames in the window
    double zone_height = 0;          // [m]
    double zone_volume = 0;          // [m^3]
    double mean_grains = 0;          // grain centres in the zone per frame
    double solid_density = 0;        // grain mass per zone volume [kg/m^3]
    double downward_speed = 0;       // mean -vz of the zone's grains [m/s] (0 when no grain was seen)
    double flux_rate = 0;            // solid_density x downward_speed x outlet area [kg/s]
};

class OutletFlowMeter {
public:
    OutletFlowMeter(const SiloGeometry& g, double grain_mass);
    // One frame: centres of mass and velocities of the grains in the silo; `tag` as FlowPatternClassifier's.
    void add_frame(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Vector3d>& velocities,
                   double tag);
    // Over the frames whose tag lies in [tag_low, tag_high].
    OutletFlowResult result(double tag_low, double tag_high) const;
    // Checkpoint: the frames gathered so far.
    void save(StateWriter& w) const;
    void load(StateReader& r);

private:
    struct Frame {
        double tag = 0;
        double grains = 0;          // grain centres in the zone
        double downward_sum = 0;    // sum of -vz over the zone's grains [m/s]
    };
    bool in_zone(const Eigen::Vector3d& p) const;
    SiloGeometry g_;
    double grain_mass_;
    double zone_height_, outlet_area_;
    std::vector<Frame> frames_;
};

}  // namespace demcal::kernel::silo
