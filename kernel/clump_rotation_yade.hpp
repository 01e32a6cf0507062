// YADE's rotational update of an aspherical body (a clump), as NewtonIntegrator::leapfrogAsphericalRotate of YADE
// 2023.02a computes it (exactAsphericalRot = True, its default): a leapfrog on the world angular momentum with a
// half-step quaternion (Fincham's scheme), the orientation advanced by q + dt dq/dt without normalising in between.
//
// Why the kernel has it: the cross-check against YADE (demcal silo --discharge-rotation yade) can then discharge with
// YADE's integrator and measure what the integrators alone change. The kernel's own scheme (clump_rotation.hpp,
// Richardson as LAMMPS/LIGGGHTS) stays the default.
//
// YADE's choices kept as they are, since matching them is the point: both body-frame angular velocities (at n and at
// n + 1/2) are taken with the orientation at n, and the world omega at n + 1/2 is that body-frame omega turned by the
// new orientation before it is normalised (Eigen's quaternion-vector product on a nearly unit quaternion).
#pragma once
#include "kernel/types.hpp"

namespace demcal::kernel::clump_rotation {

/// The body-frame angular velocity of a body-frame angular momentum, YADE's cwiseQuotient by the principal moments;
/// a zero moment (a template built by hand) gives 0 about that axis, as the kernel's own scheme does, not inf.
inline Vec3 yade_body_omega(const Vec3& L_body, const Vec3& inertia) {
  Vec3 w;
  for (int k = 0; k < 3; ++k) w[k] = inertia[k] > 0 ? L_body[k] / inertia[k] : 0.0;
  return w;
}

/// YADE's DotQ: dq/dt = 1/2 q (0, w_body) for a body-frame angular velocity w_body.
inline Quat yade_dot_q(const Vec3& w_body, const Quat& q) {
  Quat d;
  d.w() = (-q.x() * w_body[0] - q.y() * w_body[1] - q.z() * w_body[2]) / 2;
  d.x() = (q.w() * w_body[0] - q.z() * w_body[1] + q.y() * w_body[2]) / 2;
  d.y() = (q.z() * w_body[0] + q.w() * w_body[1] - q.x() * w_body[2]) / 2;
  d.z() = (-q.y() * w_body[0] + q.x() * w_body[1] + q.w() * w_body[2]) / 2;
  return d;
}

/// One step of YADE's aspherical leapfrog. `q`: the orientation at n (body -> world), advanced to n + 1 and
/// normalised. `L_n`: the world angular momentum at n (L at n - 1/2 plus dt/2 torque); `L_half`: at n + 1/2 (L at
/// n - 1/2 plus dt torque); `inertia`: the principal moments. Returns the world angular velocity at n + 1/2.
inline Vec3 yade_leapfrog(Quat& q, const Vec3& L_n, const Vec3& L_half, const Vec3& inertia, double dt) {
  const Mat3 A = q.conjugate().toRotationMatrix();  // world -> body at n
  const Vec3 w_body_n = yade_body_omega(A * L_n, inertia);
  const Quat dq_n = yade_dot_q(w_body_n, q);
  const Quat q_half(q.coeffs() + dt / 2. * dq_n.coeffs());
  const Vec3 w_body_half = yade_body_omega(A * L_half, inertia);
  const Quat dq_half = yade_dot_q(w_body_half, q_half);
  q = Quat(q.coeffs() + dt * dq_half.coeffs());
  const Vec3 omega = q * w_body_half;  // (q not yet normalised, as in YADE)
  q.normalize();
  return omega;
}

}  // namespace demcal::kernel::clump_rotation
