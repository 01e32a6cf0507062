// Rigid multi-sphere clump templates: member spheres in a body frame, and the mass properties of their union
// (overlapping volume counted once), integrated on a regular grid like YADE's Clump::updateProperties.
#pragma once
#include <vector>
#include "kernel/types.hpp"

namespace demcal::kernel {

struct ClumpTemplate {
  // input (body frame, the "template frame" the user's orientation refers to)
  std::vector<Vec3> positions;   ///< member centres in the template frame [m]
  std::vector<double> radii;     ///< member radii [m]
  // derived by make_clump_template
  double density = 0;            ///< [kg/m^3]
  double volume = 0;             ///< volume of the union of the members [m^3]
  double mass = 0;               ///< density * volume [kg]
  Vec3 com = Vec3::Zero();       ///< centre of mass in the template frame [m]
  Vec3 inertia = Vec3::Zero();   ///< principal moments of inertia about the centre of mass, ascending [kg m^2]
  Quat principal = Quat::Identity();  ///< rotation principal frame -> template frame (columns: principal axes)
  std::vector<Vec3> offsets;     ///< member centres relative to the centre of mass, in the principal frame [m]
  double bounding_radius = 0;    ///< max |offset| + radius [m]
};

/// Builds a template from member spheres (template frame) and the density. Mass, centre of mass and inertia tensor
/// of the union of spheres are integrated at the centres of `cells` grid cells along the longest side of the
/// bounding box (cubic cells); the error is O(h^2)-ish on the surface, well below 0.1 % at the default 240.
ClumpTemplate make_clump_template(const std::vector<Vec3>& positions, const std::vector<double>& radii, double density,
                                  int cells = 240);

/// Scales a template about its centre of mass by `factor`: positions, offsets and radii (x factor), volume and mass
/// (x factor^3), moments of inertia (x factor^5). Cheaper than integrating the larger union again, and exact.
void scale_clump_template(ClumpTemplate& t, double factor);

/// The seed's wheat grain (thesis section 2.3.1): three spheres in a row along x, the middle one r = 1.5 mm at the
/// origin, the end ones r = 1.25 mm at +-1.5 mm; rho = 1430 kg/m^3 unless given.
ClumpTemplate wheat_clump_template(double density = 1430.0, int cells = 240);

}  // namespace demcal::kernel
