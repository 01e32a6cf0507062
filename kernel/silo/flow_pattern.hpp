// The flow pattern (mass / mixed / funnel) from the velocity field in the hopper during the steady discharge.
//
// Measure (wall-to-axis velocity ratio): each grain whose centre lies in the hopper within `wall_layer` of the
// hopper's slanted wall, and at least `edge_clearance` from the outlet edge measured along the wall, is a "wall
// sample"; each grain within `axis_fraction` of the local half size from the axis (at least `axis_min` from it) is an
// "axis sample". Samples are binned by height (bin = `bin_height`). The measure is the mean, over all wall samples, of
// the wall grain's downward velocity divided by the mean downward velocity of the axis samples of its height bin
// (bins whose axis grains are not moving down, mean below `min_axis_speed`, are left out). It is accumulated over
// every sampled frame of the steady discharge.
//
// Thresholds (after the seed's figure 3.7, where the pattern is read from the mid-plane coloured linearly from the
// minimal (blue) to the maximal (red) vertical velocity): in mass flow the whole hopper content moves, the grains at the
// hopper wall as well as the core (for frictionless radial flow in a cone the ratio is cos^3 theta, 0.96 at 10 deg);
// in funnel flow the grains along the hopper wall look stagnant (blue) while the core runs. Funnel flow: ratio < 0.25
// (wall grains in the lowest quarter of the core's speed: blue on such a scale); mass flow: ratio >= 0.5 (wall grains
// at least half the core's speed: green to red); mixed flow in between. Measured on the reduced case (D = 70 mm,
// d = 30 mm, 4000 grains; examples/silo/README.md) the ratio falls monotonically with theta: 0.81, 0.62, 0.40, 0.22,
// 0.10, ... for 10, 20, 30, 40, 50 deg, so these thresholds give mass flow below 30 deg, mixed at 30 deg and funnel
// flow from 40 deg, the seed's sequence.
#pragma once
#include "kernel/silo/silo_geometry.hpp"
#include "kernel/state_io.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace demcal::kernel::silo {

enum class FlowPattern { undetermined, mass, mixed, funnel };
std::string to_string(FlowPattern p);

struct FlowPatternSettings {
    double wall_layer = 0.0055;      // [m], default one grain length d_p
    double edge_clearance = 0.011;   // [m] along the wall from the outlet edge, default 2 d_p
    double axis_fraction = 0.3;      // of the local half size
    double axis_min = 0.00275;       // [m], default d_p / 2
    double bin_height = 0.0055;      // [m]
    double min_axis_speed = 1e-3;    // [m/s]
    double mass_threshold = 0.5;
    double funnel_threshold = 0.25;
};

struct FlowPatternResult {
    FlowPattern pattern = FlowPattern::undetermined;
    double ratio = 0;              // the measure (wall / axis downward velocity)
    double wall_speed = 0;         // mean downward velocity of the wall samples used [m/s]
    double axis_speed = 0;         // mean downward velocity of the axis samples of the same bins [m/s]
    long wall_samples = 0, axis_samples = 0, frames = 0;
    std::string measure;           // the measure in words, with the thresholds
    std::string message;           // why it is undetermined
};

// Frames are gathered while the discharged fraction of the filled mass lies in [steady_lower / 2, steady_upper]: the
// measure's window (steady_lower..steady_upper of the mass discharged at the end) is known only at the end and can
// begin lower when the flow stops early. One rule for the kernel's run and for frames read from another code.
bool gathers_frame(double fraction_out, double steady_lower, double steady_upper);

class FlowPatternClassifier {
public:
    FlowPatternClassifier(const SiloGeometry& g, FlowPatternSettings s = {});
    // One frame: centres of mass and velocities of the grains in the silo; `tag` (e.g. the discharged mass at that
    // moment) lets result() keep only the frames of a window chosen afterwards.
    void add_frame(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Vector3d>& velocities,
                   double tag = 0);
    // The measure over the frames whose tag lies in [tag_low, tag_high].
    FlowPatternResult result(double tag_low = -1e300, double tag_high = 1e300) const;
    const FlowPatternSettings& settings() const { return s_; }
    // Checkpoint: the frames gathered so far (the geometry and settings come from the run's settings).
    void save(StateWriter& w) const;
    void load(StateReader& r);

private:
    struct Bin {
        double wall_sum = 0, axis_sum = 0;
        long wall_n = 0, axis_n = 0;
    };
    struct Frame {
        double tag = 0;
        std::vector<Bin> bins;
    };
    SiloGeometry g_;
    FlowPatternSettings s_;
    std::vector<Frame> frames_;  // per frame, so the ratio uses the axis speed of the same moment
};

}  // namespace demcal::kernel::silo
