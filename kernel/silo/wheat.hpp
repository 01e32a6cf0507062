// The seed's wheat grain and the micromechanical parameters of its Table 2.1 (section 2.3.1).
#pragma once
#include <Eigen/Core>

#include <vector>

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
inline constexpr double wheat_mass = 3.56e-5;        // seed [kg]
inline constexpr double wheat_inertia_axial = 2.918e-11;      // seed [kg m^2]
inline constexpr double wheat_inertia_transverse = 7.654e-11;  // seed [kg m^2]
// Volume of the grain (the seed's mass at the seed's density): 24.9 mm^3.
double wheat_grain_volume();
// Equivalent-volume sphere diameter of the grain: (6 V / pi)^(1/3) = 3.62 mm.
double wheat_equivalent_diameter();

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

    Material wheat_scaled() const { return {wheat.shear_modulus * stiffness_scale, wheat.poisson, wheat.density}; }
    // Whether either pair is cohesive: the silo then runs JKR (with gamma = 0 for a pair without cohesion, which is
    // Hertz) instead of Hertz-Mindlin.
    bool cohesive() const { return wheat_wheat.surface_energy > 0 || wheat_steel.surface_energy > 0; }

    Material steel_scaled() const { return {steel.shear_modulus * stiffness_scale, steel.poisson, steel.density}; }
};

// Rayleigh time step of a sphere of radius r: pi r sqrt(rho/G) / (0.1631 nu + 0.8766).
double rayleigh_time_step(const Material& m, double radius);

}  // namespace demcal::kernel::silo
