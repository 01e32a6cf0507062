#include "kernel/silo/wheat.hpp"

#include <cmath>

namespace demcal::kernel::silo {

std::vector<ClumpSphere> wheat_clump() {
    return {{Eigen::Vector3d(-0.0015, 0, 0), 0.00125},
            {Eigen::Vector3d(0, 0, 0), 0.0015},
            {Eigen::Vector3d(0.0015, 0, 0), 0.00125}};
}

double wheat_equivalent_diameter() { return std::cbrt(6 * (wheat_mass / 1430.0) / 3.14159265358979323846); }

double rayleigh_time_step(const Material& m, double radius) {
    return 3.14159265358979323846 * radius * std::sqrt(m.density / m.shear_modulus) / (0.1631 * m.poisson + 0.8766);
}

}  // namespace demcal::kernel::silo
