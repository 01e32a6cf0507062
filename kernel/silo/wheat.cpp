#include "kernel/silo/wheat.hpp"

#include "kernel/material.hpp"

#include <cmath>

namespace demcal::kernel::silo {

std::vector<ClumpSphere> wheat_clump() {
    return {{Eigen::Vector3d(-0.0015, 0, 0), 0.00125},
            {Eigen::Vector3d(0, 0, 0), 0.0015},
            {Eigen::Vector3d(0.0015, 0, 0), 0.00125}};
}

double wheat_grain_volume() { return wheat_mass / WheatMaterials{}.wheat.density; }

double wheat_equivalent_diameter() { return std::cbrt(6 * wheat_grain_volume() / 3.14159265358979323846); }

double rayleigh_time_step(const Material& m, double radius) {
    return kernel::rayleigh_timestep(radius, m.density, m.shear_modulus, m.poisson);
}

}  // namespace demcal::kernel::silo
