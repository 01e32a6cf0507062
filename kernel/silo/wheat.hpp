// The seed's wheat grain and the micromechanical parameters of its Table 2.1 (section 2.3.1).
#pragma once
#include <Eigen/Core>

#include <vector>

#include "kernel/clump.hpp"

namespace demcal::kernel::silo {

// One sphere of a rigid clump: centre in the clump's body frame (long axis along x) and radius.
struct ClumpSphere {
    Eigen::Vector3d centre;
    double radius;
};

// The seed's grain (figure 2.6): three spheres in a row, the middle one r = 1.5 mm, the end ones r = 1.25 mm with
// centres 1.5 mm from it. Mass 0.0356 g (union of the spheres at 1430 kg/m^3), principal moments 2.918e-11 (long
// axis) and 7.654e-11 kg m^2.
std::vector<ClumpSphere> wheat_clump();
inline constexpr double wheat_length = 0.0055;       // end to end [m]: the particle size d_p used for the outlet
// The seed's grain's length over its width: (2 x 1.5 + 2 x 1.25) / (2 x 1.5) mm.
inline constexpr double wheat_aspect_ratio = 11.0 / 6.0;
// Elongations a grain of this family may take: at 1 the end spheres touch the middle one from inside (a sphere); at
// 8/3 they touch it from outside, beyond which the clump would fall apart into three spheres. 2.6 keeps every
// member overlapping its neighbour by 4 % of the middle radius.
inline constexpr double min_grain_aspect_ratio = 1.0, max_grain_aspect_ratio = 2.6;
inline constexpr double wheat_mass = 3.56e-5;        // seed [kg]
inline constexpr double wheat_inertia_axial = 2.918e-11;      // seed [kg m^2]
inline constexpr double wheat_inertia_transverse = 7.654e-11;  // seed [kg m^2]
// Volume of the grain (the seed's mass at the seed's density): 24.9 mm^3.
double wheat_grain_volume();
// Equivalent-volume sphere diameter of the grain: (6 V / pi)^(1/3) = 3.62 mm.
double wheat_equivalent_diameter();

// A grain of the seed's family with another elongation (length / width = aspect_ratio, within the bounds above):
// the same three spheres in a row with the seed's radius ratio (1.25 : 1.5), the end spheres moved along the axis,
// and the whole scaled so that the union keeps the seed grain's volume (so its mass, equivalent diameter and the
// grain count of a fill mass stay). Elongation alone changes, not size. At the seed's ratio: exactly wheat_clump().
// Throws std::invalid_argument naming the value outside the bounds.
std::vector<ClumpSphere> elongated_wheat_clump(double aspect_ratio);
// End-to-end length of a clump of spheres in a row along x [m].
double clump_length(const std::vector<ClumpSphere>& spheres);
// Volume of the union of spheres whose centres lie on the x axis [m^3] (a solid of revolution, integrated exactly
// between the breakpoints where the outermost sphere changes, by Gauss-Legendre on each piece).
double coaxial_union_volume(const std::vector<ClumpSphere>& spheres);
// The mass properties of such a grain at `density` (kernel/clump.hpp). At the seed's ratio the same template as
// kernel::wheat_clump_template, bit for bit.
kernel::ClumpTemplate wheat_grain_template(double density, double aspect_ratio);

struct Material {
    double shear_modulus;  // G [Pa]
    double poisson;        // nu [-]
    double density;        // rho [kg/m^3]
    double young() const { return 2 * shear_modulus * (1 + poisson); }
};

// Pair coefficients of Table 2.1.
struct PairCoefficients {
    double restitution;       // C_r [-]
    double friction;          // mu_0, static (sliding) friction [-]
    double rolling_friction;  // f [-], constant directional torque tau = -f Fn R omega/|omega| (EDEM)
    // gamma [J/m^2] >= 0: JKR cohesion (EDEM's "Hertz-Mindlin with JKR cohesion", kernel/contact/jkr_normal.hpp),
    // pull-off force 3 pi gamma R*. 0 (Table 2.1's wheat): no cohesion, the Hertz-Mindlin law.
    double surface_energy = 0;
};

struct WheatMaterials {
    Material wheat{3.58e8, 0.4, 1430};
    Material steel{8e8, 0.3, 7500};
    PairCoefficients wheat_wheat{0.5, 0.3, 0.01};
    PairCoefficients wheat_steel{0.6, 0.25, 0.01};
    // Scales both shear moduli (1 = the seed's values). A softer contact allows a larger time step (dt ~ G^-1/2) at
    // the cost of larger overlaps; the reduced test cases use 0.01 (see examples/silo/README.md).
    double stiffness_scale = 1.0;
    // Length over width of the grain (elongated_wheat_clump): the seed's 11/6 unless a material says otherwise.
    double grain_aspect_ratio = wheat_aspect_ratio;

    Material wheat_scaled() const { return {wheat.shear_modulus * stiffness_scale, wheat.poisson, wheat.density}; }
    // Whether either pair is cohesive: the silo then runs JKR (with gamma = 0 for a pair without cohesion, which is
    // Hertz) instead of Hertz-Mindlin.
    bool cohesive() const { return wheat_wheat.surface_energy > 0 || wheat_steel.surface_energy > 0; }

    Material steel_scaled() const { return {steel.shear_modulus * stiffness_scale, steel.poisson, steel.density}; }
};

// Rayleigh time step of a sphere of radius r: pi r sqrt(rho/G) / (0.1631 nu + 0.8766).
double rayleigh_time_step(const Material& m, double radius);

}  // namespace demcal::kernel::silo
