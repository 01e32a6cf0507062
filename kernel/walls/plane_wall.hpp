// An infinite, one-sided plane: particles live on the side its normal points to (a floor, a servo-held lid).
#pragma once
#include <vector>
#include "kernel/types.hpp"

namespace demcal::kernel {

struct PlaneWall {
  Vec3 point = Vec3::Zero();    ///< a point on the plane [m]
  Vec3 normal = Vec3::UnitZ();  ///< unit normal, towards the particles

  /// Closest-point query for a sphere at p of radius r (in the wall's frame). If it touches (overlap dn > 0), sets n
  /// (unit, from the wall towards p), dist (distance from p to the contact point) and returns true.
  bool contact(const Vec3& p, double r, Vec3& n, double& dn, double& dist) const {
    const double d = (p - point).dot(normal);
    if (d >= r || d <= -r) return false;  // beyond the far side: not a contact of this one-sided plane
    n = normal; dn = r - d; dist = d;
    return true;
  }
  /// No bounding box: a plane is infinite (WallGrid offers it to every sphere).
  bool bounds(Vec3&, Vec3&) const { return false; }
  void append_numbers(std::vector<double>& c) const {
    c.insert(c.end(), {point.x(), point.y(), point.z(), normal.x(), normal.y(), normal.z()});
  }
};

}  // namespace demcal::kernel
