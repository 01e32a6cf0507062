// The native DEM simulation: spheres and rigid multi-sphere clumps, analytic walls that can move (a prescribed law or a
// driver's velocity), a contact law composed at compile time from sub-models (kernel/contact/contact_law.hpp), linked-cell + Verlet-skin neighbour list, velocity-Verlet
// integration (clumps: angular momentum + Richardson quaternion update, as LAMMPS/LIGGGHTS fix rigid / multisphere),
// OpenMP. Same input and thread count => bit-identical results (no atomics, fixed-order gathers and sums).
//
// Typical use:
//   Simulation sim;
//   int wheat = sim.add_material({.young = 2 * 3.58e8 * 1.4, .poisson = 0.4, .density = 1430});
//   int steel = sim.add_material({.young = 2 * 8e8 * 1.3, .poisson = 0.3, .density = 7500});
//   sim.set_pair(wheat, wheat, {{.restitution = 0.5}, {.friction = 0.3}, {.rolling_friction = 0.01}});
//   sim.set_pair(wheat, steel, {{.restitution = 0.6}, {.friction = 0.25}, {.rolling_friction = 0.01}});
//   int grain = sim.add_clump_template(wheat_clump_template());
//   sim.add_wall(Wall::cylinder(0, 0, 0.0525, 0.0, 0.4, steel));
//   sim.add_clump(grain, wheat, {0, 0, 0.1}, Quat::Identity());
//   sim.set_timestep(0.3 * sim.rayleigh_timestep());
//   sim.step(1000);
#pragma once
#include <bit>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "kernel/clump.hpp"
#include "kernel/clump_rotation_scheme.hpp"
#include "kernel/contact/contact_law.hpp"
#include "kernel/material.hpp"
#include "kernel/neighbor.hpp"
#include "kernel/types.hpp"
#include "kernel/wall_grid.hpp"
#include "kernel/walls.hpp"

namespace demcal::kernel {

/// A snapshot of one body (a single sphere or a clump), as returned by BasicSimulation::body().
struct BodyState {
  BodyId id = 0;                        ///< stable identity (assigned at insertion, never reused)
  bool is_clump = false;                ///< false: a single sphere
  int material = 0;                     ///< material id
  int clump_template = -1;              ///< template id for clumps, -1 for spheres
  double radius = 0;                    ///< sphere radius; for clumps the template's bounding radius [m]
  double mass = 0;                      ///< [kg]
  Vec3 position = Vec3::Zero();         ///< centre of mass [m]
  Vec3 velocity = Vec3::Zero();         ///< velocity of the centre of mass [m/s]
  Vec3 angular_velocity = Vec3::Zero(); ///< world frame [rad/s]
  Quat orientation = Quat::Identity();  ///< template frame -> world (spheres: identity, not tracked)
};

/// A snapshot of one sphere (a single sphere or a clump member), for output/visualisation.
struct SphereState {
  Vec3 position = Vec3::Zero();  ///< [m]
  Vec3 velocity = Vec3::Zero();  ///< velocity of the sphere's centre [m/s]
  double radius = 0;             ///< [m]
  int material = 0;
  std::size_t body = 0;          ///< index of its body (valid until the next add/remove)
};

/// What remove_bodies_if removed.
struct RemovalResult {
  std::size_t count = 0;  ///< number of bodies removed
  double mass = 0;        ///< their total mass [kg]
};

template <class Law>
class BasicSimulation {
 public:
  /// The per-material-pair inputs of the law: its sub-models' fields side by side (kernel/contact/).
  using PairParams = typename Law::Params;
  BasicSimulation();

  // ---------------------------------------------------------------- setup
  /// Adds a material; returns its id (0, 1, ...). Validated: E > 0, -1 < nu < 0.5, density >= 0.
  int add_material(const Material& m);
  const Material& material(int id) const { return materials_.at(id); }
  /// Sets the properties of the (unordered) material pair (a, b). Every pair of materials that can meet (particle-
  /// particle, particle-wall) must be set before stepping, or step() throws naming the pair.
  /// The fields are validated here (std::invalid_argument naming the field).
  void set_pair(int a, int b, const PairParams& p);
  /// Gravity acceleration [m/s^2] (default (0, 0, -9.81)).
  void set_gravity(const Vec3& g) { gravity_ = g; }
  const Vec3& gravity() const { return gravity_; }
  /// Time step [s] (> 0; no default: use e.g. 0.2-0.4 * rayleigh_timestep()).
  void set_timestep(double dt);
  double timestep() const { return dt_; }
  /// Smallest Rayleigh time step over the spheres present (pi R sqrt(rho/G)/(0.1631 nu + 0.8766)) [s]; 0 if none.
  double rayleigh_timestep() const;
  /// Verlet skin [m] (default: 0.2 * the mean sphere radius at the first step if never set). The neighbour list is
  /// rebuilt when a sphere has moved more than skin/2 since the last build.
  void set_skin(double skin);
  double skin() const { return skin_; }
  /// Number of OpenMP threads (default 1; <= 0: omp_get_max_threads()). The results do not depend on it: every
  /// parallel loop writes disjoint data and every sum runs in a fixed order (tested bit for bit).
  void set_threads(int n);
  int threads() const { return threads_; }
  /// Loops run on one thread while there are fewer than this many spheres (default 2000): below it, OpenMP barriers
  /// cost more than they save (much more on an oversubscribed machine). 0: always parallel (tests).
  void set_min_parallel(std::size_t n) { min_parallel_ = n; }
  /// Every this many neighbour-list builds (the first included) the spheres are renumbered in linked-cell order, so
  /// that neighbours sit close in memory (randomly inserted grains otherwise miss the cache). 0: never. Sphere
  /// indices (sphere(k), sphere_positions()) change then; body indices and ids do not. Default 10.
  void set_reorder_every(int builds) { reorder_every_ = builds; }

  /// Adds a wall; returns its id.
  int add_wall(const Wall& w);
  /// Enables/disables a wall (e.g. opens the outlet plate). A disabled wall exerts no force.
  void set_wall_enabled(int id, bool enabled);
  /// Forgets every contact's memory, of sphere pairs and wall contacts alike (tangential springs, a JKR contact's
  /// touched flag): each contact goes on as if it had just formed. A bed imported into another code starts so (YADE
  /// creates its interactions afresh); demcal silo --forget-contact-history measures what that changes.
  void forget_contact_history();
  /// Goes on as a leapfrog code started from this state goes on, YADE importing the bed (yade_scripts/silo.py):
  /// every contact forgets its past (forget_contact_history); the next force evaluation advances the fresh contacts'
  /// springs by one step, as YADE's first InteractionLoop does on new interactions; the next step kicks the velocities
  /// by a whole step, not half, as leapfrog takes the state's on-step velocities for its half-step ones. With YADE's
  /// law, clump rotation and walls the kernel then follows YADE's own run of the state until chaos parts them
  /// (tests/kernel/test_silo_yade_trajectory.cpp). Both effects are spent by the next step() (not saved in a state).
  void restart_as_imported_leapfrog();
  /// YADE's non-viscous local damping (NewtonIntegrator(damping = d)), d in [0, 1); default 0 (none). For matching
  /// YADE's quasi-static tests; it is not a physical dissipation.
  void set_local_damping(double damping);
  double local_damping() const { return local_damping_; }
  /// How clumps turn: the kernel's Richardson quaternion update (default; LAMMPS/LIGGGHTS) or YADE's aspherical
  /// leapfrog (kernel/clump_rotation_yade.hpp), for cross-checks that remove the integrators' difference. A setting
  /// like the damping: not part of the saved state. (A force refresh after a setting changed between steps takes
  /// omega back to the half step from L with the new orientation, as the kernel's own scheme does; YADE's step had
  /// used the old one's body frame: O(dt) apart in omega for that one evaluation. The silo never refreshes so.)
  void set_clump_rotation(ClumpRotation scheme) { clump_rotation_ = scheme; }
  ClumpRotation clump_rotation() const { return clump_rotation_; }
  /// Laws with bonds (YadeCohesiveFrictional): the contacts acting at the next force evaluation are bonded, where
  /// their pair has a cohesion (YADE's setCohesionNow). Forces are evaluated again at the next step() without
  /// advancing time (as after any state change).
  void bond_contacts_now()
    requires Law::has_bonds;

  /// Laws with bonds: how many particle-particle contacts are bonded now (at the last force evaluation).
  std::size_t bonded_contact_count() const
    requires Law::has_bonds;

  /// Sets the velocity [m/s] of a wall without a prescribed motion law (a driver's servo or a shear frame): it moves by
  /// velocity * dt each step from then on. Throws for a wall that follows a law.
  void set_wall_velocity(int id, const Vec3& velocity);
  const Wall& wall(int id) const { return walls_.at(id); }
  std::size_t num_walls() const { return walls_.size(); }
  /// Total contact force exerted BY the particles ON wall `id` at the last force evaluation [N].
  Vec3 wall_force(int id) const;

  /// Registers a clump template (kernel/clump.hpp); returns its id. Its mass and inertia are used as they are
  /// (make the template with the density of the material you will give the clumps).
  int add_clump_template(const ClumpTemplate& t);
  const ClumpTemplate& clump_template(int id) const { return templates_.at(id); }

  /// Adds a single sphere; returns its id. position [m], radius [m] > 0, velocity [m/s], omega [rad/s].
  BodyId add_sphere(const Vec3& position, double radius, int material, const Vec3& velocity = Vec3::Zero(),
                    const Vec3& omega = Vec3::Zero());
  /// Adds a rigid clump of template `tmpl`: its centre of mass at `com` [m], `orientation` rotating the template
  /// frame into the world, velocity of the centre of mass [m/s], angular velocity omega [rad/s] (world frame).
  BodyId add_clump(int tmpl, int material, const Vec3& com, const Quat& orientation = Quat::Identity(),
                   const Vec3& velocity = Vec3::Zero(), const Vec3& omega = Vec3::Zero());

  /// Scales every particle about its own centre of mass by `factor` (> 0): sphere radii, clump members' offsets and
  /// radii, masses (factor^3) and moments of inertia (factor^5); velocities and angular velocities are kept, and so are
  /// the contact histories. YADE's utils.growParticles(factor, updateMass = True), with which a packing procedure grows
  /// a loose cloud in place. The clump templates are scaled with them (every body grows alike).
  void scale_particles(double factor);

  // ---------------------------------------------------------------- run
  /// Advances n steps of the time step (velocity Verlet; forces at half-step velocities, as LAMMPS/LIGGGHTS).
  void step(long n = 1);
  /// The same, asking `should_stop` after every step but the last: at a yes it returns the steps done (fewer than n)
  /// with the state between two steps of the loop: velocities at the half step, the next step's first half kick still
  /// owed (velocity Verlet fuses it with the last step's second one). Only save_state() and step() are meant then: a
  /// later step() (in this object or one that loaded the state) pays the fused kick first, so that a run stopped and
  /// continued takes exactly the uninterrupted run's steps, bit for bit. A stop within a long stretch (a silo's record
  /// interval of millions of steps at 10^6 grains) therefore need not wait for its end.
  long step(long n, const std::function<bool()>& should_stop);
  /// Whether a stopped step(n, should_stop) left the velocities at the half step (see there).
  bool between_steps() const { return half_kick_owed_; }
  double time() const { return time_; }           ///< simulated time [s]
  long steps_done() const { return steps_; }      ///< steps taken so far

  // ---------------------------------------------------------------- state
  /// Bodies are indexed 0..num_bodies()-1 in insertion order; removal compacts (indices shift, ids stay).
  std::size_t num_bodies() const { return body_ref_.size(); }
  BodyState body(std::size_t i) const;
  /// Sets the velocity [m/s] and angular velocity [rad/s, world] of body i.
  void set_body_velocity(std::size_t i, const Vec3& velocity, const Vec3& omega);
  /// Exact removals (default off): the pair loop then records each pair's torque on i (a few per cent of its time on
  /// the peer case), which a removal needs to take a body's contacts out of its neighbours' loads. A case that removes
  /// bodies as it runs (the silo's discharge) turns them on: evaluating every force again after a removal moves the
  /// whole bed a little (kernel/README.md).
  void set_exact_removal(bool on) { exact_removal_ = on; pair_torques_i_known_ = false; }
  /// Removes every body for which pred(state) is true; returns how many and their mass. With exact removals on
  /// (set_exact_removal) the rest goes on as if they had gone before the last force evaluation (their contacts' loads
  /// and the half kick those gave taken out); off, the forces of the rest are evaluated again.
  RemovalResult remove_bodies_if(const std::function<bool(const BodyState&)>& pred);

  /// Spheres (single ones and clump members): 0..num_spheres()-1.
  std::size_t num_spheres() const { return x_.size(); }
  SphereState sphere(std::size_t k) const;
  const std::vector<Vec3>& sphere_positions() const { return x_; }  ///< all sphere centres [m]
  const std::vector<double>& sphere_radii() const { return r_; }    ///< all sphere radii [m]

  /// The spheres touching wall `id` at the last force evaluation (a sphere keeps up to 3 wall contacts with history;
  /// contacts beyond that act but are not listed), in ascending sphere index.
  std::vector<std::size_t> wall_contact_spheres(int id) const;
  /// YADE's utils.unbalancedForce(): the mean over bodies of |contact force + m g| divided by the mean magnitude of
  /// the contact forces (particle pairs and wall contacts acting at the last force evaluation), both before local
  /// damping. A quasi-static packing has a small value (YADE's scripts wait for 0.01-0.05). 0 without contacts.
  double unbalanced_force() const;

  /// Translational + rotational kinetic energy of all bodies [J].
  double kinetic_energy() const;
  double rotational_kinetic_energy() const;
  /// Potential energy in gravity, -sum m g.x [J].
  double potential_energy() const;
  /// Total linear momentum [kg m/s] and angular momentum about `origin` [kg m^2/s].
  Vec3 linear_momentum() const;
  Vec3 angular_momentum(const Vec3& origin = Vec3::Zero()) const;
  double total_mass() const;

  // ---------------------------------------------------------------- checkpoint
  /// Writes the whole dynamic state (bodies, contact histories, neighbour list, wall switches, time, step count) so
  /// that load_state() continues bit for bit as if the run had never stopped. The configuration (materials, pairs,
  /// clump templates, walls) is not restored: set it up the same way before load_state(); its numbers are written
  /// and checked. Thread count and parallel threshold are not part of the state (results do not depend on them).
  void save_state(std::ostream& os) const;
  /// Replaces the dynamic state by one save_state() wrote. Throws std::runtime_error naming `source` and what
  /// differs when the configuration set up here is not the one the state was saved with, or the data are cut short.
  void load_state(std::istream& is, const std::string& source);

  // ---------------------------------------------------------------- diagnostics
  /// Sphere pairs (i < j) overlapping now, found through the neighbour list (builds it if needed).
  std::vector<std::pair<std::int32_t, std::int32_t>> contact_pairs();
  /// The same by brute force (O(n^2); tests).
  std::vector<std::pair<std::int32_t, std::int32_t>> contact_pairs_brute_force() const;
  std::size_t neighbor_builds() const { return nl_.num_builds(); }
  std::size_t neighbor_pairs() const { return nl_.num_pairs(); }
  /// Approximate heap memory of the simulation's arrays [bytes].
  std::size_t memory_bytes() const;

 private:
  // 3: contact histories of any size, walls move; 4: the skin spent by growth; 5: stopped between two steps (the
  // half kick owed). 3 and 4 are still read.
  static constexpr const char* kStateFormat = "demcal-kernel-state/5";
  void prepare();
  void compute_forces(bool rebuild, double dt_history);
  // compute_forces' steps around its pair and wall loop (which stays one loop: as functions, even inlined, its parts
  // made the peer case 2.4-6.5 % slower, stop 52)
  void prepare_lists(bool rebuild);  // the neighbour list rebuilt if asked or stale, a loaded state's wall lists
  void add_partner_loads();          // each pair's load on its j (an `omp for` in compute_forces' region)
  void sum_clump_loads();            // each clump's force and torque (likewise)
  bool kick_drift(double kick);
  void kick(double sign = 1.0);  // the second half kick of velocity Verlet; -1 takes it back
  void refresh_forces();         // forces of the current state after a change (step() calls it)
  void update_members(std::size_t c, const Mat3& R, bool positions);  // R: the clump's rotation matrix
  void rebuild_body_index();  // the body <-> sphere maps and the members' offsets, after cmem_ or a template changed
  // Every per-sphere array (with its entries per sphere) and every per-clump array, listed once: renumbering and
  // removal apply the same permutation or compaction to all of them.
  template <class F>
  void for_each_sphere_array(F&& f) {
    f(x_, 1); f(v_, 1); f(w_, 1); f(f_, 1); f(t_, 1);
    f(r_, 1); f(mass_, 1); f(inv_mass_, 1); f(inv_inertia_, 1); f(mat_, 1); f(clump_, 1);
    f(wall_slot_id_, kWallSlots); f(wall_slot_s_, kWallSlots * kHist); f(wall_slot_f_, kWallSlots);
  }
  template <class F>
  void for_each_clump_array(F&& f) {
    f(cx_); f(cv_); f(cw_); f(cL_); f(cI_); f(cF_); f(cT_); f(cq_); f(cm_); f(ctmpl_); f(cmat_);
  }
  std::vector<double> configuration_numbers() const;  // what load_state() checks
  void reorder_spheres();
  void rebuild_neighbors();  // the neighbour list and the wall candidates, always together
  void find_wall_candidates();
  void move_walls();  // to the current time: displacement and velocity over the step
  void apply_local_damping();
  bool walls_left_reach() const;  // a wall moved more than skin/2 since the last neighbour build

  // materials
  std::vector<Material> materials_;
  std::vector<PairParams> pair_props_;        // nm * nm
  std::vector<char> pair_set_;
  std::vector<typename Law::Coeffs> coeffs_;  // nm * nm, ordered (row: sphere i's material; built in prepare)
  int nm_coeffs_ = 0;
  double law_reach_ = 0;  // how far beyond touching the law can act for the radii present [m] (prepare)
  bool list_from_state_ = false;  // the neighbour list was loaded (load_state) and not yet prepared for
  std::vector<Wall> walls_;
  std::vector<Vec3> wall_disp_built_;  // each wall's displacement at the last neighbour build
  bool walls_move_ = false;            // some wall has a motion law or a velocity
  double local_damping_ = 0;           // YADE's non-viscous damping coefficient
  ClumpRotation clump_rotation_ = ClumpRotation::richardson;
  bool bond_next_evaluation_ = false;  // bond the contacts of the next force evaluation
  std::vector<ClumpTemplate> templates_;

  // per sphere (structure of arrays)
  std::vector<Vec3> x_, v_, w_, f_, t_;
  std::vector<double> r_, mass_, inv_mass_, inv_inertia_;  // mass_: body mass (m* of a clump member); inv_*: spheres
  std::vector<std::int32_t> mat_, clump_;                  // clump_: clump index or -1
  static constexpr int kWallSlots = 3;                      // wall contacts with history per sphere
  static constexpr int kHist = Law::history_size;           // doubles of contact history per contact
  std::vector<std::int32_t> wall_slot_id_;                  // kWallSlots per sphere, -1 empty
  std::vector<double> wall_slot_s_;                         // kWallSlots * kHist per sphere: history
  std::vector<Vec3> wall_slot_f_;                           // kWallSlots per sphere: force on the sphere
  struct PairLoad {
    Vec3 force_i, torque_j;  // one pair's force on i and torque on j, side by side for the gather's one read
  };
  std::vector<PairLoad> pair_load_;                         // per pair (written and gathered in compute_forces)
  // Each pair's torque on i, recorded when exact removals are on (set_exact_removal: a removal then takes a removed
  // body's contacts out of its neighbours' loads); known: they are the last evaluation's (false after load_state)
  bool exact_removal_ = false;
  std::vector<Vec3> pair_torque_i_;
  bool pair_torques_i_known_ = false;
  std::vector<double> omega_norm_;                          // |w_| per sphere, for the rolling torques
  bool omega_norm_fresh_ = false;                           // kick_drift filled omega_norm_ for the current w_
  static constexpr int kMaxWallCandidates = 64;             // walls tracked per sphere (bit mask)
  // The lowest wall index left in a candidate mask, taken out of it; kMaxWallCandidates (>= any tracked wall count)
  // once the mask is empty.
  static int next_wall_candidate(std::uint64_t& mask) {
    if (mask == 0) return kMaxWallCandidates;
    const int w = std::countr_zero(mask);
    mask &= mask - 1;
    return w;
  }
  std::vector<std::uint64_t> wall_cand_;                    // per sphere: walls within reach at the last build
  // Past kMaxWallCandidates walls (the facets of a mesh wall) the candidates are a list per sphere instead (CSR, in
  // ascending wall order). Not saved in a state: derived again from the build positions after a load.
  std::vector<std::uint32_t> wall_list_row_;
  std::vector<std::int32_t> wall_list_;
  bool wall_lists_stale_ = false;                           // a state was loaded: derive the lists before the next use
  WallGrid wall_grid_;                                      // the candidate searches' broad phase (scratch)
  // remove_bodies_if: the loads of the contacts with the spheres about to go, out of their neighbours' forces and
  // the last half kick (forces stay valid)
  void take_out_removed_contacts(const std::vector<char>& drop_sphere, const std::vector<char>& drop_clump);
  // remove_bodies_if's steps: the spheres and clumps of the bodies that go, the new index of each kept item (-1 for
  // one that goes), and the per-sphere, per-clump and per-body arrays compacted over the kept ones
  void mark_removed_spheres(const std::vector<char>& drop_body, std::vector<char>& drop_sphere,
                            std::vector<char>& drop_clump) const;
  static std::vector<std::int32_t> kept_numbering(const std::vector<char>& drop);
  void compact_spheres(const std::vector<char>& drop_sphere, const std::vector<std::int32_t>& c_old2new);
  void compact_clumps(const std::vector<char>& drop_clump, const std::vector<std::int32_t>& s_old2new);
  void compact_bodies(const std::vector<char>& drop_body, const std::vector<std::int32_t>& s_old2new,
                      const std::vector<std::int32_t>& c_old2new);
  void find_wall_candidate_lists(const std::vector<Vec3>& centres, double reach,
                                 const std::vector<Vec3>& wall_displacement);
  // wall_grid_ for the walls at these displacements from where they were built, spheres reaching r + reach
  void build_wall_grid(const std::vector<Vec3>& wall_displacement, double reach);

  // per clump
  std::vector<Vec3> cx_, cv_, cw_, cL_, cI_, cF_, cT_;
  std::vector<Quat> cq_;  // principal frame -> world
  std::vector<double> cm_;
  std::vector<std::int32_t> ctmpl_, cmat_;
  std::vector<std::uint32_t> cmem_start_, cmem_;  // member sphere indices (CSR)
  // the template offset of each cmem_ entry (body frame), side by side: a clump update reads them contiguously
  // instead of through its template (each clump of a spread of sizes has its own, scattered in memory)
  std::vector<Vec3> cmem_offset_;

  // bodies
  std::vector<std::int32_t> body_ref_;  // >= 0: sphere index; < 0: -(clump + 1)
  std::vector<BodyId> body_id_;
  std::vector<std::uint32_t> sphere_body_, clump_body_;  // inverse maps
  BodyId next_id_ = 1;

  NeighborList nl_;
  Vec3 gravity_ = Vec3(0, 0, -9.81);
  double dt_ = 0, time_ = 0, skin_ = -1;
  long steps_ = 0;
  int threads_ = 1;
  int reorder_every_ = 10;
  std::size_t builds_since_reorder_ = 0;
  std::size_t min_parallel_ = 2000;
  int nt() const { return x_.size() >= min_parallel_ ? threads_ : 1; }
  bool forces_valid_ = false, prepared_ = false;
  // The change that invalidated the forces leaves the state (positions, velocities) as it was: the last half kick,
  // taken with the forces before the change, is taken again with the new ones (see refresh_forces).
  bool rekick_on_refresh_ = false;
  bool import_spring_step_pending_ = false;  // restart_as_imported_leapfrog: the refresh advances the springs
  bool half_kick_owed_ = false;  // step(n, should_stop) stopped inside its loop: the next step's kick is fused
  bool import_full_kick_pending_ = false;    // restart_as_imported_leapfrog: the next step's first kick is whole
};

extern template class BasicSimulation<HertzMindlinEdem>;
extern template class BasicSimulation<HertzMindlin>;
extern template class BasicSimulation<JkrMindlinEdem>;
extern template class BasicSimulation<YadeCohesiveFrictional>;

/// The seed's model: Hertz-Mindlin (no slip) + EDEM constant directional torque rolling friction.
using Simulation = BasicSimulation<HertzMindlinEdem>;
/// The seed's model with JKR adhesion (cohesive powders).
using CohesiveSimulation = BasicSimulation<JkrMindlinEdem>;
/// YADE's shear-box laws (linear, fragile bonds) for cross-checks with YADE.
using YadeLawSimulation = BasicSimulation<YadeCohesiveFrictional>;

}  // namespace demcal::kernel
