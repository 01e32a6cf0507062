// A solid axis-aligned box (YADE's utils.box as the walls of a shear box): a sphere touches its closest surface
// point; a sphere whose centre got inside is pushed out through the nearest face (as YADE's Ig2_Box_Sphere_ScGeom).
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>
#include "kernel/types.hpp"

namespace demcal::kernel {

struct BoxWall {
  Vec3 centre = Vec3::Zero();  ///< [m]
  Vec3 half = Vec3::Zero();    ///< half extents along x, y, z [m] (> 0)

  bool contact(const Vec3& p, double r, Vec3& n, double& dn, double& dist) const {
    const Vec3 q = p - centre;
    const Vec3 outside = q.cwiseAbs() - half;  // > 0 along the axes where the centre is outside the slab
    if (outside.maxCoeff() >= r) return false;
    if (outside.maxCoeff() > 0.0) {
      const Vec3 closest = q.cwiseMax(-half).cwiseMin(half);
      const Vec3 d = q - closest;
      const double d2 = d.squaredNorm();
      if (d2 >= r * r) return false;
      const double dl = std::sqrt(d2);
      n = d / dl; dn = r - dl; dist = dl;
      return true;
    }
    // centre inside: out through the face it is nearest to
    Eigen::Index axis = 0;
    outside.maxCoeff(&axis);
    n = Vec3::Zero();
    n[axis] = q[axis] >= 0 ? 1.0 : -1.0;
    dist = outside[axis];  // <= 0: the contact point lies beyond the centre
    dn = r - dist;
    return true;
  }
  /// Axis-aligned bounding box [lo, hi]: the box itself (a centre inside it is a contact too).
  bool bounds(Vec3& lo, Vec3& hi) const {
    lo = centre - half; hi = centre + half;
    return true;
  }
  void append_numbers(std::vector<double>& c) const {
    c.insert(c.end(), {centre.x(), centre.y(), centre.z(), half.x(), half.y(), half.z()});
  }
};

}  // namespace demcal::kernel
