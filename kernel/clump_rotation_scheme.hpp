// The choice of rotational update for rigid clumps, apart from the simulation so that a case's settings can name it.
#pragma once
#include <cstdint>

namespace demcal::kernel {

/// The rotational update of rigid clumps (BasicSimulation::set_clump_rotation).
enum class ClumpRotation : std::uint8_t {
  richardson = 0,     ///< the kernel's: Richardson quaternion iteration, omega from L (kernel/clump_rotation.hpp)
  yade_leapfrog = 1,  ///< YADE 2023.02a's NewtonIntegrator(exactAsphericalRot = True) (kernel/clump_rotation_yade.hpp)
};

}  // namespace demcal::kernel
