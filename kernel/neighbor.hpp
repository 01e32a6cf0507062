// Linked-cell neighbour search with a Verlet skin, producing a half list (pairs i < j) in CSR form, with the
// contact history of each pair (the contact law's history_size doubles) carried across rebuilds and a transposed index (pairs by their j) so that forces
// can be gathered per sphere in a fixed order (deterministic for any thread count, no atomics).
#pragma once
#include <cstdint>
#include <utility>
#include <vector>
#include "kernel/state_io.hpp"
#include "kernel/types.hpp"

namespace demcal::kernel {

/// The linked-cell grid over a set of spheres: cells of at least 2 r_max + skin, coarsened until there are at most
/// max(64, 4 n) of them. Shared by the neighbour build and the cell-order renumbering, so both see the same cells.
struct CellGrid {
  Vec3 lo;
  double size = 0;
  std::int64_t nx = 0, ny = 0, nz = 0;
  /// False (grid unset) when a position is not finite.
  bool fit(const std::vector<Vec3>& x, const std::vector<double>& r, double skin);
  std::size_t count() const { return std::size_t(nx * ny * nz); }
  /// Linear index (z slowest) of the cell holding p, clamped into the grid.
  std::uint32_t cell_of(const Vec3& p) const;
};

class NeighborList {
 public:
  /// Doubles of contact history per pair (the law's history_size); set before the first build.
  void set_history_size(int doubles) { hsize_ = std::size_t(doubles); }
  std::size_t history_size() const { return hsize_; }
  /// Rebuilds the list: pairs (i < j) with |x_i - x_j| < r_i + r_j + skin, excluding pairs of the same clump
  /// (group[i] == group[j] >= 0). Histories of pairs present before are kept (matched by (i, j)); new pairs start
  /// at zero. Uses `threads` OpenMP threads; the result does not depend on it.
  /// reach: how far beyond touching the contact law may act (adhesion) [m]; the list then holds the pairs with
  /// |x_i - x_j| < r_i + r_j + skin + reach.
  void build(const std::vector<Vec3>& x, const std::vector<double>& r, const std::vector<std::int32_t>& group,
             double skin, int threads, double reach = 0.0);
  /// True when some sphere moved more than displacement_allowance() since the last build (or the list was never
  /// built / invalidated).
  bool needs_rebuild(const std::vector<Vec3>& x, int threads) const;
  /// How far a sphere may move from its build position before the list may miss a contact: skin/2, less what growth
  /// has spent (spend()).
  double displacement_allowance() const { return 0.5 * skin_ - spent_; }
  /// Charges a widening of every contact's reach since the build [m] (spheres grown by up to `amount` in radius, a
  /// law's reach beyond touching grown by `amount`) to the skin: the list stays valid while each sphere's
  /// displacement plus everything spent stays within skin/2 (then no pair outside the list can touch or act);
  /// invalidated once nothing is left. A build starts again from the whole skin.
  void spend(double amount);
  /// Renumbers spheres after a removal or a permutation: old2new[old] = new index or -1 (removed). Pairs keep their
  /// history (passed through swap_history where i and j swap order). The list must then be rebuilt before use.
  void renumber(const std::vector<std::int32_t>& old2new, std::size_t new_count, void (*swap_history)(double*));
  void invalidate() { valid_ = false; }
  /// Sphere positions at the last build (for the skin/2 displacement check).
  const std::vector<Vec3>& built_positions() const { return x_built_; }
  bool valid() const { return valid_; }

  /// Checkpoint: the list, its histories and its build positions (kernel/state_io.hpp).
  void save(StateWriter& w) const;
  /// spent_in_state: false for a state written before the skin budget existed (nothing was spent then: growth
  /// invalidated the list)
  void load(StateReader& r, bool spent_in_state = true);

  std::size_t num_pairs() const { return nbr.size(); }
  std::size_t num_builds() const { return builds_; }

  // CSR half list: pairs of sphere i are p in [row[i], row[i+1]), partner nbr[p] > i, history
  // hist[p * history_size() ...].
  std::vector<std::uint32_t> row;
  std::vector<std::int32_t> nbr;
  std::vector<double> hist;
  // transposed: pairs where sphere j is the partner: pair_of[q] for q in [trow[j], trow[j+1]), ascending i.
  std::vector<std::uint32_t> trow;
  std::vector<std::uint32_t> tpair;

 private:
  std::vector<Vec3> x_built_;
  double skin_ = 0;
  double spent_ = 0;  // of skin/2, by growth since the last build
  std::size_t hsize_ = 0;
  bool valid_ = false;
  std::size_t builds_ = 0;
  // cell grid scratch
  std::vector<std::uint32_t> cell_start_, cell_items_, cell_of_;
  // The spheres' centres, radii and groups copied in cell order (cell_items_'s), so that the search streams through
  // each cell's spheres instead of gathering them by index (the search's loads were most of a build's time).
  struct Binned {
    Vec3 x;
    double r;
    std::int32_t group;
    std::uint32_t index;
  };
  std::vector<Binned> binned_;
  // build scratch: the partners each thread found for its block of spheres (j > i and j < i)
  std::vector<std::vector<std::int32_t>> thread_fwd_, thread_bwd_;
  std::vector<std::vector<std::int32_t>> thread_found_;  // one sphere's candidates, partners first
};

/// All pairs (i < j, not in the same clump) whose spheres overlap (|x_i - x_j| < r_i + r_j), by brute force O(n^2).
std::vector<std::pair<std::int32_t, std::int32_t>> brute_force_contacts(const std::vector<Vec3>& x,
                                                                        const std::vector<double>& r,
                                                                        const std::vector<std::int32_t>& group);

}  // namespace demcal::kernel
