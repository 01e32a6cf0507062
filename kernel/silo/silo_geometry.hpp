// The silo of the seed's DEM model (section 2.3): a cylindrical body over a conical hopper with a circular outlet,
// or a rectangular box over a wedge hopper with a slot outlet spanning the depth (section 2.1.2).
// Frame: z up, the outlet plane at z = 0, the silo axis along z through x = y = 0. SI units, angles in degrees.
#pragma once
#include <Eigen/Core>

#include <string>

namespace demcal::kernel::silo {

enum class SiloShape { conical, rectangular };

struct SiloGeometry {
    SiloShape shape = SiloShape::conical;
    double diameter = 0.105;       // D [m], cylindrical body (conical)
    double body_height = 0.4;      // height of the vertical body above the hopper [m]
    double half_angle_deg = 30;    // theta, hopper half angle from the vertical [deg], 0 < theta < 90
    double outlet = 0.035;         // d, circular outlet diameter (conical) or a, slot width (rectangular) [m]
    double depth = 0.05;           // b [m], rectangular: silo depth (along y), the slot spans it
    double width = 0.1;            // c [m], rectangular: silo width (along x); the hopper narrows it to a

    static SiloGeometry conical(double theta_deg, double outlet_d = 0.035, double diameter_D = 0.105,
                                double body_height = 0.4);
    static SiloGeometry rectangular(double theta_deg, double a, double b, double c, double body_height = 0.4);

    // Half-size of the horizontal section at height z: the radius (conical) or the half width along x (rectangular),
    // for 0 <= z <= top(); the outlet's half size below 0.
    double half_size_at(double z) const;
    double outlet_half() const { return 0.5 * outlet; }
    double top_half() const { return shape == SiloShape::conical ? 0.5 * diameter : 0.5 * width; }
    double hopper_height() const;     // H_h: height of the hopper (outlet to the body) [m]
    double top() const { return hopper_height() + body_height; }
    double volume() const;            // inside volume of hopper and body [m^3]
    double volume_below(double z) const;   // inside volume between the outlet and height z [m^3]
    double outlet_area() const;
    double horizontal_area_at(double z) const;
    // Transverse coordinate used by the flow-pattern measure and the section: r = sqrt(x^2+y^2) (conical) or |x|.
    double transverse(const Eigen::Vector3d& p) const;
    // Distance from p to the nearest side wall (hopper or body; negative outside), ignoring the outlet plane.
    double distance_to_side_wall(const Eigen::Vector3d& p) const;
    // Is a sphere of radius r centred at p inside the silo with at least `clearance` to every wall (and above z=0)?
    bool contains(const Eigen::Vector3d& p, double r, double clearance = 0) const;
    std::string describe() const;
};

// Throws std::invalid_argument naming the field and its value: non-positive sizes, theta outside (0, 90),
// an outlet not larger than `min_outlet_particles` particle sizes or not smaller than the silo, a hopper taller than
// 20 silo sizes (theta too small for the outlet), a rectangular depth smaller than the outlet criterion.
void validate(const SiloGeometry& g, double particle_size, double min_outlet_particles = 3.0);

}  // namespace demcal::kernel::silo
