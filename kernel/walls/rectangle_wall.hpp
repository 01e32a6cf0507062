// A bounded plane (a plate): centre, normal, in-plane axis u, half extents; two-sided, contact with the closest point
// of the rectangle, so edges and corners act too. Slanted hopper walls, outlet plates, the sides of a box.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>
#include "kernel/types.hpp"

namespace demcal::kernel {

struct RectangleWall {
  Vec3 centre = Vec3::Zero();   ///< [m]
  Vec3 normal = Vec3::UnitZ();  ///< unit normal
  Vec3 u = Vec3::UnitX();       ///< unit in-plane axis (orthogonal to normal); v = normal x u
  Vec3 v = Vec3::UnitY();
  double half_u = 0, half_v = 0;  ///< half extents along u and v [m]

  bool contact(const Vec3& p, double r, Vec3& n, double& dn, double& dist) const {
    const Vec3 q = p - centre;
    const double dz = q.dot(normal);
    if (dz >= r || dz <= -r) return false;
    const double a = std::clamp(q.dot(u), -half_u, half_u), b = std::clamp(q.dot(v), -half_v, half_v);
    const Vec3 d = q - a * u - b * v;  // p - closest point
    const double d2 = d.squaredNorm();
    if (d2 >= r * r) return false;
    const double dl = std::sqrt(d2);
    if (dl > 1e-300) n = d / dl; else n = normal;
    dn = r - dl; dist = dl;
    return true;
  }
  /// Axis-aligned bounding box [lo, hi] of the rectangle (every point a contact can be with lies in it).
  bool bounds(Vec3& lo, Vec3& hi) const {
    const Vec3 extent = half_u * u.cwiseAbs() + half_v * v.cwiseAbs();
    lo = centre - extent; hi = centre + extent;
    return true;
  }
  void append_numbers(std::vector<double>& c) const {
    c.insert(c.end(), {centre.x(), centre.y(), centre.z(), normal.x(), normal.y(), normal.z(), u.x(), u.y(), u.z(),
                       v.x(), v.y(), v.z(), half_u, half_v});
  }
};

}  // namespace demcal::kernel
