// The surface swept by the segment (r0, z0)-(r1, z1) of the (rho, z) half-plane around a vertical axis through
// (cx, cy); two-sided, closest point. A cylinder (r0 = r1), a cone frustum (a hopper: r0 = outlet radius at the
// bottom), an annulus or a disk (z0 = z1; a disk with r0 = 0 is a round outlet plate) are this one type.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>
#include "kernel/types.hpp"

namespace demcal::kernel {

struct AxisymmetricWall {
  double cx = 0, cy = 0;                  ///< axis position (axis is vertical, parallel to z) [m]
  double r0 = 0, z0 = 0, r1 = 0, z1 = 0;  ///< segment end points in (rho, z) [m]

  bool contact(const Vec3& p, double r, Vec3& n, double& dn, double& dist) const {
    // quick reject on the segment's bounding box in (rho, z), without a square root
    if (p.z() + r <= std::min(z0, z1) || p.z() - r >= std::max(z0, z1)) return false;
    const double dx = p.x() - cx, dy = p.y() - cy;
    const double rho2 = dx * dx + dy * dy;
    const double rlo = std::min(r0, r1) - r, rhi = std::max(r0, r1) + r;
    if ((rlo > 0 && rho2 <= rlo * rlo) || rho2 >= rhi * rhi) return false;
    const double rho = std::sqrt(rho2);
    const double ex = r1 - r0, ez = z1 - z0;
    const double len2 = ex * ex + ez * ez;
    double t = len2 > 0 ? ((rho - r0) * ex + (p.z() - z0) * ez) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double qr = rho - (r0 + t * ex), qz = p.z() - (z0 + t * ez);
    const double d2 = qr * qr + qz * qz;
    if (d2 >= r * r) return false;
    const double dl = std::sqrt(d2);
    double erx = 1.0, ery = 0.0;
    if (rho > 1e-300) { erx = dx / rho; ery = dy / rho; }
    if (dl > 1e-300) {
      n = Vec3(qr * erx, qr * ery, qz) / dl;
    } else {  // centre on the surface: take the segment's normal (pointing to larger rho for a cylinder)
      const double l = std::sqrt(len2);
      n = Vec3(ez / l * erx, ez / l * ery, -ex / l);
    }
    dn = r - dl; dist = dl;
    return true;
  }
  /// Axis-aligned bounding box [lo, hi] of the surface of revolution.
  bool bounds(Vec3& lo, Vec3& hi) const {
    const double r = std::max(r0, r1);
    lo = Vec3(cx - r, cy - r, std::min(z0, z1)); hi = Vec3(cx + r, cy + r, std::max(z0, z1));
    return true;
  }
  void append_numbers(std::vector<double>& c) const { c.insert(c.end(), {cx, cy, r0, z0, r1, z1}); }
};

}  // namespace demcal::kernel
