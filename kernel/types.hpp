// Basic types of the native DEM kernel (SI units throughout: m, kg, s, N, Pa).
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace demcal::kernel {

using Vec3 = Eigen::Vector3d;      ///< a point, velocity, force or torque in the world frame
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;   ///< unit quaternion: body frame -> world frame
using BodyId = std::uint64_t;      ///< stable identity of a body (never reused within one Simulation)

}  // namespace demcal::kernel
