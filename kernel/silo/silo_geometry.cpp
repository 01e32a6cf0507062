#include "kernel/silo/silo_geometry.hpp"
#include "kernel/silo/input_error.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace demcal::kernel::silo {

namespace {
constexpr double pi = 3.14159265358979323846;
double rad(double deg) { return deg * pi / 180.0; }

}  // namespace

SiloGeometry SiloGeometry::conical(double theta_deg, double outlet_d, double diameter_D, double body_h) {
    SiloGeometry g;
    g.shape = SiloShape::conical;
    g.half_angle_deg = theta_deg;
    g.outlet = outlet_d;
    g.diameter = diameter_D;
    g.body_height = body_h;
    return g;
}

SiloGeometry SiloGeometry::rectangular(double theta_deg, double a, double b, double c, double body_h) {
    SiloGeometry g;
    g.shape = SiloShape::rectangular;
    g.half_angle_deg = theta_deg;
    g.outlet = a;
    g.depth = b;
    g.width = c;
    g.body_height = body_h;
    return g;
}

double SiloGeometry::hopper_height() const { return (top_half() - outlet_half()) / std::tan(rad(half_angle_deg)); }

double SiloGeometry::half_size_at(double z) const {
    if (z <= 0) return outlet_half();
    const double hh = hopper_height();
    if (z >= hh) return top_half();
    return outlet_half() + z * std::tan(rad(half_angle_deg));
}

double SiloGeometry::horizontal_area_at(double z) const {
    const double h = half_size_at(z);
    return shape == SiloShape::conical ? pi * h * h : 2 * h * depth;
}

double SiloGeometry::outlet_area() const {
    return shape == SiloShape::conical ? pi * outlet_half() * outlet_half() : outlet * depth;
}

double SiloGeometry::volume_below(double z) const {
    if (z <= 0) return 0;
    const double hh = hopper_height(), t = std::tan(rad(half_angle_deg));
    const double zh = std::min(z, hh);
    const double r0 = outlet_half(), r1 = r0 + zh * t;
    double v;
    if (shape == SiloShape::conical)
        v = pi * zh / 3 * (r0 * r0 + r0 * r1 + r1 * r1);
    else
        v = (r0 + r1) * zh * depth;  // trapezoid: (2 r0 + 2 r1)/2 * zh * b
    if (z > hh) v += horizontal_area_at(hh + 1e-12) * (std::min(z, top()) - hh);
    return v;
}

double SiloGeometry::volume() const { return volume_below(top()); }

double SiloGeometry::transverse(const Eigen::Vector3d& p) const {
    return shape == SiloShape::conical ? std::hypot(p.x(), p.y()) : std::abs(p.x());
}

double SiloGeometry::distance_to_side_wall(const Eigen::Vector3d& p) const {
    // In the (s, z) half plane the side wall is the polyline (r0, 0) - (R, H_h) - (R, top): the distance is the
    // nearest of its two segments (a sphere just above the hopper's top edge can touch the flat hopper of a large
    // theta), signed positive inside.
    const double s = transverse(p), z = p.z();
    const double r0 = outlet_half(), R = top_half(), hh = hopper_height();
    auto seg = [&](double a0, double b0, double a1, double b1) {
        const double ex = a1 - a0, ez = b1 - b0, l2 = ex * ex + ez * ez;
        const double t = l2 > 0 ? std::clamp(((s - a0) * ex + (z - b0) * ez) / l2, 0.0, 1.0) : 0.0;
        return std::hypot(s - (a0 + t * ex), z - (b0 + t * ez));
    };
    const double d_wall = std::min(seg(r0, 0, R, hh), seg(R, hh, R, std::max(top(), hh)));
    const bool inside = z >= hh ? s <= R : s <= r0 + z * std::tan(rad(half_angle_deg));
    double d = inside ? d_wall : -d_wall;
    if (z < 0) d = r0 - s;
    if (shape == SiloShape::rectangular) d = std::min(d, 0.5 * depth - std::abs(p.y()));
    return d;
}

bool SiloGeometry::contains(const Eigen::Vector3d& p, double r, double clearance) const {
    if (p.z() - r < clearance || p.z() + r > top() - clearance) return false;
    return distance_to_side_wall(p) >= r + clearance;
}

std::string SiloGeometry::describe() const {
    std::ostringstream s;
    if (shape == SiloShape::conical)
        s << "conical hopper: D = " << diameter << " m, d = " << outlet << " m, theta = " << half_angle_deg
          << " deg, hopper height " << hopper_height() << " m, body " << body_height << " m";
    else
        s << "rectangular hopper: a = " << outlet << " m, b = " << depth << " m, c = " << width
          << " m, theta = " << half_angle_deg << " deg, hopper height " << hopper_height() << " m, body "
          << body_height << " m";
    return s.str();
}

void validate(const SiloGeometry& g, double particle_size, double min_outlet_particles) {
    if (!(particle_size > 0)) reject_setting("particle_size", particle_size, "must be positive");
    if (!(g.half_angle_deg > 0 && g.half_angle_deg < 90))
        reject_setting("theta", g.half_angle_deg, "the hopper half angle must lie strictly between 0 and 90 deg");
    if (!(g.body_height >= 0) || !std::isfinite(g.body_height)) reject_setting("body_height", g.body_height, "must be >= 0 m");
    const char* outlet_name = g.shape == SiloShape::conical ? "outlet" : "a (outlet width)";
    if (!(g.outlet > 0) || !std::isfinite(g.outlet)) reject_setting(outlet_name, g.outlet, "must be positive");
    if (g.outlet < min_outlet_particles * particle_size)
        reject_setting(outlet_name, g.outlet,
            "the outlet must be at least " + setting_text(min_outlet_particles) + " particle sizes (" +
                setting_text(min_outlet_particles * particle_size) + " m for d_p = " + setting_text(particle_size) +
                " m), or the grains arch over it");
    if (g.shape == SiloShape::conical) {
        if (!(g.diameter > 0) || !std::isfinite(g.diameter))
            reject_setting("diameter", g.diameter, "the silo diameter D must be larger than the outlet (" + setting_text(g.outlet) + " m)");
        if (!(g.diameter > g.outlet))  // a rule on both: the outlet may be the one given wrong
            throw SettingRejected("diameter", g.diameter, outlet_name, g.outlet, "the silo diameter D must be larger than the outlet");
    } else {
        if (!(g.width > 0) || !std::isfinite(g.width))
            reject_setting("c (width)", g.width, "the silo width c must be larger than the outlet width a (" + setting_text(g.outlet) + " m)");
        if (!(g.width > g.outlet))
            throw SettingRejected("c (width)", g.width, outlet_name, g.outlet, "the silo width c must be larger than the outlet width a");
        if (!(g.depth > 0) || !std::isfinite(g.depth)) reject_setting("b (depth)", g.depth, "must be positive");
        if (g.depth < min_outlet_particles * particle_size)
            reject_setting("b (depth)", g.depth,
                "the slot spans the depth b, which must be at least " + setting_text(min_outlet_particles) +
                    " particle sizes (" + setting_text(min_outlet_particles * particle_size) + " m)");
    }
    const double size = g.shape == SiloShape::conical ? g.diameter : g.width;
    // A bed is a few grains deep at most once the silo is this wide: the largest run (5,000,000 grains) could not
    // fill it (a diameter of 1e19 m was refused only by the stiffness check, for a fall of 1e10 m/s).
    constexpr double kMaxParticleSizesAcross = 1000;
    const char* size_name = g.shape == SiloShape::conical ? "diameter" : "c (width)";
    if (size > kMaxParticleSizesAcross * particle_size)
        reject_setting(size_name, size,
                       "more than " + setting_text(kMaxParticleSizesAcross) + " particle sizes across (" +
                           setting_text(kMaxParticleSizesAcross * particle_size) + " m for d_p = " +
                           setting_text(particle_size) + " m): no run can fill it");
    if (g.shape == SiloShape::rectangular && g.depth > kMaxParticleSizesAcross * particle_size)
        reject_setting("b (depth)", g.depth,
                       "more than " + setting_text(kMaxParticleSizesAcross) + " particle sizes (" +
                           setting_text(kMaxParticleSizesAcross * particle_size) + " m for d_p = " +
                           setting_text(particle_size) + " m): no run can fill it");
    if (g.hopper_height() > 20 * size)
        reject_setting("theta", g.half_angle_deg,
            "the hopper would be " + setting_text(g.hopper_height()) + " m tall (more than 20 silo sizes)");
    // Beyond a few sizes the body adds only head that Janssen's arching screens from the outlet (industrial silos
    // stop near H/D = 10); a body of kilometres would make the filling's free fall the run's whole time.
    if (g.body_height > 20 * size)
        reject_setting("body_height", g.body_height,
            "the body would be more than 20 silo sizes tall (" + setting_text(20 * size) + " m)");
}

}  // namespace demcal::kernel::silo
