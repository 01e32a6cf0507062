// Implementation of BasicSimulation<Law>; included only by the .cpp files that instantiate a law
// (kernel/simulation.cpp). See simulation.hpp for the interface.
#pragma once
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>

#include "kernel/clump_rotation.hpp"
#include "kernel/clump_rotation_yade.hpp"
#include "kernel/state_io.hpp"

#include "kernel/simulation.hpp"

namespace demcal::kernel {

namespace detail {
/// 1/I per principal moment (0 for a zero moment: a degenerate axis takes no angular velocity).
inline Vec3 inverse_moments(const Vec3& I) {
  return Vec3(I.x() > 0 ? 1.0 / I.x() : 0.0, I.y() > 0 ? 1.0 / I.y() : 0.0, I.z() > 0 ? 1.0 / I.z() : 0.0);
}
}  // namespace detail

template <class Law>
BasicSimulation<Law>::BasicSimulation() {
  threads_ = 1;
  nl_.set_history_size(kHist);
}

template <class Law>
int BasicSimulation<Law>::add_material(const Material& m) {
  if (!(m.young > 0)) throw std::invalid_argument("material young must be > 0, got " + std::to_string(m.young));
  if (!(m.poisson > -1 && m.poisson < 0.5))
    throw std::invalid_argument("material poisson must be in (-1, 0.5), got " + std::to_string(m.poisson));
  if (!(m.density >= 0)) throw std::invalid_argument("material density must be >= 0, got " + std::to_string(m.density));
  const int nm_old = int(materials_.size());
  materials_.push_back(m);
  const int nm = nm_old + 1;
  std::vector<PairParams> pp(nm * nm);
  std::vector<char> ps(nm * nm, 0);
  for (int a = 0; a < nm_old; ++a)
    for (int b = 0; b < nm_old; ++b) {
      pp[a * nm + b] = pair_props_[a * nm_old + b];
      ps[a * nm + b] = pair_set_[a * nm_old + b];
    }
  pair_props_ = std::move(pp);
  pair_set_ = std::move(ps);
  prepared_ = false;
  return nm - 1;
}

template <class Law>
void BasicSimulation<Law>::set_pair(int a, int b, const PairParams& p) {
  const int nm = int(materials_.size());
  if (a < 0 || b < 0 || a >= nm || b >= nm) throw std::invalid_argument("set_pair: unknown material id");
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("set_pair(" + std::to_string(a) + ", " + std::to_string(b) + "): " + e.what());
  }
  pair_props_[a * nm + b] = pair_props_[b * nm + a] = p;
  pair_set_[a * nm + b] = pair_set_[b * nm + a] = 1;
  prepared_ = false;
}

template <class Law>
void BasicSimulation<Law>::set_timestep(double dt) {
  if (!(dt > 0)) throw std::invalid_argument("set_timestep: dt must be > 0");
  dt_ = dt;
}

template <class Law>
double BasicSimulation<Law>::rayleigh_timestep() const {
  double best = 0;
  for (std::size_t k = 0; k < r_.size(); ++k) {
    const Material& m = materials_[mat_[k]];
    const double t = kernel::rayleigh_timestep(r_[k], m.density, m.shear_modulus(), m.poisson);
    if (best == 0 || t < best) best = t;
  }
  return best;
}

template <class Law>
void BasicSimulation<Law>::set_skin(double skin) {
  if (!(skin > 0)) throw std::invalid_argument("set_skin: skin must be > 0");
  skin_ = skin;
  nl_.invalidate();
}

template <class Law>
void BasicSimulation<Law>::set_threads(int n) {
  threads_ = n > 0 ? n : omp_get_max_threads();
}

template <class Law>
int BasicSimulation<Law>::add_wall(const Wall& w) {
  if (w.material < 0 || w.material >= int(materials_.size())) throw std::invalid_argument("add_wall: unknown material");
  walls_.push_back(w);
  nl_.invalidate();  // the wall candidates are found at the neighbour build
  prepared_ = false;
  forces_valid_ = false;
  rekick_on_refresh_ = false;  // (the state itself changed)
  return int(walls_.size()) - 1;
}

template <class Law>
void BasicSimulation<Law>::set_wall_enabled(int id, bool enabled) {
  walls_.at(id).enabled = enabled;
  forces_valid_ = false;
  rekick_on_refresh_ = false;  // (the state itself changed)
}

template <class Law>
void BasicSimulation<Law>::forget_contact_history() {
  std::fill(nl_.hist.begin(), nl_.hist.end(), 0.0);
  std::fill(wall_slot_s_.begin(), wall_slot_s_.end(), 0.0);
  forces_valid_ = false;
  rekick_on_refresh_ = false;  // (the state itself changed: the forces of the next step are those of fresh contacts)
}

template <class Law>
void BasicSimulation<Law>::restart_as_imported_leapfrog() {
  forget_contact_history();
  import_spring_step_pending_ = true;
  import_full_kick_pending_ = true;
}

template <class Law>
void BasicSimulation<Law>::set_wall_velocity(int id, const Vec3& velocity) {
  Wall& w = walls_.at(id);
  if (w.motion) throw std::logic_error("set_wall_velocity: wall " + std::to_string(id) + " follows a motion law");
  if (!velocity.allFinite()) throw std::invalid_argument("set_wall_velocity: the velocity must be finite");
  w.velocity = velocity;
  if (!Law::forces_depend_on_velocity) return;  // the forces of this state are the same: nothing to refresh
  if (forces_valid_) rekick_on_refresh_ = true;
  forces_valid_ = false;
}

template <class Law>
void BasicSimulation<Law>::move_walls() {
  // The displacement at the current time; the velocity contacts see is the mean over the step just taken, so the
  // tangential springs advance by exactly the wall's displacement (the particles' velocities are mid-step too).
  for (Wall& w : walls_) {
    if (w.motion) {
      const Vec3 d = w.motion->displacement(time_ + dt_);
      w.velocity = (d - w.displacement) / dt_;
      w.displacement = d;
    } else if (w.velocity != Vec3::Zero()) {
      w.displacement += dt_ * w.velocity;
    }
  }
}

template <class Law>
bool BasicSimulation<Law>::walls_left_reach() const {
  if (!walls_move_ || wall_disp_built_.size() != walls_.size()) return walls_move_;
  const double lim2 = 0.25 * skin_ * skin_;
  for (std::size_t k = 0; k < walls_.size(); ++k)
    if ((walls_[k].displacement - wall_disp_built_[k]).squaredNorm() > lim2) return true;
  return false;
}

template <class Law>
Vec3 BasicSimulation<Law>::wall_force(int id) const {
  // Summed when asked, in sphere order, from the forces each sphere keeps per wall contact: a serial pass over every
  // sphere in each step would cost every step, for a value most runs never read.
  if (id < 0 || id >= int(walls_.size())) throw std::out_of_range("wall_force: no wall " + std::to_string(id));
  Vec3 f = Vec3::Zero();
  for (std::size_t i = 0; i < x_.size(); ++i)
    for (int k = 0; k < kWallSlots; ++k)
      if (wall_slot_id_[i * kWallSlots + k] == id) f -= wall_slot_f_[i * kWallSlots + k];
  return f;
}

template <class Law>
int BasicSimulation<Law>::add_clump_template(const ClumpTemplate& t) {
  if (t.offsets.empty() || !(t.mass > 0)) throw std::invalid_argument("add_clump_template: use make_clump_template");
  templates_.push_back(t);
  return int(templates_.size()) - 1;
}

template <class Law>
BodyId BasicSimulation<Law>::add_sphere(const Vec3& position, double radius, int material, const Vec3& velocity,
                                        const Vec3& omega) {
  if (material < 0 || material >= int(materials_.size())) throw std::invalid_argument("add_sphere: unknown material");
  if (!(radius > 0)) throw std::invalid_argument("add_sphere: radius must be > 0");
  const double rho = materials_[material].density;
  if (!(rho > 0)) throw std::invalid_argument("add_sphere: the material's density must be > 0");
  const double m = rho * 4.0 / 3.0 * M_PI * radius * radius * radius;
  x_.push_back(position); v_.push_back(velocity); w_.push_back(omega);
  f_.push_back(Vec3::Zero()); t_.push_back(Vec3::Zero());
  r_.push_back(radius); mass_.push_back(m); inv_mass_.push_back(1.0 / m);
  inv_inertia_.push_back(1.0 / (0.4 * m * radius * radius));
  mat_.push_back(material); clump_.push_back(-1);
  for (int s = 0; s < kWallSlots; ++s) { wall_slot_id_.push_back(-1); wall_slot_f_.push_back(Vec3::Zero()); }
  wall_slot_s_.resize(wall_slot_s_.size() + kWallSlots * kHist, 0.0);
  body_ref_.push_back(std::int32_t(x_.size() - 1));
  body_id_.push_back(next_id_);
  sphere_body_.push_back(std::uint32_t(body_ref_.size() - 1));
  forces_valid_ = false;
  rekick_on_refresh_ = false;  // (the state itself changed)
  nl_.invalidate();
  return next_id_++;
}

template <class Law>
BodyId BasicSimulation<Law>::add_clump(int tmpl, int material, const Vec3& com, const Quat& orientation,
                                       const Vec3& velocity, const Vec3& omega) {
  if (tmpl < 0 || tmpl >= int(templates_.size())) throw std::invalid_argument("add_clump: unknown template");
  if (material < 0 || material >= int(materials_.size())) throw std::invalid_argument("add_clump: unknown material");
  const ClumpTemplate& t = templates_[tmpl];
  const std::size_t c = cx_.size();
  const Quat q = (orientation.normalized() * t.principal).normalized();
  cx_.push_back(com); cv_.push_back(velocity); cw_.push_back(omega);
  cq_.push_back(q); cI_.push_back(t.inertia); cm_.push_back(t.mass);
  // L = R I R^T omega
  const Mat3 R = q.toRotationMatrix();
  cL_.push_back(R * t.inertia.asDiagonal() * (R.transpose() * omega));
  cF_.push_back(Vec3::Zero()); cT_.push_back(Vec3::Zero());
  ctmpl_.push_back(tmpl); cmat_.push_back(material);
  if (cmem_start_.empty()) cmem_start_.push_back(0);
  for (std::size_t k = 0; k < t.offsets.size(); ++k) {
    const Vec3 d = R * t.offsets[k];
    cmem_.push_back(std::uint32_t(x_.size()));
    cmem_offset_.push_back(t.offsets[k]);
    x_.push_back(com + d); v_.push_back(velocity + omega.cross(d)); w_.push_back(omega);
    f_.push_back(Vec3::Zero()); t_.push_back(Vec3::Zero());
    r_.push_back(t.radii[k]); mass_.push_back(t.mass); inv_mass_.push_back(0.0); inv_inertia_.push_back(0.0);
    mat_.push_back(material); clump_.push_back(std::int32_t(c));
    for (int s = 0; s < kWallSlots; ++s) { wall_slot_id_.push_back(-1); wall_slot_f_.push_back(Vec3::Zero()); }
    wall_slot_s_.resize(wall_slot_s_.size() + kWallSlots * kHist, 0.0);
  }
  cmem_start_.push_back(std::uint32_t(cmem_.size()));
  body_ref_.push_back(-std::int32_t(c) - 1);
  body_id_.push_back(next_id_);
  clump_body_.push_back(std::uint32_t(body_ref_.size() - 1));
  for (std::size_t k = 0; k < t.offsets.size(); ++k) sphere_body_.push_back(std::uint32_t(body_ref_.size() - 1));
  forces_valid_ = false;
  rekick_on_refresh_ = false;  // (the state itself changed)
  nl_.invalidate();
  return next_id_++;
}

template <class Law>
void BasicSimulation<Law>::rebuild_body_index() {
  sphere_body_.assign(x_.size(), 0);
  clump_body_.assign(cx_.size(), 0);
  for (std::size_t b = 0; b < body_ref_.size(); ++b) {
    const std::int32_t ref = body_ref_[b];
    if (ref >= 0) {
      sphere_body_[ref] = std::uint32_t(b);
    } else {
      const std::size_t c = std::size_t(-ref - 1);
      clump_body_[c] = std::uint32_t(b);
      for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k) sphere_body_[cmem_[k]] = std::uint32_t(b);
    }
  }
  cmem_offset_.resize(cmem_.size());
  for (std::size_t c = 0; c < cx_.size(); ++c) {
    const ClumpTemplate& t = templates_[ctmpl_[c]];
    for (std::uint32_t k = cmem_start_[c], m = 0; k < cmem_start_[c + 1]; ++k, ++m) cmem_offset_[k] = t.offsets[m];
  }
}

template <class Law>
void BasicSimulation<Law>::prepare() {
  if (!(dt_ > 0)) throw std::logic_error("step: set_timestep() first");
  const int nm = int(materials_.size());
  if (!prepared_) {
    std::vector<char> used(nm, 0), used_wall(nm, 0);
    for (auto m : mat_) used[m] = 1;
    for (const Wall& w : walls_) used_wall[w.material] = 1;
    coeffs_.assign(nm * nm, typename Law::Coeffs{});
    for (int a = 0; a < nm; ++a)
      for (int b = 0; b < nm; ++b) {
        const bool needed = used[a] && (used[b] || used_wall[b]);
        if (pair_set_[a * nm + b]) {
          coeffs_[a * nm + b] = Law::mix(materials_[a], materials_[b], pair_props_[a * nm + b]);
        } else if (needed) {
          throw std::logic_error("step: material pair (" + std::to_string(a) + ", " + std::to_string(b) +
                                 ") has no properties: call set_pair()");
        }
      }
    nm_coeffs_ = nm;
    prepared_ = true;
  }
  walls_move_ = false;
  for (const Wall& w : walls_) walls_move_ = walls_move_ || w.motion || w.velocity != Vec3::Zero();
  if constexpr (Law::beyond_contact) {
    // R* of any contact is at most the largest radius (a wall contact's R* is the sphere's radius)
    double r_max = 0;
    for (double r : r_) r_max = std::max(r_max, r);
    double reach = 0;
    for (int a = 0; a < nm; ++a)
      for (int b = 0; b < nm; ++b)
        if (pair_set_[a * nm + b]) reach = std::max(reach, Law::reach(coeffs_[a * nm + b], r_max));
    // pairs may now act beyond the list's reach (charged to its skin); not so for a list just loaded from a state: it
    // was built with the reach of these materials and radii (the configuration matched), as the uninterrupted run's
    if (reach > law_reach_ && !list_from_state_) nl_.spend(reach - law_reach_);
    law_reach_ = reach;
    list_from_state_ = false;
  }
  if (skin_ <= 0) {
    double rs = 0;
    for (double r : r_) rs += r;
    skin_ = r_.empty() ? 1e-4 : 0.2 * rs / double(r_.size());
  }
}

template <class Law>
void BasicSimulation<Law>::update_members(std::size_t c, const Mat3& R, bool positions) {
  const Vec3 w = cw_[c];
  for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k) {
    const std::uint32_t s = cmem_[k];
    const Vec3 d = R * cmem_offset_[k];
    if (positions) x_[s] = cx_[c] + d;
    v_[s] = cv_[c] + w.cross(d);
    w_[s] = w;
  }
}

template <class Law>
bool BasicSimulation<Law>::kick_drift(double kick) {
  // kick = 1: the first half kick of velocity Verlet; kick = 2: fused with the previous step's second half kick
  const double h = 0.5 * dt_ * kick, dt = dt_;
  const Vec3 g = gravity_;
  const std::int64_t n = std::int64_t(x_.size()), nc = std::int64_t(cx_.size());
  const bool check = nl_.valid() && nl_.built_positions().size() == x_.size();
  const Vec3* xb = check ? nl_.built_positions().data() : nullptr;
  const double allowance = nl_.displacement_allowance();
  const double lim2 = allowance * allowance;
  int moved = check ? 0 : 1;
  if (Law::uses_omega_norm) omega_norm_.resize(std::size_t(n));
  double* wnorm = omega_norm_.data();
#pragma omp parallel num_threads(nt()) reduction(| : moved)
  {
#pragma omp for schedule(static) nowait
    for (std::int64_t i = 0; i < n; ++i) {  // single spheres (clump members are moved by their clump below)
      if (clump_[i] >= 0) continue;
      v_[i] += h * (f_[i] * inv_mass_[i] + g);
      w_[i] += (h * inv_inertia_[i]) * t_[i];
      if (Law::uses_omega_norm) wnorm[i] = w_[i].norm();
      x_[i] += dt * v_[i];
      if (check && (x_[i] - xb[i]).squaredNorm() > lim2) moved = 1;
    }
    // clumps in batches of clump_rotation::kLanes: the orientation update runs on the batch side by side
    namespace cr = clump_rotation;
    const std::int64_t nbatch = (nc + cr::kLanes - 1) / cr::kLanes;
#pragma omp for schedule(static)
    for (std::int64_t b = 0; b < nbatch; ++b) {
      const std::int64_t c0 = b * cr::kLanes, lanes = std::min<std::int64_t>(cr::kLanes, nc - c0);
      cr::QuatPack q{};
      cr::VecPack L{}, inv_I{};
      for (int k = 0; k < cr::kLanes; ++k) q.w[k] = 1.0;  // unused lanes: identity, no momentum
      for (int k = 0; k < lanes; ++k) {
        const std::int64_t c = c0 + k;
        cv_[c] += h * (cF_[c] / cm_[c] + g);
        cx_[c] += dt * cv_[c];
        cL_[c] += h * cT_[c];
        const Vec3 iI = detail::inverse_moments(cI_[c]);
        q.x[k] = cq_[c].x(); q.y[k] = cq_[c].y(); q.z[k] = cq_[c].z(); q.w[k] = cq_[c].w();
        L.x[k] = cL_[c].x(); L.y[k] = cL_[c].y(); L.z[k] = cL_[c].z();
        inv_I.x[k] = iI.x(); inv_I.y[k] = iI.y(); inv_I.z[k] = iI.z();
      }
      if (clump_rotation_ == ClumpRotation::yade_leapfrog) {
        // YADE's scheme, one clump at a time (a cross-check's option, not the kernel's hot path)
        for (int k = 0; k < lanes; ++k) {
          const std::int64_t c = c0 + k;
          cw_[c] = cr::yade_leapfrog(cq_[c], cL_[c] - (0.5 * dt) * cT_[c], cL_[c], cI_[c], dt);
          update_members(std::size_t(c), cq_[c].toRotationMatrix(), true);
        }
      } else {
        cr::richardson(q, L, inv_I, dt);
        // one rotation matrix for the new omega and the members
        const cr::MatPack R = cr::rotation_matrix(q);
        const cr::VecPack w = cr::angular_velocity(R, L, inv_I);
        for (int k = 0; k < lanes; ++k) {
          const std::int64_t c = c0 + k;
          cq_[c] = Quat(q.w[k], q.x[k], q.y[k], q.z[k]);
          cw_[c] = Vec3(w.x[k], w.y[k], w.z[k]);
          Mat3 Rk;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) Rk(i, j) = R.m[i][j][k];
          update_members(std::size_t(c), Rk, true);
        }
      }
      for (int k = 0; k < lanes; ++k) {
        const std::int64_t c = c0 + k;
        if (Law::uses_omega_norm) {
          const double wn = cw_[c].norm();  // the members' omega is the clump's
          for (std::uint32_t m = cmem_start_[c]; m < cmem_start_[c + 1]; ++m) wnorm[cmem_[m]] = wn;
        }
        if (check)
          for (std::uint32_t m = cmem_start_[c]; m < cmem_start_[c + 1]; ++m)
            if ((x_[cmem_[m]] - xb[cmem_[m]]).squaredNorm() > lim2) moved = 1;
      }
    }
  }
  omega_norm_fresh_ = Law::uses_omega_norm;
  return moved != 0;
}

template <class Law>
void BasicSimulation<Law>::kick(double sign) {
  const double h = 0.5 * dt_ * sign;
  const Vec3 g = gravity_;
  const std::int64_t n = std::int64_t(x_.size()), nc = std::int64_t(cx_.size());
#pragma omp parallel num_threads(nt())
  {
#pragma omp for schedule(static) nowait
    for (std::int64_t i = 0; i < n; ++i) {
      if (clump_[i] >= 0) continue;
      v_[i] += h * (f_[i] * inv_mass_[i] + g);
      w_[i] += (h * inv_inertia_[i]) * t_[i];
    }
#pragma omp for schedule(static)
    for (std::int64_t c = 0; c < nc; ++c) {
      cv_[c] += h * (cF_[c] / cm_[c] + g);
      cL_[c] += h * cT_[c];
      const Mat3 R = cq_[c].toRotationMatrix();
      cw_[c] = R * (R.transpose() * cL_[c]).cwiseProduct(detail::inverse_moments(cI_[c]));
      update_members(std::size_t(c), R, false);
    }
  }
}

template <class Law>
void BasicSimulation<Law>::reorder_spheres() {
  // Spheres sorted by the cell of their body's centre (a clump's centre of mass), the members of a clump kept
  // together in template order, and the clumps renumbered in the same order: the force loop then reads
  // neighbours that lie close in memory, and the clump update reads and writes its members contiguously.
  const std::size_t n = x_.size(), nc = cx_.size();
  if (n < 2) return;
  CellGrid grid;
  if (!grid.fit(x_, r_, skin_)) return;  // the neighbour build reports it
  struct Key {
    std::uint32_t cell, owner, member, old;  // owner: the sphere itself, or its clump's first member (both unique)
    bool operator<(const Key& o) const {
      return cell != o.cell ? cell < o.cell : owner != o.owner ? owner < o.owner : member < o.member;
    }
  };
  std::vector<Key> key(n);
  for (std::size_t i = 0; i < n; ++i)
    if (clump_[i] < 0) key[i] = {grid.cell_of(x_[i]), std::uint32_t(i), 0, std::uint32_t(i)};
  for (std::size_t c = 0; c < nc; ++c) {
    const std::uint32_t cell = grid.cell_of(cx_[c]), owner = cmem_[cmem_start_[c]];
    for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k)
      key[cmem_[k]] = {cell, owner, k - cmem_start_[c], cmem_[k]};
  }
  std::sort(key.begin(), key.end());  // keys are unique: deterministic
  std::vector<std::int32_t> old2new(n);
  bool identity = true;
  for (std::size_t k = 0; k < n; ++k) {
    old2new[key[k].old] = std::int32_t(k);
    identity = identity && key[k].old == k;
  }
  if (identity) return;
  omega_norm_fresh_ = false;  // (|omega| per sphere is scratch, not permuted: computed again)
  auto permute = [&](auto& vec, std::size_t per) {
    auto tmp = vec;
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t m = 0; m < per; ++m) vec[k * per + m] = tmp[std::size_t(key[k].old) * per + m];
  };
  for_each_sphere_array(permute);
  if (nc > 0) {
    // clumps in the order of their (now contiguous) members
    std::vector<std::uint32_t> corder(nc);
    for (std::size_t c = 0; c < nc; ++c) corder[c] = std::uint32_t(c);
    std::sort(corder.begin(), corder.end(), [&](std::uint32_t a, std::uint32_t b) {
      return old2new[cmem_[cmem_start_[a]]] < old2new[cmem_[cmem_start_[b]]];
    });
    std::vector<std::int32_t> cold2new(nc);
    for (std::size_t k = 0; k < nc; ++k) cold2new[corder[k]] = std::int32_t(k);
    auto cpermute = [&](auto& vec) {
      auto tmp = vec;
      for (std::size_t k = 0; k < nc; ++k) vec[k] = tmp[corder[k]];
    };
    std::vector<std::uint32_t> mem_start{0}, mem;
    mem.reserve(cmem_.size());
    for (std::size_t k = 0; k < nc; ++k) {
      const std::uint32_t c = corder[k];
      for (std::uint32_t m = cmem_start_[c]; m < cmem_start_[c + 1]; ++m) mem.push_back(std::uint32_t(old2new[cmem_[m]]));
      mem_start.push_back(std::uint32_t(mem.size()));
    }
    cmem_start_ = std::move(mem_start);
    cmem_ = std::move(mem);
    for_each_clump_array(cpermute);
    for (auto& c : clump_)
      if (c >= 0) c = cold2new[c];
    for (auto& ref : body_ref_)
      if (ref < 0) ref = -cold2new[std::size_t(-ref - 1)] - 1;
  } else {
    for (auto& m : cmem_) m = std::uint32_t(old2new[m]);
  }
  for (auto& ref : body_ref_)
    if (ref >= 0) ref = old2new[ref];
  rebuild_body_index();
  nl_.renumber(old2new, n, &Law::swap_history);
}

template <class Law>
void BasicSimulation<Law>::rebuild_neighbors() {
  nl_.build(x_, r_, clump_, skin_, nt(), law_reach_);
  find_wall_candidates();  // same positions, same skin: valid until the list is
}

template <class Law>
void BasicSimulation<Law>::find_wall_candidates() {
  // A sphere moves less than skin/2 between two neighbour builds, and so does a moving wall (walls_left_reach), so
  // only walls closer than r + skin/2 (+ skin/2 when walls move, + the law's reach beyond touching) to its centre
  // now can touch it before the next build. Disabled walls are kept as candidates (enabling one needs no rebuild);
  // the force loop skips them.
  const std::int64_t n = std::int64_t(x_.size());
  const int nw = int(walls_.size());
  wall_cand_.assign(std::size_t(n), 0);
  wall_disp_built_.resize(walls_.size());
  for (std::size_t k = 0; k < walls_.size(); ++k) wall_disp_built_[k] = walls_[k].displacement;
  wall_list_row_.clear();
  wall_list_.clear();
  wall_lists_stale_ = false;
  if (nw == 0) return;
  const double reach = 0.5 * skin_ + (walls_move_ ? 0.5 * skin_ : 0.0) + law_reach_;
  if (nw > kMaxWallCandidates) {
    find_wall_candidate_lists(x_, reach, wall_disp_built_);
    return;
  }
  build_wall_grid(wall_disp_built_, reach);
#pragma omp parallel for num_threads(nt()) schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    std::uint64_t m = 0;
    Vec3 nrm;
    double dn, dist;
    const double ri = r_[i] + reach;
    wall_grid_.for_each_candidate(x_[i], [&](int wdx) {
      if (wall_grid_.near_box(wdx, x_[i], ri) && walls_[wdx].contact(x_[i], ri, nrm, dn, dist))
        m |= std::uint64_t(1) << wdx;
    });
    wall_cand_[std::size_t(i)] = m;
  }
}

template <class Law>
void BasicSimulation<Law>::build_wall_grid(const std::vector<Vec3>& wall_displacement, double reach) {
  double r_max = 0;
  for (double r : r_) r_max = std::max(r_max, r);
  wall_grid_.build(walls_, wall_displacement, r_max + reach);
}

template <class Law>
void BasicSimulation<Law>::find_wall_candidate_lists(const std::vector<Vec3>& centres, double reach,
                                                     const std::vector<Vec3>& wall_displacement) {
  // Each thread lists the walls of its contiguous block of spheres (schedule static, no chunk: blocks in thread
  // order), then the blocks are joined in that order: ascending spheres, ascending walls, whatever the thread count.
  const std::int64_t n = std::int64_t(centres.size());
  std::vector<std::uint32_t> count(std::size_t(n), 0);
  std::vector<std::vector<std::int32_t>> block(static_cast<std::size_t>(nt()));
  build_wall_grid(wall_displacement, reach);
#pragma omp parallel num_threads(nt())
  {
    std::vector<std::int32_t>& mine = block[std::size_t(omp_get_thread_num())];
    Vec3 nrm;
    double dn, dist;
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      const Vec3& c = centres[std::size_t(i)];
      const double ri = r_[std::size_t(i)] + reach;
      wall_grid_.for_each_candidate(c, [&](int wdx) {
        if (!wall_grid_.near_box(wdx, c, ri)) return;
        // the wall where it stood at the build: contact() takes off its displacement now
        const Vec3 p = c + (walls_[wdx].displacement - wall_displacement[std::size_t(wdx)]);
        if (walls_[wdx].contact(p, ri, nrm, dn, dist)) {
          mine.push_back(wdx);
          ++count[std::size_t(i)];
        }
      });
    }
  }
  wall_list_row_.assign(std::size_t(n) + 1, 0);
  for (std::int64_t i = 0; i < n; ++i) wall_list_row_[std::size_t(i) + 1] = wall_list_row_[std::size_t(i)] + count[std::size_t(i)];
  wall_list_.clear();
  wall_list_.reserve(wall_list_row_.back());
  for (const auto& b : block) wall_list_.insert(wall_list_.end(), b.begin(), b.end());
}

template <class Law>
void BasicSimulation<Law>::compute_forces(bool rebuild, double dt_history) {
  prepare_lists(rebuild);
  const std::int64_t n = std::int64_t(x_.size());
  pair_load_.resize(nl_.num_pairs());
  PairLoad* load = pair_load_.data();
  if (exact_removal_) pair_torque_i_.resize(nl_.num_pairs());
  Vec3* torque_i = exact_removal_ ? pair_torque_i_.data() : nullptr;  // (recorded for an exact removal only)
  const int nm = nm_coeffs_;
  const double dt = dt_history;  // the tangential springs advance by vt * dt_history
  const int nw = int(walls_.size());
  const std::uint32_t* row = nl_.row.data();
  const std::int32_t* nbr = nl_.nbr.data();
  double* hist = nl_.hist.data();
  const double law_reach = law_reach_;
  const bool bond_now = bond_next_evaluation_;  // (YADE's setCohesionNow: the contacts acting in this evaluation)
  bond_next_evaluation_ = false;
  // |omega| once per sphere, not once per contact side (a sphere has several contacts); kick_drift has filled it
  // unless the angular velocities changed otherwise since (a velocity set, bodies added, removed or renumbered)
  const bool fill_omega_norm = Law::uses_omega_norm && !(omega_norm_fresh_ && omega_norm_.size() == std::size_t(n));
  if (Law::uses_omega_norm) omega_norm_.resize(std::size_t(n));
  omega_norm_fresh_ = false;  // the next kick changes omega
  double* wnorm = omega_norm_.data();
  // the steps below share one parallel region: their loops are `omp for` directives bound to it
#pragma omp parallel num_threads(nt())
  {
    if (fill_omega_norm) {
#pragma omp for schedule(static)
      for (std::int64_t i = 0; i < n; ++i) wnorm[i] = w_[i].norm();
    }
    // dynamic: the contacts per sphere vary along the cell order (a packed hopper below, a loose top, an emptying
    // outlet), and a static split left one thread waiting (the silo's full case: 1.85 -> 1.91 cores busy of 2).
    // Each i writes only its own row, so the result does not depend on the schedule.
#pragma omp for schedule(dynamic, 512)
    for (std::int64_t i = 0; i < n; ++i) {
      Vec3 fi = Vec3::Zero(), ti = Vec3::Zero();
      const Vec3 xi = x_[i], vi = v_[i], wi = w_[i];
      const double ri = r_[i], mi = mass_[i];
      const typename Law::Coeffs* crow = coeffs_.data() + std::size_t(mat_[i]) * nm;
      for (std::uint32_t p = row[i]; p < row[i + 1]; ++p) {
        const std::int32_t j = nbr[p];
        double* h = hist + std::size_t(p) * kHist;
        const Vec3 d = xi - x_[j];
        const double rs = ri + r_[j];
        const double d2 = d.squaredNorm();
        const double reach = Law::beyond_contact ? rs + law_reach : rs;
        if (d2 >= reach * reach) {
          std::fill_n(h, kHist, 0.0);
          load[p].force_i.setZero();
          load[p].torque_j.setZero();
          if (torque_i) torque_i[p].setZero();
          continue;
        }
        const double dist = std::sqrt(d2);
        const double rj = r_[j], mj = mass_[j];
        ContactGeometry geo;
        geo.n = d * (1.0 / dist);
        geo.dn = rs - dist;
        geo.radius_i = ri;
        geo.radius_j = rj;
        // R* = ri rj / (ri + rj), m* = mi mj / (mi + mj) with one division
        const double q = 1.0 / (rs * (mi + mj));
        geo.r_star = ri * rj * (mi + mj) * q;
        geo.m_star = mi * mj * rs * q;
        geo.lever_i = ri - 0.5 * geo.dn;
        geo.lever_j = r_[j] - 0.5 * geo.dn;
        const typename Law::Coeffs& coeffs = crow[mat_[j]];
        if constexpr (Law::beyond_contact) {
          if (!Law::acts(coeffs, geo, h)) {  // a gap the contact does not (or no longer) bridge
            std::fill_n(h, kHist, 0.0);
            load[p].force_i.setZero();
            load[p].torque_j.setZero();
            if (torque_i) torque_i[p].setZero();
            continue;
          }
        }
        ContactKinematics kin;
        kin.omega_i = wi;
        kin.omega_j = w_[j];
        if (Law::uses_omega_norm) {
          kin.omega_i_norm = wnorm[i];
          kin.omega_j_norm = wnorm[j];
        }
        kin.v_rel = (vi - geo.lever_i * wi.cross(geo.n)) - (v_[j] + geo.lever_j * w_[j].cross(geo.n));
        if constexpr (Law::uses_centre_velocities) {
          kin.v_i = vi;
          kin.v_j = v_[j];
        }
        const ContactResult res = Law::compute(coeffs, geo, kin, h, dt, false, bond_now);
        fi += res.force_i;
        ti += res.torque_i;
        load[p].force_i = res.force_i;
        load[p].torque_j = res.torque_j;
        if (torque_i) torque_i[p] = res.torque_i;
      }
      // walls: up to kWallSlots simultaneous contacts keep a history
      if (nw > 0) {
        constexpr int kH = kHist > 0 ? kHist : 1;  // (no zero-length arrays)
        std::int32_t* sid = &wall_slot_id_[std::size_t(i) * kWallSlots];
        double* ss = wall_slot_s_.data() + std::size_t(i) * kWallSlots * kHist;
        Vec3* sf = &wall_slot_f_[std::size_t(i) * kWallSlots];
        std::int32_t nid[kWallSlots] = {-1, -1, -1};
        double ns[kWallSlots][kH];
        Vec3 nf[kWallSlots];
        int used = 0;
        // only the walls within reach at the last neighbour build, in ascending order: the set bits of the candidate
        // mask, or past kMaxWallCandidates walls the sphere's candidate list; not a test of every wall
        const bool masked = nw <= kMaxWallCandidates;
        std::uint64_t candidates = masked ? wall_cand_[i] : 0;
        std::uint32_t listed = masked ? 0 : wall_list_row_[i];
        const std::uint32_t listed_end = masked ? 0 : wall_list_row_[i + 1];
        auto next_candidate = [&]() -> int {
          if (masked) return next_wall_candidate(candidates);
          return listed < listed_end ? wall_list_[listed++] : nw;
        };
        for (int wdx = next_candidate(); wdx < nw; wdx = next_candidate()) {
          const Wall& wall = walls_[wdx];
          if (!wall.enabled) continue;
          Vec3 nrm;
          double dn, dist;
          if (!wall.contact(xi, Law::beyond_contact ? ri + law_reach : ri, nrm, dn, dist)) continue;
          double s[kH] = {};
          for (int k = 0; k < kWallSlots; ++k)
            if (sid[k] == wdx) std::copy_n(ss + k * kHist, kHist, s);
          const typename Law::Coeffs& coeffs = crow[wall.material];
          ContactGeometry geo;
          geo.n = nrm;
          geo.dn = Law::beyond_contact ? dn - law_reach : dn;
          geo.radius_i = ri;
          geo.radius_j = 0;
          geo.r_star = ri;
          geo.m_star = mi;
          geo.lever_i = Law::lever_at_overlap_middle ? ri - 0.5 * geo.dn : dist;
          geo.lever_j = 0;
          if constexpr (Law::beyond_contact) {
            if (!Law::acts(coeffs, geo, s)) continue;
          }
          ContactKinematics kin;
          kin.omega_i = wi;
          kin.omega_j = Vec3::Zero();
          if (Law::uses_omega_norm) kin.omega_i_norm = wnorm[i];
          kin.v_rel = vi - geo.lever_i * wi.cross(nrm) - wall.velocity;
          if constexpr (Law::uses_centre_velocities) {
            kin.v_i = vi;
            kin.v_j = wall.velocity;
          }
          const ContactResult res = Law::compute(coeffs, geo, kin, s, dt, true, bond_now);
          fi += res.force_i;
          ti += res.torque_i;
          if (used < kWallSlots) {
            nid[used] = wdx;
            std::copy_n(s, kHist, ns[used]);
            nf[used] = res.force_i;
            ++used;
          }
        }
        if (used > 0 || sid[0] >= 0)  // (slots are filled from the front: sid[0] < 0 means all empty)
          for (int k = 0; k < kWallSlots; ++k) {
            sid[k] = nid[k];
            for (int m = 0; m < kHist; ++m) ss[k * kHist + m] = k < used ? ns[k][m] : 0.0;
            sf[k] = k < used ? nf[k] : Vec3::Zero();
          }
      }
      f_[i] = fi;
      t_[i] = ti;
    }
    add_partner_loads();
    sum_clump_loads();
  }
  pair_torques_i_known_ = exact_removal_;
  if (local_damping_ > 0) apply_local_damping();
}

template <class Law>
void BasicSimulation<Law>::prepare_lists(bool rebuild) {
  if (rebuild || !nl_.valid() || nl_.built_positions().size() != x_.size()) {
    if (reorder_every_ > 0 && builds_since_reorder_ % reorder_every_ == 0) reorder_spheres();
    ++builds_since_reorder_;
    rebuild_neighbors();
  } else if (wall_lists_stale_) {
    // a loaded state: the lists its run had, or more walls (the largest reach, the radii now): a wider filter finds
    // the same contacts in the same order, so the run goes on bit for bit
    if (int(walls_.size()) > kMaxWallCandidates)
      find_wall_candidate_lists(nl_.built_positions(), skin_ + law_reach_, wall_disp_built_);
    wall_lists_stale_ = false;
  }
}

template <class Law>
void BasicSimulation<Law>::add_partner_loads() {
  // the j-side of each pair, gathered in a fixed order (ascending i); an `omp for` of compute_forces' region
  const PairLoad* load = pair_load_.data();
  const std::uint32_t* trow = nl_.trow.data();
  const std::uint32_t* tpair = nl_.tpair.data();
  const std::int64_t n = std::int64_t(x_.size());
#pragma omp for schedule(static)
  for (std::int64_t j = 0; j < n; ++j) {
    Vec3 fj = Vec3::Zero(), tj = Vec3::Zero();
    for (std::uint32_t q = trow[j]; q < trow[j + 1]; ++q) {
      const std::uint32_t p = tpair[q];
      fj -= load[p].force_i;
      tj += load[p].torque_j;
    }
    f_[j] += fj;
    t_[j] += tj;
  }
}

template <class Law>
void BasicSimulation<Law>::sum_clump_loads() {
  // each clump's total force and torque about its centre of mass (members in a fixed order); an `omp for` of
  // compute_forces' region
  const std::int64_t nc = std::int64_t(cx_.size());
#pragma omp for schedule(static)
  for (std::int64_t c = 0; c < nc; ++c) {
    Vec3 F = Vec3::Zero(), T = Vec3::Zero();
    for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k) {
      const std::uint32_t s = cmem_[k];
      F += f_[s];
      T += t_[s] + (x_[s] - cx_[c]).cross(f_[s]);
    }
    cF_[c] = F;
    cT_[c] = T;
  }
}

template <class Law>
void BasicSimulation<Law>::apply_local_damping() {
  // YADE's NewtonIntegrator(damping = d), per component, with the velocities of the move that led here (v^{k-1/2},
  // which is what the state holds at a force evaluation): a_i *= 1 - d sign(a_i (v_i + dt/2 a_i)), gravity included
  // (dampGravity); spheres' angular accelerations likewise; clumps damp the torque, T_i *= 1 - d sign(T_i w_i). The
  // damped force replaces the force, so both half kicks of velocity Verlet use it (= YADE's leapfrog).
  const double d = local_damping_, h = 0.5 * dt_;
  const Vec3 g = gravity_;
  auto sgn = [](double x) { return double((x > 0) - (x < 0)); };
  const std::int64_t n = std::int64_t(x_.size()), nc = std::int64_t(cx_.size());
#pragma omp parallel num_threads(nt())
  {
#pragma omp for schedule(static) nowait
    for (std::int64_t i = 0; i < n; ++i) {
      if (clump_[i] >= 0) continue;
      const double m = mass_[i];
      for (int k = 0; k < 3; ++k) {
        double a = f_[i][k] / m + g[k];
        a *= 1 - d * sgn(a * (v_[i][k] + h * a));
        f_[i][k] = (a - g[k]) * m;
        const double al = t_[i][k] * inv_inertia_[i];
        t_[i][k] *= 1 - d * sgn(al * (w_[i][k] + h * al));
      }
    }
#pragma omp for schedule(static)
    for (std::int64_t c = 0; c < nc; ++c)
      for (int k = 0; k < 3; ++k) {
        double a = cF_[c][k] / cm_[c] + g[k];
        a *= 1 - d * sgn(a * (cv_[c][k] + h * a));
        cF_[c][k] = (a - g[k]) * cm_[c];
        cT_[c][k] *= 1 - d * sgn(cT_[c][k] * cw_[c][k]);
      }
  }
}

template <class Law>
void BasicSimulation<Law>::set_local_damping(double damping) {
  if (!(damping >= 0 && damping < 1)) throw std::invalid_argument("set_local_damping: damping must be in [0, 1)");
  local_damping_ = damping;
  if (forces_valid_) rekick_on_refresh_ = true;
  forces_valid_ = false;
}

template <class Law>
void BasicSimulation<Law>::bond_contacts_now()
  requires Law::has_bonds
{
  bond_next_evaluation_ = true;
  if (forces_valid_) rekick_on_refresh_ = true;
  forces_valid_ = false;
}

template <class Law>
std::size_t BasicSimulation<Law>::bonded_contact_count() const
  requires Law::has_bonds
{
  // the bond flag is the normal model's first history entry, zeroed when the bond fails or the contact ends
  std::size_t count = 0;
  for (std::size_t p = 0; p < nl_.num_pairs(); ++p)
    if (nl_.hist[p * kHist] != 0.0) ++count;
  return count;
}

template <class Law>
void BasicSimulation<Law>::refresh_forces() {
  // Forces of the current state (after an insertion, a removal, a wall toggled, velocities set): time does not
  // advance, so neither do the tangential springs; a wall on a law moves at its velocity of this instant.
  // After a change that keeps the state (particles grown, a wall's velocity or the damping set, bonds made) the last
  // half kick is taken back and taken again with the new forces, so the change acts on the whole step as in a
  // leapfrog integrator (YADE's, where a PyRunner's change acts before the next force evaluation); without this the
  // step that follows a change got half the old force, which made the kernel's shear box drift from YADE's.
  const bool rekick = rekick_on_refresh_ && steps_ > 0;
  rekick_on_refresh_ = false;
  if (rekick) kick(-1.0);
  for (Wall& w : walls_)
    if (w.motion) w.velocity = w.motion->velocity(time_);
  // (dt: a state restarted as a leapfrog code imports it, whose first evaluation advances the fresh springs)
  compute_forces(nl_.needs_rebuild(x_, nt()), import_spring_step_pending_ ? dt_ : 0.0);
  import_spring_step_pending_ = false;
  if (rekick) kick(1.0);
  forces_valid_ = true;
}

template <class Law>
void BasicSimulation<Law>::step(long nsteps) {
  step(nsteps, {});
}

template <class Law>
long BasicSimulation<Law>::step(long nsteps, const std::function<bool()>& should_stop) {
  prepare();
  if (!forces_valid_) refresh_forces();
  if (nsteps <= 0) return 0;
  if (import_full_kick_pending_) {  // the on-step velocities taken as half-step ones: a whole first kick
    kick(1.0);
    import_full_kick_pending_ = false;
  }
  // velocity Verlet; the second half kick of a step and the first of the next are fused into one pass (also across
  // a stop: an owed half kick is paid with the first kick here)
  for (long s = 0; s < nsteps; ++s) {
    const bool moved = kick_drift(s == 0 && !half_kick_owed_ ? 1.0 : 2.0);
    half_kick_owed_ = false;
    if (walls_move_) move_walls();
    compute_forces(moved || (walls_move_ && walls_left_reach()), dt_);
    time_ += dt_;
    ++steps_;
    if (should_stop && s + 1 < nsteps && should_stop()) {
      half_kick_owed_ = true;
      return s + 1;
    }
  }
  kick();
  return nsteps;
}

template <class Law>
void BasicSimulation<Law>::scale_particles(double factor) {
  if (!(factor > 0 && std::isfinite(factor)))
    throw std::invalid_argument("scale_particles: factor must be finite and > 0, got " + std::to_string(factor));
  const double f3 = factor * factor * factor, f5 = f3 * factor * factor;
  for (ClumpTemplate& t : templates_) scale_clump_template(t, factor);
  for (Vec3& o : cmem_offset_) o *= factor;  // (as scale_clump_template scales the offsets: the same numbers)
  for (std::size_t i = 0; i < x_.size(); ++i) {
    r_[i] *= factor;
    mass_[i] *= f3;  // a member's m* is its clump's mass
    if (clump_[i] < 0) {
      inv_mass_[i] /= f3;
      inv_inertia_[i] /= f5;
    }
  }
  for (std::size_t c = 0; c < cx_.size(); ++c) {
    cm_[c] *= f3;
    cI_[c] *= f5;
    cL_[c] *= f5;  // the same angular velocity
    update_members(c, cq_[c].toRotationMatrix(), true);
  }
  omega_norm_fresh_ = false;
  if (forces_valid_) rekick_on_refresh_ = true;
  forces_valid_ = false;
  // every radius grew by at most (factor - 1) r_max: charged to the skin (the grid's cells are sized at each build)
  double r_max = 0;
  for (double r : r_) r_max = std::max(r_max, r);
  if (factor > 1) nl_.spend(r_max - r_max / factor);
}

template <class Law>
std::vector<std::size_t> BasicSimulation<Law>::wall_contact_spheres(int id) const {
  if (id < 0 || id >= int(walls_.size())) throw std::out_of_range("wall_contact_spheres: no wall " + std::to_string(id));
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < x_.size(); ++i)
    for (int k = 0; k < kWallSlots; ++k)
      if (wall_slot_id_[i * kWallSlots + k] == id) out.push_back(i);
  return out;
}

template <class Law>
double BasicSimulation<Law>::unbalanced_force() const {
  // The forces as the contacts gave them (apply_local_damping has rescaled f_ since): rebuilt from the pair loads of
  // the last evaluation and the wall slots.
  const std::size_t n = x_.size();
  std::vector<Vec3> contact(n, Vec3::Zero());
  double sum_contact = 0;
  std::size_t contacts = 0;
  const std::size_t pairs = std::min<std::size_t>(pair_load_.size(), nl_.num_pairs());
  if (nl_.row.size() == n + 1)
    for (std::size_t i = 0; i < n; ++i)
      for (std::uint32_t p = nl_.row[i]; p < nl_.row[i + 1] && p < pairs; ++p) {
        const Vec3& fp = pair_load_[p].force_i;
        if (fp == Vec3::Zero()) continue;
        contact[i] += fp;
        contact[std::size_t(nl_.nbr[p])] -= fp;
        sum_contact += fp.norm();
        ++contacts;
      }
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < kWallSlots; ++k)
      if (wall_slot_id_[i * kWallSlots + k] >= 0) {
        const Vec3& fw = wall_slot_f_[i * kWallSlots + k];
        contact[i] += fw;
        sum_contact += fw.norm();
        ++contacts;
      }
  if (contacts == 0 || body_ref_.empty()) return 0.0;
  double sum_body = 0;
  for (const std::int32_t ref : body_ref_) {
    if (ref >= 0) {
      sum_body += (contact[std::size_t(ref)] + mass_[std::size_t(ref)] * gravity_).norm();
    } else {
      const std::size_t c = std::size_t(-ref - 1);
      Vec3 F = cm_[c] * gravity_;
      for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k) F += contact[cmem_[k]];
      sum_body += F.norm();
    }
  }
  return (sum_body / double(body_ref_.size())) / (sum_contact / double(contacts));
}

template <class Law>
BodyState BasicSimulation<Law>::body(std::size_t b) const {
  BodyState s;
  const std::int32_t ref = body_ref_.at(b);
  s.id = body_id_[b];
  if (ref >= 0) {
    s.is_clump = false;
    s.material = mat_[ref];
    s.radius = r_[ref];
    s.mass = mass_[ref];
    s.position = x_[ref];
    s.velocity = v_[ref];
    s.angular_velocity = w_[ref];
  } else {
    const std::size_t c = std::size_t(-ref - 1);
    const ClumpTemplate& t = templates_[ctmpl_[c]];
    s.is_clump = true;
    s.material = cmat_[c];
    s.clump_template = ctmpl_[c];
    s.radius = t.bounding_radius;
    s.mass = cm_[c];
    s.position = cx_[c];
    s.velocity = cv_[c];
    s.angular_velocity = cw_[c];
    s.orientation = (cq_[c] * t.principal.conjugate()).normalized();
  }
  return s;
}

template <class Law>
void BasicSimulation<Law>::set_body_velocity(std::size_t b, const Vec3& velocity, const Vec3& omega) {
  const std::int32_t ref = body_ref_.at(b);
  if (ref >= 0) {
    v_[ref] = velocity;
    w_[ref] = omega;
  } else {
    const std::size_t c = std::size_t(-ref - 1);
    cv_[c] = velocity;
    cw_[c] = omega;
    const Mat3 R = cq_[c].toRotationMatrix();
    cL_[c] = R * cI_[c].asDiagonal() * (R.transpose() * omega);
    update_members(c, R, false);
  }
  forces_valid_ = false;
  rekick_on_refresh_ = false;  // (the state itself changed)
}

template <class Law>
RemovalResult BasicSimulation<Law>::remove_bodies_if(const std::function<bool(const BodyState&)>& pred) {
  RemovalResult res;
  std::vector<char> drop_body(body_ref_.size(), 0);
  for (std::size_t b = 0; b < body_ref_.size(); ++b) {
    const BodyState s = body(b);
    if (pred(s)) {
      drop_body[b] = 1;
      ++res.count;
      res.mass += s.mass;
    }
  }
  if (res.count == 0) return res;
  const std::size_t n = x_.size(), nc = cx_.size();
  std::vector<char> drop_sphere(n, 0), drop_clump(nc, 0);
  mark_removed_spheres(drop_body, drop_sphere, drop_clump);
  // With exact removals on, the bodies go as if they had gone before the last force evaluation (as a leapfrog code
  // erasing them between two steps, YADE's silo.py): their contacts' loads leave their neighbours' forces and the
  // half kick those loads gave is taken back, so the forces stay valid and nothing else changes. (Recomputing every
  // force instead re-evaluated each damped contact with the on-step velocities and re-capped its spring: at every
  // removal the whole bed moved otherwise, which slowed the silo's discharge by about 2 %, measured against YADE;
  // examples/crosscheck/README.md.) Not with local damping (the forces then hold the damping's rescaling): those
  // forces are evaluated again.
  const bool loads_known = exact_removal_ && forces_valid_ && local_damping_ == 0 && pair_torques_i_known_ &&
                           pair_load_.size() == nl_.num_pairs() && pair_torque_i_.size() == pair_load_.size() &&
                           nl_.row.size() == n + 1;
  if (loads_known) take_out_removed_contacts(drop_sphere, drop_clump);
  const std::vector<std::int32_t> s_old2new = kept_numbering(drop_sphere), c_old2new = kept_numbering(drop_clump);
  compact_spheres(drop_sphere, c_old2new);
  compact_clumps(drop_clump, s_old2new);
  compact_bodies(drop_body, s_old2new, c_old2new);
  const std::size_t kept_spheres = std::size_t(std::count(drop_sphere.begin(), drop_sphere.end(), char(0)));
  nl_.renumber(s_old2new, kept_spheres, &Law::swap_history);
  // forces of the remaining spheres are still valid except for the contacts with removed ones; recompute
  forces_valid_ = loads_known;
  rekick_on_refresh_ = false;  // (the state itself changed)
  return res;
}

template <class Law>
void BasicSimulation<Law>::mark_removed_spheres(const std::vector<char>& drop_body, std::vector<char>& drop_sphere,
                                                std::vector<char>& drop_clump) const {
  for (std::size_t b = 0; b < body_ref_.size(); ++b) {
    if (!drop_body[b]) continue;
    const std::int32_t ref = body_ref_[b];
    if (ref >= 0) {
      drop_sphere[ref] = 1;
    } else {
      const std::size_t c = std::size_t(-ref - 1);
      drop_clump[c] = 1;
      for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k) drop_sphere[cmem_[k]] = 1;
    }
  }
}

template <class Law>
std::vector<std::int32_t> BasicSimulation<Law>::kept_numbering(const std::vector<char>& drop) {
  std::vector<std::int32_t> old2new(drop.size(), -1);
  std::int32_t kept = 0;
  for (std::size_t i = 0; i < drop.size(); ++i)
    if (!drop[i]) old2new[i] = kept++;
  return old2new;
}

template <class Law>
void BasicSimulation<Law>::compact_spheres(const std::vector<char>& drop_sphere,
                                           const std::vector<std::int32_t>& c_old2new) {
  const std::size_t n = drop_sphere.size();
  auto compact = [&](auto& vec, std::size_t per) {
    std::size_t o = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (drop_sphere[i]) continue;
      for (std::size_t k = 0; k < per; ++k) vec[o * per + k] = vec[i * per + k];
      ++o;
    }
    vec.resize(o * per);
  };
  for_each_sphere_array(compact);
  for (auto& c : clump_)
    if (c >= 0) c = c_old2new[c];
}

template <class Law>
void BasicSimulation<Law>::compact_clumps(const std::vector<char>& drop_clump,
                                          const std::vector<std::int32_t>& s_old2new) {
  const std::size_t nc = drop_clump.size();
  std::vector<std::uint32_t> mem_start{0}, mem;
  for (std::size_t c = 0; c < nc; ++c) {
    if (drop_clump[c]) continue;
    for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k) mem.push_back(std::uint32_t(s_old2new[cmem_[k]]));
    mem_start.push_back(std::uint32_t(mem.size()));
  }
  cmem_start_ = std::move(mem_start);
  cmem_ = std::move(mem);
  auto compact = [&](auto& vec) {
    std::size_t o = 0;
    for (std::size_t c = 0; c < nc; ++c)
      if (!drop_clump[c]) vec[o++] = vec[c];
    vec.resize(o);
  };
  for_each_clump_array(compact);
}

template <class Law>
void BasicSimulation<Law>::compact_bodies(const std::vector<char>& drop_body,
                                          const std::vector<std::int32_t>& s_old2new,
                                          const std::vector<std::int32_t>& c_old2new) {
  std::vector<std::int32_t> refs;
  std::vector<BodyId> ids;
  for (std::size_t b = 0; b < body_ref_.size(); ++b) {
    if (drop_body[b]) continue;
    const std::int32_t ref = body_ref_[b];
    refs.push_back(ref >= 0 ? s_old2new[ref] : -c_old2new[std::size_t(-ref - 1)] - 1);
    ids.push_back(body_id_[b]);
  }
  body_ref_ = std::move(refs);
  body_id_ = std::move(ids);
  rebuild_body_index();
}

template <class Law>
void BasicSimulation<Law>::take_out_removed_contacts(const std::vector<char>& drop_sphere,
                                                     const std::vector<char>& drop_clump) {
  const std::size_t n = x_.size(), nc = cx_.size();
  std::vector<Vec3> force_out(n, Vec3::Zero()), torque_out(n, Vec3::Zero());
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t p = nl_.row[i]; p < nl_.row[i + 1]; ++p) {
      const std::size_t j = std::size_t(nl_.nbr[p]);
      if (drop_sphere[i] == drop_sphere[j]) continue;  // both stay, or both go
      if (!drop_sphere[i]) {
        force_out[i] += pair_load_[p].force_i;
        torque_out[i] += pair_torque_i_[p];
      } else {
        force_out[j] -= pair_load_[p].force_i;
        torque_out[j] += pair_load_[p].torque_j;
      }
    }
  const double h = 0.5 * dt_;  // the half kick the last evaluation's forces gave (step() ends with it)
  for (std::size_t i = 0; i < n; ++i) {
    if (drop_sphere[i]) continue;
    f_[i] -= force_out[i];
    t_[i] -= torque_out[i];
    if (clump_[i] < 0) {
      v_[i] -= h * inv_mass_[i] * force_out[i];
      w_[i] -= (h * inv_inertia_[i]) * torque_out[i];
    }
  }
  for (std::size_t c = 0; c < nc; ++c) {
    if (drop_clump[c]) continue;
    Vec3 F = Vec3::Zero(), T = Vec3::Zero();  // the members' loads summed as compute_forces sums them
    for (std::uint32_t k = cmem_start_[c]; k < cmem_start_[c + 1]; ++k) {
      const std::uint32_t m = cmem_[k];
      F += f_[m];
      T += t_[m] + (x_[m] - cx_[c]).cross(f_[m]);
    }
    if (F == cF_[c] && T == cT_[c]) continue;
    cv_[c] -= h * (cF_[c] - F) / cm_[c];
    cL_[c] -= h * (cT_[c] - T);
    cF_[c] = F;
    cT_[c] = T;
    const Mat3 R = cq_[c].toRotationMatrix();
    cw_[c] = R * (R.transpose() * cL_[c]).cwiseProduct(detail::inverse_moments(cI_[c]));
    update_members(c, R, false);
  }
  omega_norm_fresh_ = false;
}

template <class Law>
SphereState BasicSimulation<Law>::sphere(std::size_t k) const {
  SphereState s;
  s.position = x_.at(k);
  s.velocity = v_[k];
  s.radius = r_[k];
  s.material = mat_[k];
  s.body = sphere_body_[k];
  return s;
}

template <class Law>
double BasicSimulation<Law>::rotational_kinetic_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < x_.size(); ++i)
    if (clump_[i] < 0) e += 0.5 * w_[i].squaredNorm() / inv_inertia_[i];
  for (std::size_t c = 0; c < cx_.size(); ++c) e += 0.5 * cL_[c].dot(cw_[c]);
  return e;
}

template <class Law>
double BasicSimulation<Law>::kinetic_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < x_.size(); ++i)
    if (clump_[i] < 0) e += 0.5 * mass_[i] * v_[i].squaredNorm();
  for (std::size_t c = 0; c < cx_.size(); ++c) e += 0.5 * cm_[c] * cv_[c].squaredNorm();
  return e + rotational_kinetic_energy();
}

template <class Law>
double BasicSimulation<Law>::potential_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < x_.size(); ++i)
    if (clump_[i] < 0) e -= mass_[i] * gravity_.dot(x_[i]);
  for (std::size_t c = 0; c < cx_.size(); ++c) e -= cm_[c] * gravity_.dot(cx_[c]);
  return e;
}

template <class Law>
Vec3 BasicSimulation<Law>::linear_momentum() const {
  Vec3 p = Vec3::Zero();
  for (std::size_t i = 0; i < x_.size(); ++i)
    if (clump_[i] < 0) p += mass_[i] * v_[i];
  for (std::size_t c = 0; c < cx_.size(); ++c) p += cm_[c] * cv_[c];
  return p;
}

template <class Law>
Vec3 BasicSimulation<Law>::angular_momentum(const Vec3& o) const {
  Vec3 L = Vec3::Zero();
  for (std::size_t i = 0; i < x_.size(); ++i)
    if (clump_[i] < 0) L += mass_[i] * (x_[i] - o).cross(v_[i]) + w_[i] / inv_inertia_[i];
  for (std::size_t c = 0; c < cx_.size(); ++c) L += cm_[c] * (cx_[c] - o).cross(cv_[c]) + cL_[c];
  return L;
}

template <class Law>
double BasicSimulation<Law>::total_mass() const {
  double m = 0;
  for (std::size_t i = 0; i < x_.size(); ++i)
    if (clump_[i] < 0) m += mass_[i];
  for (double cm : cm_) m += cm;
  return m;
}

template <class Law>
std::vector<std::pair<std::int32_t, std::int32_t>> BasicSimulation<Law>::contact_pairs() {
  prepare();
  if (nl_.needs_rebuild(x_, nt())) rebuild_neighbors();
  std::vector<std::pair<std::int32_t, std::int32_t>> out;
  for (std::size_t i = 0; i + 1 < nl_.row.size(); ++i)
    for (std::uint32_t p = nl_.row[i]; p < nl_.row[i + 1]; ++p) {
      const std::int32_t j = nl_.nbr[p];
      const double c = r_[i] + r_[j];
      if ((x_[i] - x_[j]).squaredNorm() < c * c) out.emplace_back(std::int32_t(i), j);
    }
  return out;
}

template <class Law>
std::vector<std::pair<std::int32_t, std::int32_t>> BasicSimulation<Law>::contact_pairs_brute_force() const {
  return brute_force_contacts(x_, r_, clump_);
}

// ---------------------------------------------------------------- checkpoint

template <class Law>
std::vector<double> BasicSimulation<Law>::configuration_numbers() const {
  std::vector<double> c;
  auto vec = [&](const Vec3& v) { c.insert(c.end(), {v.x(), v.y(), v.z()}); };
  c.push_back(double(materials_.size()));
  for (const Material& m : materials_) c.insert(c.end(), {m.young, m.poisson, m.density});
  // a pair's inputs are the sub-models' fields, all doubles
  static_assert(std::is_trivially_copyable_v<PairParams> && sizeof(PairParams) % sizeof(double) == 0);
  for (std::size_t k = 0; k < pair_props_.size(); ++k) {
    double p[sizeof(PairParams) / sizeof(double) + 1] = {double(pair_set_[k])};
    std::memcpy(p + 1, &pair_props_[k], sizeof(PairParams));
    c.insert(c.end(), std::begin(p), std::end(p));
  }
  c.push_back(double(templates_.size()));
  for (const ClumpTemplate& t : templates_) {
    c.insert(c.end(), {double(t.offsets.size()), t.mass});
    vec(t.inertia);
    for (const Vec3& o : t.offsets) vec(o);
    for (double r : t.radii) c.push_back(r);
  }
  c.push_back(double(walls_.size()));
  for (const Wall& w : walls_) w.append_numbers(c);
  return c;
}

template <class Law>
void BasicSimulation<Law>::save_state(std::ostream& os) const {
  StateWriter w(os);
  w.text(kStateFormat);
  w.array(configuration_numbers());
  std::vector<char> enabled;
  std::vector<Vec3> wall_motion;  // displacement and velocity of each wall
  for (const Wall& wall : walls_) {
    enabled.push_back(wall.enabled);
    wall_motion.push_back(wall.displacement);
    wall_motion.push_back(wall.velocity);
  }
  w.array(enabled);
  w.array(wall_motion);
  w.array(wall_disp_built_);  // (when a moving wall next forces a neighbour build)
  // the for_each lists only hand out references; nothing is modified
  auto* self = const_cast<BasicSimulation*>(this);
  self->for_each_sphere_array([&](auto& a, int) { w.array(a); });
  self->for_each_clump_array([&](auto& a) { w.array(a); });
  // (the pair loads as two arrays, force then torque)
  std::vector<Vec3> pair_f(pair_load_.size()), pair_tj(pair_load_.size());
  for (std::size_t p = 0; p < pair_load_.size(); ++p) {
    pair_f[p] = pair_load_[p].force_i;
    pair_tj[p] = pair_load_[p].torque_j;
  }
  w.array(pair_f); w.array(pair_tj); w.array(wall_cand_);
  w.array(cmem_start_); w.array(cmem_);
  w.array(body_ref_); w.array(body_id_);
  w.value(next_id_);
  nl_.save(w);
  w.value(gravity_); w.value(dt_); w.value(time_); w.value(skin_); w.value(steps_);
  w.value(reorder_every_); w.value(std::uint64_t(builds_since_reorder_)); w.value(forces_valid_);
  w.value(half_kick_owed_);
  w.checksum();
  if (!w.ok()) throw std::runtime_error("save_state: the stream failed while writing");
}

template <class Law>
void BasicSimulation<Law>::load_state(std::istream& is, const std::string& source) {
  StateReader r(is, source);
  const std::string tag = r.text("format tag");
  const bool spent_in_state = tag != "demcal-kernel-state/3";  // (/3: before the skin budget; read as nothing spent)
  if (tag == "demcal-kernel-state/1" || tag == "demcal-kernel-state/2")
    r.fail("format tag", "written by an older demcal (" + tag + "; this one reads " + kStateFormat +
                             "): finish that run with the demcal that started it, or start it again");
  if (tag != kStateFormat && tag != "demcal-kernel-state/3" && tag != "demcal-kernel-state/4")
    r.fail("format tag", "'" + tag.substr(0, 40) + "' is not a demcal kernel state (" + kStateFormat + ")");
  std::vector<double> saved;
  r.array(saved, "configuration");
  const std::vector<double> now = configuration_numbers();
  if (saved != now) {
    std::size_t k = 0;
    while (k < saved.size() && k < now.size() && saved[k] == now[k]) ++k;
    throw std::runtime_error(source + ": the materials, pairs, clump templates or walls set up now differ from the "
                             "saved ones (first difference at configuration number " + std::to_string(k) + ")");
  }
  std::vector<char> enabled;
  std::vector<Vec3> wall_motion;
  r.array(enabled, "wall switches");
  r.array(wall_motion, "wall motion");
  r.array(wall_disp_built_, "wall displacements at the last neighbour build");
  if (wall_disp_built_.size() > walls_.size()) r.fail("walls", "wrong count");
  if (enabled.size() != walls_.size() || wall_motion.size() != 2 * walls_.size()) r.fail("walls", "wrong count");
  for_each_sphere_array([&](auto& a, int) { r.array(a, "sphere arrays"); });
  for_each_clump_array([&](auto& a) { r.array(a, "clump arrays"); });
  std::vector<Vec3> pair_f, pair_tj;
  r.array(pair_f, "pair forces"); r.array(pair_tj, "pair torques"); r.array(wall_cand_, "wall candidates");
  if (pair_f.size() != pair_tj.size()) r.fail("pair loads", "force and torque counts differ");
  pair_load_.resize(pair_f.size());
  for (std::size_t p = 0; p < pair_f.size(); ++p) pair_load_[p] = {pair_f[p], pair_tj[p]};
  pair_torques_i_known_ = false;  // (not in the state: a removal before the next evaluation evaluates the forces)
  omega_norm_fresh_ = false;
  r.array(cmem_start_, "clump members"); r.array(cmem_, "clump members");
  r.array(body_ref_, "bodies"); r.array(body_id_, "body ids");
  r.value(next_id_, "next body id");
  nl_.load(r, spent_in_state);
  r.value(gravity_, "gravity"); r.value(dt_, "time step"); r.value(time_, "time"); r.value(skin_, "skin");
  r.value(steps_, "step count"); r.value(reorder_every_, "reorder period");
  builds_since_reorder_ = std::size_t(r.value<std::uint64_t>("builds since the last reorder"));
  r.value(forces_valid_, "force state");
  half_kick_owed_ = false;
  if (tag == kStateFormat) r.value(half_kick_owed_, "half kick owed");
  r.checksum();  // nothing read is used before the whole state is known to be the one written
  for (std::size_t k = 0; k < walls_.size(); ++k) {
    walls_[k].enabled = enabled[k] != 0;
    walls_[k].displacement = wall_motion[2 * k];
    walls_[k].velocity = wall_motion[2 * k + 1];
  }
  const std::size_t n = x_.size(), nc = cx_.size();
  bool sizes_ok = wall_slot_id_.size() == n * kWallSlots && wall_slot_s_.size() == n * kWallSlots * kHist &&
                  clump_.size() == n && cq_.size() == nc &&
                  (nc == 0 ? cmem_start_.size() <= 1 : cmem_start_.size() == nc + 1) && body_id_.size() == body_ref_.size();
  for (auto t : ctmpl_) sizes_ok = sizes_ok && t >= 0 && t < std::int32_t(templates_.size());
  for (auto m : mat_) sizes_ok = sizes_ok && m >= 0 && m < std::int32_t(materials_.size());
  if (!sizes_ok) r.fail("state", "inconsistent array sizes or indices");
  rebuild_body_index();
  prepared_ = false;  // pair coefficients are derived from the configuration again
  list_from_state_ = true;  // and the law's reach (prepare), which must not discard the list loaded here
  wall_lists_stale_ = true;
}

template <class Law>
std::size_t BasicSimulation<Law>::memory_bytes() const {
  const std::size_t n = x_.size();
  std::size_t b = n * (5 * sizeof(Vec3) + 4 * sizeof(double) + 2 * sizeof(std::int32_t) +
                       kWallSlots * (sizeof(std::int32_t) + sizeof(Vec3) + kHist * sizeof(double)) + sizeof(std::uint32_t) +
                       sizeof(std::uint64_t));  // the last: the wall mask
  b += nl_.num_pairs() * (sizeof(std::int32_t) + kHist * sizeof(double) + 2 * sizeof(Vec3) + sizeof(std::uint32_t)) +
       2 * (n + 1) * 4;
  b += omega_norm_.size() * sizeof(double);  // (laws with rolling friction only)
  b += cx_.size() * (7 * sizeof(Vec3) + sizeof(Quat) + sizeof(double) + 3 * 4);
  return b;
}

}  // namespace demcal::kernel
