// A triangular facet, two-sided: the piece of a mesh wall (a polygonal cone or cylinder, an imported surface). Its
// contact is YADE's (Ig2_Facet_Sphere_ScGeom of YADE 2023.02a, shrinkFactor 0), so that a kernel silo built of the
// same facets as yade_scripts/silo.py meets its walls as YADE's grains do:
//   in the facet's plane, with the origin at the incentre, the edge whose outward normal ne_k gives the largest
//   ne_k . p (p the centre's projection) is taken; below the incircle radius (the projection inside) the contact is
//   with the face (normal along the facet's normal, on the sphere's side); otherwise the projection is moved onto
//   that edge's line and, if it then lies beyond one of the edge's ends, onto that vertex, and the normal runs from
//   that point to the centre.
// Each facet of a mesh is one wall, so a sphere across a shared edge touches both facets, as in YADE (on a flat
// quad split in two triangles, near the diagonal, the two contacts add up: YADE's facets do that too).
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>
#include "kernel/types.hpp"

namespace demcal::kernel {

struct TriangleWall {
  Vec3 centre = Vec3::Zero();  ///< incentre [m] (YADE's facet body position)
  Vec3 normal = Vec3::UnitZ(); ///< unit normal, (v1 - v0) x (v2 - v1) direction
  Vec3 vertex[3];              ///< vertices relative to the incentre [m]
  Vec3 edge_normal[3];         ///< unit in-plane outward normal of edge k (vertex k -> k+1)
  double incircle = 0;         ///< incircle radius [m]

  static TriangleWall from_vertices(const Vec3& a, const Vec3& b, const Vec3& c) {
    TriangleWall t;
    const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm(), perimeter = la + lb + lc;
    const Vec3 e[3] = {b - a, c - b, a - c};
    const Vec3 n = e[0].cross(e[1]);
    const double twice_area = n.norm();
    if (!(twice_area > 1e-12 * perimeter * perimeter) || !std::isfinite(twice_area))
      throw std::invalid_argument("Wall::triangle: the three vertices must span a triangle (they are collinear)");
    t.centre = (la * a + lb * b + lc * c) / perimeter;
    t.normal = n / twice_area;
    const Vec3 v[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      t.vertex[k] = v[k] - t.centre;
      t.edge_normal[k] = e[k].cross(t.normal).normalized();
    }
    t.incircle = twice_area / perimeter;
    return t;
  }

  bool contact(const Vec3& p, double r, Vec3& n, double& dn, double& dist) const {
    const Vec3 cl = p - centre;
    double height = normal.dot(cl);
    Vec3 side = normal;
    if (height < 0) { side = -normal; height = -height; }
    if (height >= r) return false;
    Vec3 cp = cl - height * side;  // the projection onto the plane
    double bm = edge_normal[0].dot(cp);
    int m = 0;
    for (int k = 1; k < 3; ++k) {
      const double b = edge_normal[k].dot(cp);
      if (bm < b) { bm = b; m = k; }
    }
    if (bm < incircle) {  // inside: the face
      n = side; dn = r - height; dist = height;
      return true;
    }
    cp += edge_normal[m] * (incircle - bm);  // onto edge m's line
    if (cp.dot(edge_normal[m == 0 ? 2 : m - 1]) > incircle) cp = vertex[m];
    else if (cp.dot(edge_normal[(m + 1) % 3]) > incircle) cp = vertex[(m + 1) % 3];
    const Vec3 d = cl - cp;
    const double d2 = d.squaredNorm();
    if (d2 >= r * r) return false;
    dist = std::sqrt(d2);
    n = dist > 1e-300 ? Vec3(d / dist) : side;
    dn = r - dist;
    return true;
  }
  /// Axis-aligned bounding box [lo, hi] of the facet (a contact point is always on the closed triangle).
  bool bounds(Vec3& lo, Vec3& hi) const {
    lo = hi = vertex[0];
    for (int k = 1; k < 3; ++k) { lo = lo.cwiseMin(vertex[k]); hi = hi.cwiseMax(vertex[k]); }
    lo += centre; hi += centre;
    return true;
  }
  void append_numbers(std::vector<double>& c) const {
    c.insert(c.end(), {centre.x(), centre.y(), centre.z(), normal.x(), normal.y(), normal.z()});
    for (const Vec3& v : vertex) c.insert(c.end(), {v.x(), v.y(), v.z()});
  }
};

}  // namespace demcal::kernel
