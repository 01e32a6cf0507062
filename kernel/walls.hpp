// Walls: one type per shape (kernel/walls/: PlaneWall, RectangleWall, BoxWall, AxisymmetricWall for cylinders, cones,
// disks, TriangleWall for the facets of a mesh), each with its closest-point query; a Wall adds what every wall has: a material, an on/off switch, and a
// translation (displacement and velocity) that follows a prescribed law (kernel/walls/wall_motion.hpp) or a velocity
// a driver sets. Contacts see the wall's velocity. The per-particle wall loop visits the shape through std::visit
// (a jump table, like the switch it replaced); the contact law is shared with sphere-sphere contacts.
#pragma once
#include <memory>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>
#include "kernel/types.hpp"
#include "kernel/walls/axisymmetric_wall.hpp"
#include "kernel/walls/box_wall.hpp"
#include "kernel/walls/plane_wall.hpp"
#include "kernel/walls/rectangle_wall.hpp"
#include "kernel/walls/triangle_wall.hpp"
#include "kernel/walls/wall_motion.hpp"

namespace demcal::kernel {

struct Wall {
  using Shape = std::variant<PlaneWall, RectangleWall, BoxWall, AxisymmetricWall, TriangleWall>;
  Shape shape;
  int material = 0;      ///< material id (Simulation::add_material); its pairs with particle materials apply
  bool enabled = true;   ///< a disabled wall exerts no force (its tangential histories are dropped)
  std::string name;      ///< free label
  /// Prescribed motion; null: the wall moves at `velocity`, which only a driver changes (set_wall_velocity).
  std::shared_ptr<const WallMotion> motion;
  Vec3 displacement = Vec3::Zero();  ///< translation from the built position now [m] (dynamic state)
  Vec3 velocity = Vec3::Zero();      ///< velocity over the last step [m/s] (dynamic state)

  /// Closest-point query for a sphere at p of radius r against the wall where it is now. If it touches (overlap
  /// dn > 0), sets n (unit, from the wall towards p), dist (distance from p to the contact point) and returns true.
  bool contact(const Vec3& p, double r, Vec3& n, double& dn, double& dist) const {
    const Vec3 q = p - displacement;
    return std::visit([&](const auto& s) { return s.contact(q, r, n, dn, dist); }, shape);
  }
  /// The axis-aligned box [lo, hi] that holds every point of the wall a contact can be with, the wall where it was
  /// built (add its displacement); false for an unbounded wall (a plane). A sphere centre farther than r from the
  /// box touches nothing of the wall (the broad phase of the wall candidates, kernel/wall_grid.hpp).
  bool built_bounds(Vec3& lo, Vec3& hi) const {
    return std::visit([&](const auto& s) { return s.bounds(lo, hi); }, shape);
  }
  /// The shape's kind and numbers, the material and the motion law (the checkpoint's configuration check).
  void append_numbers(std::vector<double>& c) const {
    c.insert(c.end(), {double(shape.index()), double(material)});
    std::visit([&](const auto& s) { s.append_numbers(c); }, shape);
    if (motion) motion->append_numbers(c); else c.push_back(0.0);
  }
  /// The same wall moving on `law`.
  Wall moving(std::shared_ptr<const WallMotion> law) const { Wall w = *this; w.motion = std::move(law); return w; }

  /// Infinite one-sided plane through `point` with unit `normal` pointing towards the particles.
  static Wall plane(const Vec3& point, const Vec3& normal, int material) {
    return make(PlaneWall{point, normal.normalized()}, material);
  }
  /// Bounded rectangle: centre, normal, in-plane axis u (made orthogonal to normal), half extents along u and v.
  static Wall rectangle(const Vec3& centre, const Vec3& normal, const Vec3& u_axis, double half_u, double half_v,
                        int material) {
    RectangleWall r;
    r.centre = centre;
    r.normal = normal.normalized();
    r.u = u_axis - u_axis.dot(r.normal) * r.normal;
    if (r.u.norm() < 1e-12) throw std::invalid_argument("Wall::rectangle: u_axis parallel to normal");
    r.u.normalize();
    r.v = r.normal.cross(r.u);
    r.half_u = half_u;
    r.half_v = half_v;
    return make(r, material);
  }
  /// Rectangle from three corners: a (origin), b (a + edge 1), c (a + edge 2); edges must be orthogonal.
  static Wall rectangle_from_corners(const Vec3& a, const Vec3& b, const Vec3& c, int material) {
    const Vec3 e1 = b - a, e2 = c - a;
    return rectangle(a + 0.5 * (e1 + e2), e1.cross(e2), e1, 0.5 * e1.norm(), 0.5 * e2.norm(), material);
  }
  /// Triangular facet with vertices a, b, c (two-sided; YADE's facet contact: kernel/walls/triangle_wall.hpp).
  static Wall triangle(const Vec3& a, const Vec3& b, const Vec3& c, int material) {
    return make(TriangleWall::from_vertices(a, b, c), material);
  }
  /// Solid axis-aligned box between corners lo and hi.
  static Wall box(const Vec3& lo, const Vec3& hi, int material) {
    if (!((hi - lo).minCoeff() > 0)) throw std::invalid_argument("Wall::box: hi must exceed lo along every axis");
    return make(BoxWall{0.5 * (lo + hi), 0.5 * (hi - lo)}, material);
  }
  /// Surface of revolution of the segment (r0, z0)-(r1, z1) around the vertical axis through (cx, cy).
  static Wall axisymmetric(double cx, double cy, double r0, double z0, double r1, double z1, int material) {
    return make(AxisymmetricWall{cx, cy, r0, z0, r1, z1}, material);
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

 private:
  static Wall make(Shape s, int material) {
    Wall w;
    w.shape = std::move(s);
    w.material = material;
    return w;
  }
};

}  // namespace demcal::kernel
