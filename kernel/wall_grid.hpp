// The broad phase of the wall candidates: which walls a sphere centre can be within reach of, without testing every
// wall. A mesh wall has hundreds of facets (yade_scripts/silo.py's cone and cylinder: 288), and testing each against
// each sphere at every neighbour build cost the silo's discharge more than its force loop (27 % of a run against
// 33 %, perf). Each bounded wall's box (Wall::bounds), grown by the largest reach, is binned into a uniform grid of
// cells; a centre's cell lists, in ascending order, the walls whose grown box meets the cell, plus every unbounded
// wall (a plane). The exact test (Wall::contact) then runs on those only, in the same ascending order as a test of
// every wall, so the candidates found, and every result after them, are the same bits.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>
#include "kernel/types.hpp"
#include "kernel/walls.hpp"

namespace demcal::kernel {

class WallGrid {
 public:
  /// Bins `walls`, each displaced by displacement[w] from where it was built, for centres at most `reach` from a
  /// wall's box (reach >= every sphere's radius plus the distance it looks ahead).
  void build(const std::vector<Wall>& walls, const std::vector<Vec3>& displacement, double reach);
  /// Calls f(w) for every wall w a centre at p can be within `reach` of (a superset), in ascending order.
  template <class F>
  void for_each_candidate(const Vec3& p, F&& f) const {
    const std::int64_t c = cell_of(p);
    const std::int32_t *b = walls_.data(), *b_end = b;
    if (c >= 0) { b += start_[std::size_t(c)]; b_end = walls_.data() + start_[std::size_t(c) + 1]; }
    const std::int32_t *u = unbounded_.data(), *u_end = u + unbounded_.size();
    while (b != b_end || u != u_end)  // the cell's bounded walls and the unbounded ones, merged in ascending order
      f(u == u_end || (b != b_end && *b < *u) ? *b++ : *u++);
  }
  /// Whether a centre at p lies within `r` of wall w's box (a cheap test before Wall::contact; always true for an
  /// unbounded wall).
  bool near_box(int w, const Vec3& p, double r) const {
    const Box& b = boxes_[std::size_t(w)];
    if (!b.bounded) return true;
    return (p - b.lo).minCoeff() > -r && (b.hi - p).minCoeff() > -r;
  }
  std::size_t cell_count() const { return start_.empty() ? 0 : start_.size() - 1; }

 private:
  struct Box {
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
    bool bounded = false;
  };
  std::vector<Box> boxes_;
  std::vector<std::int32_t> unbounded_;  // ascending
  Vec3 origin_ = Vec3::Zero();
  double inv_cell_ = 0;
  std::int64_t dims_[3] = {0, 0, 0};
  std::vector<std::uint32_t> start_;  // CSR over cells (x fastest)
  std::vector<std::int32_t> walls_;   // each cell's walls, ascending
  std::vector<double> key_;           // the walls' numbers, displacements and reach the grid was built for
  bool built_ = false;

  // -1: outside the grid (only unbounded walls can be within reach there)
  std::int64_t cell_of(const Vec3& p) const {
    if (start_.empty()) return -1;
    std::int64_t k[3];
    for (int a = 0; a < 3; ++a) {
      const double u = (p[a] - origin_[a]) * inv_cell_;
      if (!(u >= 0 && u < double(dims_[a]))) return -1;  // (NaN too)
      k[a] = std::int64_t(u);
    }
    return (k[2] * dims_[1] + k[1]) * dims_[0] + k[0];
  }
};

}  // namespace demcal::kernel
