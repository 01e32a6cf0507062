#include "kernel/silo/wheat.hpp"

#include "kernel/material.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace demcal::kernel::silo {

namespace {
constexpr double kMiddleRadius = 0.0015, kEndRadius = 0.00125;  // the seed's members [m]
}  // namespace

std::vector<ClumpSphere> wheat_clump() {
    return {{Eigen::Vector3d(-0.0015, 0, 0), 0.00125},
            {Eigen::Vector3d(0, 0, 0), 0.0015},
            {Eigen::Vector3d(0.0015, 0, 0), 0.00125}};
}

double wheat_grain_volume() { return wheat_mass / WheatMaterials{}.wheat.density; }

double wheat_equivalent_diameter() { return std::cbrt(6 * wheat_grain_volume() / 3.14159265358979323846); }

double clump_length(const std::vector<ClumpSphere>& spheres) {
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& s : spheres) {
        lo = std::min(lo, s.centre.x() - s.radius);
        hi = std::max(hi, s.centre.x() + s.radius);
    }
    return hi - lo;
}

double coaxial_union_volume(const std::vector<ClumpSphere>& spheres) {
    // Breakpoints: each sphere's ends and each pair's surface crossing; between two, one sphere is outermost (or
    // none), so pi rho(x)^2 is one quadratic there and 2-point Gauss-Legendre integrates it exactly.
    std::vector<double> x;
    for (std::size_t i = 0; i < spheres.size(); ++i) {
        const double xi = spheres[i].centre.x(), ri = spheres[i].radius;
        x.push_back(xi - ri);
        x.push_back(xi + ri);
        for (std::size_t j = i + 1; j < spheres.size(); ++j) {
            const double xj = spheres[j].centre.x(), rj = spheres[j].radius;
            if (xj != xi) x.push_back((ri * ri - rj * rj + xj * xj - xi * xi) / (2 * (xj - xi)));
        }
    }
    std::sort(x.begin(), x.end());
    const auto rho2 = [&](double at) {
        double r2 = 0;
        for (const auto& s : spheres) r2 = std::max(r2, s.radius * s.radius - std::pow(at - s.centre.x(), 2));
        return r2;
    };
    const double g = 1 / std::sqrt(3.0);
    double volume = 0;
    for (std::size_t k = 0; k + 1 < x.size(); ++k) {
        const double mid = 0.5 * (x[k] + x[k + 1]), half = 0.5 * (x[k + 1] - x[k]);
        volume += half * (rho2(mid - g * half) + rho2(mid + g * half));
    }
    return 3.14159265358979323846 * volume;
}

std::vector<ClumpSphere> elongated_wheat_clump(double aspect_ratio) {
    if (aspect_ratio == wheat_aspect_ratio) return wheat_clump();
    if (!(aspect_ratio >= min_grain_aspect_ratio && aspect_ratio <= max_grain_aspect_ratio))
        throw std::invalid_argument("grain.aspect_ratio = " + std::to_string(aspect_ratio) +
                                    ": must lie in [1, 2.6] (length / width of the 3-sphere grain)");
    // length 2 (s + r_end) over width 2 r_middle
    const double spacing = aspect_ratio * kMiddleRadius - kEndRadius;
    std::vector<ClumpSphere> grain{{Eigen::Vector3d(-spacing, 0, 0), kEndRadius},
                                   {Eigen::Vector3d(0, 0, 0), kMiddleRadius},
                                   {Eigen::Vector3d(spacing, 0, 0), kEndRadius}};
    const double scale = std::cbrt(coaxial_union_volume(wheat_clump()) / coaxial_union_volume(grain));
    for (auto& s : grain) {
        s.centre *= scale;
        s.radius *= scale;
    }
    return grain;
}

kernel::ClumpTemplate wheat_grain_template(double density, double aspect_ratio) {
    if (aspect_ratio == wheat_aspect_ratio) return kernel::wheat_clump_template(density);
    std::vector<Vec3> positions;
    std::vector<double> radii;
    for (const auto& s : elongated_wheat_clump(aspect_ratio)) {
        positions.push_back(s.centre);
        radii.push_back(s.radius);
    }
    return kernel::make_clump_template(positions, radii, density);
}

double rayleigh_time_step(const Material& m, double radius) {
    return kernel::rayleigh_timestep(radius, m.density, m.shear_modulus, m.poisson);
}

}  // namespace demcal::kernel::silo
