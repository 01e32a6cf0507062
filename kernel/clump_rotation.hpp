// The rotational update of rigid clumps, four clumps at a time.
//
// A clump's orientation advances by a Richardson iteration (LAMMPS MathExtra::richardson, as LIGGGHTS multisphere)
// with its angular momentum L fixed over the step: omega from L, a full and two half quaternion steps, the
// extrapolation 2 q_half - q_full, normalisation. That is a long chain of dependent floating-point operations per
// clump; done one clump after the other the core waits on latencies (perf on the full silo case while filling: the
// kick, mostly this, took 42 % of a step). Here the same operations run on four clumps side by side (GCC vector
// extensions: AVX where the build allows it, two SSE2 halves otherwise), which hides the latencies.
//
// Every operation is the one Eigen performs for the scalar formulation (Quaternion * Quaternion in its SSE2 form,
// Quaternion * Vector3, squaredNorm, normalize), in the same order, with no FMA contraction: the result is the same
// bit for bit as the scalar code it replaces (checked in tests/kernel/test_clump.cpp, "batched rotation").
#pragma once
#include <cmath>
#include <cstddef>

namespace demcal::kernel::clump_rotation {

constexpr int kLanes = 4;
typedef double Pack __attribute__((vector_size(kLanes * sizeof(double))));

/// A quaternion (x, y, z, w as Eigen stores them) and a vector, one lane per clump.
struct QuatPack {
  Pack x, y, z, w;
};
struct VecPack {
  Pack x, y, z;
};

inline void sqrt_lanes(Pack& a) {
  for (int k = 0; k < kLanes; ++k) a[k] = std::sqrt(a[k]);
}

/// a x b, Eigen's cross3_impl order.
inline VecPack cross(const VecPack& a, const VecPack& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/// q v q*: Eigen's QuaternionBase::_transformVector (uv = 2 (q.vec x v); v + w uv + q.vec x uv).
inline VecPack rotate(const QuatPack& q, const VecPack& v) {
  const VecPack qv{q.x, q.y, q.z};
  VecPack uv = cross(qv, v);
  uv = {uv.x + uv.x, uv.y + uv.y, uv.z + uv.z};
  const VecPack c = cross(qv, uv);
  return {(v.x + q.w * uv.x) + c.x, (v.y + q.w * uv.y) + c.y, (v.z + q.w * uv.z) + c.z};
}

/// a b: Eigen's quat_product for double in its SSE2 form (arch/Geometry_SIMD.h), operation for operation.
inline QuatPack multiply(const QuatPack& a, const QuatPack& b) {
  QuatPack r;
  r.x = (a.w * b.x + a.y * b.z) - (a.z * b.y - a.x * b.w);
  r.y = (a.w * b.y + a.y * b.w) + (a.z * b.x - a.x * b.z);
  r.z = (a.w * b.z - a.y * b.x) + (a.z * b.w + a.x * b.y);
  r.w = (a.w * b.w - a.y * b.y) - (a.z * b.z + a.x * b.x);
  return r;
}

/// |q|^2 as Eigen's vectorised reduction of the coefficients (x, y, z, w) sums it: (x^2 + z^2) + (y^2 + w^2).
inline Pack squared_norm(const QuatPack& q) { return (q.x * q.x + q.z * q.z) + (q.y * q.y + q.w * q.w); }

/// omega (world) = q ((q* L) o inv_I).
inline VecPack omega_from_L(const QuatPack& q, const VecPack& L, const VecPack& inv_I) {
  const QuatPack qc{-q.x, -q.y, -q.z, q.w};
  const VecPack b = rotate(qc, L);
  return rotate(q, {b.x * inv_I.x, b.y * inv_I.y, b.z * inv_I.z});
}

/// dq/dt = 1/2 (0, w) q (the 1/2 is applied by the caller's step size).
inline QuatPack wq(const VecPack& w, const QuatPack& q) {
  const Pack zero = {0.0, 0.0, 0.0, 0.0};
  return multiply({w.x, w.y, w.z, zero}, q);
}

inline QuatPack add_scaled(const QuatPack& a, const Pack& s, const QuatPack& b) {
  return {a.x + s * b.x, a.y + s * b.y, a.z + s * b.z, a.w + s * b.w};
}

/// Brings a nearly unit quaternion back to unit length with one Newton step for 1/|q| (no square root, no
/// division): |q|^2 = 1 + d gives an error O(d^2). Used on the intermediate quaternions of a step, where
/// d = (|omega| dt / 2)^2 at most (5e-5 for 500 rad/s in the reduced silo's 28 us step); the quaternion kept at the
/// end of the step is normalised exactly.
inline QuatPack renormalized(const QuatPack& q) {
  const Pack f = 1.5 - 0.5 * squared_norm(q);
  return {f * q.x, f * q.y, f * q.z, f * q.w};
}

/// Advances the orientations q of four clumps over dt with their angular momenta L and inverse principal moments
/// inv_I fixed (omega at the start of the step taken from L).
inline void richardson(QuatPack& q, const VecPack& L, const VecPack& inv_I, double dt) {
  const Pack dtq = {0.5 * dt, 0.5 * dt, 0.5 * dt, 0.5 * dt};
  const Pack dtq2 = 0.5 * dtq;
  const VecPack w0 = omega_from_L(q, L, inv_I);
  const QuatPack wq0 = wq(w0, q);
  const QuatPack qfull = renormalized(add_scaled(q, dtq, wq0));
  QuatPack qhalf = renormalized(add_scaled(q, dtq2, wq0));
  const VecPack w = omega_from_L(qhalf, L, inv_I);
  qhalf = renormalized(add_scaled(qhalf, dtq2, wq(w, qhalf)));
  QuatPack r{2.0 * qhalf.x - qfull.x, 2.0 * qhalf.y - qfull.y, 2.0 * qhalf.z - qfull.z, 2.0 * qhalf.w - qfull.w};
  // Eigen's normalize(): divide by the norm where the squared norm is positive
  const Pack n2 = squared_norm(r);
  Pack n = n2;
  sqrt_lanes(n);
  const auto positive = n2 > 0.0;
  q.x = positive ? r.x / n : r.x;
  q.y = positive ? r.y / n : r.y;
  q.z = positive ? r.z / n : r.z;
  q.w = positive ? r.w / n : r.w;
}

/// A rotation matrix per lane, m[row][col].
struct MatPack {
  Pack m[3][3];
};

/// The rotation matrix of q: Eigen's QuaternionBase::toRotationMatrix, operation for operation.
inline MatPack rotation_matrix(const QuatPack& q) {
  const Pack tx = 2.0 * q.x, ty = 2.0 * q.y, tz = 2.0 * q.z;
  const Pack twx = tx * q.w, twy = ty * q.w, twz = tz * q.w;
  const Pack txx = tx * q.x, txy = ty * q.x, txz = tz * q.x;
  const Pack tyy = ty * q.y, tyz = tz * q.y, tzz = tz * q.z;
  MatPack r;
  r.m[0][0] = 1.0 - (tyy + tzz); r.m[0][1] = txy - twz;         r.m[0][2] = txz + twy;
  r.m[1][0] = txy + twz;         r.m[1][1] = 1.0 - (txx + tzz); r.m[1][2] = tyz - twx;
  r.m[2][0] = txz - twy;         r.m[2][1] = tyz + twx;         r.m[2][2] = 1.0 - (txx + tyy);
  return r;
}

/// omega (world) = R ((R^T L) o inv_I), summed as Eigen's fixed-size products sum them: R^T v over its three terms
/// in order, R v likewise for rows 0 and 1 (one packet) and as a0 + (a1 + a2) for row 2 (the scalar tail).
inline VecPack angular_velocity(const MatPack& R, const VecPack& L, const VecPack& inv_I) {
  const auto& m = R.m;
  const Pack bx = ((m[0][0] * L.x + m[1][0] * L.y) + m[2][0] * L.z) * inv_I.x;
  const Pack by = ((m[0][1] * L.x + m[1][1] * L.y) + m[2][1] * L.z) * inv_I.y;
  const Pack bz = ((m[0][2] * L.x + m[1][2] * L.y) + m[2][2] * L.z) * inv_I.z;
  return {(m[0][0] * bx + m[0][1] * by) + m[0][2] * bz, (m[1][0] * bx + m[1][1] * by) + m[1][2] * bz,
          m[2][0] * bx + (m[2][1] * by + m[2][2] * bz)};
}

}  // namespace demcal::kernel::clump_rotation
