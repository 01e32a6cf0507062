// The tiny silo of the kernel's silo-case tests: 600 grains in a 70 mm bin with a 30 deg hopper and a 30 mm outlet,
// contacts softened 1000 times, one thread; filled for at most 0.3 s, discharged for 0.2 s. Seconds per run.
#pragma once
#include "kernel/silo/silo_case.hpp"

namespace demcal::test {

inline kernel::silo::SiloCaseSettings tiny_silo_case() {
    kernel::silo::SiloCaseSettings s;
    s.geometry = kernel::silo::SiloGeometry::conical(30, 0.03, 0.07, 0.15);
    s.particles = 600;
    s.materials.stiffness_scale = 1e-3;
    s.fill_time_max = 0.3;
    s.max_time = 0.2;
    s.threads = 1;
    return s;
}

}  // namespace demcal::test
