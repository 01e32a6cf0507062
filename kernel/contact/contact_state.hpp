// What a contact law sees of one contact, and what its sub-models hand each other. The kernel builds the geometry and
// kinematics for sphere-sphere and sphere-wall contacts alike; the sub-models (normal, tangential, rolling; one
// header each) are small structs with static inline functions, composed at compile time (contact_law.hpp), so the
// inner loop has no virtual calls.
#pragma once
#include "kernel/types.hpp"

namespace demcal::kernel {

struct ContactGeometry {
  Vec3 n;          ///< unit normal, pointing from j (or the wall) towards i
  double dn;       ///< overlap [m]: > 0 in contact; < 0 is a gap, seen only by laws that act beyond contact
  double r_star;   ///< effective radius R* (1/R* = 1/R_i + 1/R_j; wall: R_i) [m]
  double m_star;   ///< effective mass m* (1/m* = 1/m_i + 1/m_j; wall: m_i; clump member: whole clump's mass) [kg]
  double radius_i; ///< radius of sphere i [m]
  double radius_j; ///< radius of sphere j [m] (wall: 0)
  double lever_i;  ///< distance from i's centre to the contact point (r_i - dn/2) [m]
  double lever_j;  ///< distance from j's centre to the contact point (r_j - dn/2; wall: 0) [m]
};

struct ContactKinematics {
  Vec3 v_rel;   ///< velocity of i's contact point relative to j's (or the wall's) [m/s]
  Vec3 v_i;     ///< velocity of i's centre [m/s] (filled for laws that ask: uses_centre_velocities)
  Vec3 v_j;     ///< velocity of j's centre, or the wall's [m/s] (likewise)
  Vec3 omega_i; ///< angular velocity of i (its body) [rad/s]
  Vec3 omega_j; ///< angular velocity of j (zero for a wall) [rad/s]
  double omega_i_norm = 0; ///< |omega_i|, computed once per sphere and force evaluation (not per contact) [rad/s]
  double omega_j_norm = 0; ///< |omega_j| (zero for a wall) [rad/s]
};

/// What the normal sub-model hands to the tangential and rolling ones: model-neutral quantities (as LAMMPS GRANULAR's
/// GranularModel fields), so that any normal model composes with any tangential or rolling model.
struct NormalState {
  double fn = 0;              ///< normal force along n (positive = repulsive) [N]
  double fn_crit = 0;         ///< the normal load that bounds friction and rolling resistance (|fn| without adhesion) [N]
  double contact_radius = 0;  ///< radius a of the contact area [m] (Hertz: sqrt(R* dn))
  double damp_prefactor = 0;  ///< normal viscous damping coefficient [kg/s]; the tangential damping scales it
  // bonded contacts (models with a bond; zero/false otherwise)
  double shear_adhesion = 0;  ///< the bond's shear strength, added to the friction cap [N]
  bool bonded = false;        ///< the contact carries an intact bond
  bool bond_failed = false;   ///< set by the tangential model when the bond fails in shear this step
};

/// What a law returns: force on i (j gets -force_i), torques about the two sphere centres.
struct ContactResult {
  Vec3 force_i = Vec3::Zero();
  Vec3 torque_i = Vec3::Zero();
  Vec3 torque_j = Vec3::Zero();
};

}  // namespace demcal::kernel
