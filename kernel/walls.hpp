// Analytic walls. Three shapes cover the silo cases:
//  - Plane: infinite, one-sided (particles live on the side the normal points to); e.g. a floor.
//  - Rectangle: a bounded plane (centre, normal, in-plane axis u, half extents); two-sided, contact with the
//    closest point of the rectangle, so edges and corners act too. Slanted hopper walls, boxes, plates.
//  - Axisymmetric segment: the surface swept by the segment (r0, z0)-(r1, z1) of the (rho, z) half-plane around a
//    vertical axis through (cx, cy); two-sided, closest point. Cylinder (r0 = r1), cone frustum (a hopper:
//    r0 = outlet radius at the bottom), annulus or disk (z0 = z1; a disk with r0 = 0 makes a round outlet plate).
// Any wall can be disabled at run time (Simulation::set_wall_enabled), e.g. to open an outlet plate.
// Walls are static (zero velocity). The per-particle wall loop is a switch on the shape (geometry only; the contact
// law is shared with sphere-sphere contacts).
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include "kernel/types.hpp"

namespace demcal::kernel {

struct Wall {
  enum class Shape { Plane, Rectangle, AxiSegment };
  Shape shape = Shape::Plane;
  int material = 0;      ///< material id (Simulation::add_material); its pairs with particle materials apply
  bool enabled = true;   ///< a disabled wall exerts no force (its tangential histories are dropped)
  std::string name;      ///< free label
  // Plane / Rectangle
  Vec3 point = Vec3::Zero();   ///< a point on the plane / the rectangle's centre [m]
  Vec3 normal = Vec3::UnitZ(); ///< unit normal (Plane: towards the particles)
  Vec3 u = Vec3::UnitX();      ///< Rectangle: unit in-plane axis (orthogonal to normal); v = normal x u
  Vec3 v = Vec3::UnitY();
  double half_u = 0, half_v = 0;  ///< Rectangle: half extents along u and v [m]
  // AxiSegment
  double cx = 0, cy = 0;          ///< axis position (axis is vertical, parallel to z) [m]
  double r0 = 0, z0 = 0, r1 = 0, z1 = 0;  ///< segment end points in (rho, z) [m]

  /// Infinite one-sided plane through `point` with unit `normal` pointing towards the particles.
  static Wall plane(const Vec3& point, const Vec3& normal, int material) {
    Wall w; w.shape = Shape::Plane; w.point = point; w.normal = normal.normalized(); w.material = material;
    return w;
  }
  /// Bounded rectangle: centre, normal, in-plane axis u (made orthogonal to normal), half extents along u and v.
  static Wall rectangle(const Vec3& centre, const Vec3& normal, const Vec3& u_axis, double half_u, double half_v,
                        int material) {
    Wall w; w.shape = Shape::Rectangle; w.point = centre; w.normal = normal.normalized();
    w.u = (u_axis - u_axis.dot(w.normal) * w.normal);
    if (w.u.norm() < 1e-12) throw std::invalid_argument("Wall::rectangle: u_axis parallel to normal");
    w.u.normalize(); w.v = w.normal.cross(w.u); w.half_u = half_u; w.half_v = half_v; w.material = material;
    return w;
  }
  /// Rectangle from three corners: a (origin), b (a + edge 1), c (a + edge 2); edges must be orthogonal.
  static Wall rectangle_from_corners(const Vec3& a, const Vec3& b, const Vec3& c, int material) {
    const Vec3 e1 = b - a, e2 = c - a;
    return rectangle(a + 0.5 * (e1 + e2), e1.cross(e2), e1, 0.5 * e1.norm(), 0.5 * e2.norm(), material);
  }
  /// Surface of revolution of the segment (r0, z0)-(r1, z1) around the vertical axis through (cx, cy).
  static Wall axisymmetric(double cx, double cy, double r0, double z0, double r1, double z1, int material) {
    Wall w; w.shape = Shape::AxiSegment; w.cx = cx; w.cy = cy; w.r0 = r0; w.z0 = z0; w.r1 = r1; w.z1 = z1;
    w.material = material;
    return w;
  }
  /// Vertical cylinder of `radius` around (cx, cy), from z_min to z_max (particles inside or outside).
  static Wall cylinder(double cx, double cy, double radius, double z_min, double z_max, int material) {
    return axisymmetric(cx, cy, radius, z_min, radius, z_max, material);
  }
  /// Conical hopper: outlet radius r_outlet at z_outlet, half angle theta [rad] from the vertical axis, up to the
  /// radius r_top (where it joins a cylinder of that radius); top height z_outlet + (r_top - r_outlet)/tan(theta).
  static Wall cone(double cx, double cy, double r_outlet, double z_outlet, double theta, double r_top, int material) {
    if (!(theta > 0 && theta < M_PI / 2)) throw std::invalid_argument("Wall::cone: theta must be in (0, pi/2)");
    return axisymmetric(cx, cy, r_outlet, z_outlet, r_top, z_outlet + (r_top - r_outlet) / std::tan(theta), material);
  }
  /// Horizontal disk of `radius` at height z around (cx, cy) (e.g. a round outlet plate), two-sided.
  static Wall disk(double cx, double cy, double radius, double z, int material) {
    return axisymmetric(cx, cy, 0.0, z, radius, z, material);
  }

  /// Closest-point query for a sphere at p of radius r. If it touches (overlap dn > 0), sets n (unit, from the
  /// wall towards p), dist (distance from p to the contact point) and returns true.
  inline bool contact(const Vec3& p, double r, Vec3& n, double& dn, double& dist) const {
    switch (shape) {
      case Shape::Plane: {
        const double d = (p - point).dot(normal);
        if (d >= r || d <= -r) return false;  // beyond the far side: not a contact of this one-sided plane
        n = normal; dn = r - d; dist = d;
        return true;
      }
      case Shape::Rectangle: {
        const Vec3 q = p - point;
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
      case Shape::AxiSegment: {
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
    }
    return false;
  }
};

}  // namespace demcal::kernel
