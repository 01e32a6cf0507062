#include "kernel/wall_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace demcal::kernel {

namespace {
constexpr double kCellsPerAxis = 64;          // the longest side of the walls' extent in about this many cells
constexpr std::int64_t kMaxCells = 1 << 16;   // rebuilt at every neighbour build: kept small
}  // namespace

void WallGrid::build(const std::vector<Wall>& walls, const std::vector<Vec3>& displacement, double reach) {
  // the same walls where they stood at the last build, the same reach: the same grid (fixed walls: built once)
  std::vector<double> key;
  key.reserve(walls.size() * 20 + 1);
  for (std::size_t w = 0; w < walls.size(); ++w) {
    walls[w].append_numbers(key);
    key.insert(key.end(), {displacement[w].x(), displacement[w].y(), displacement[w].z()});
  }
  key.push_back(reach);
  if (built_ && key == key_) return;
  key_.swap(key);
  built_ = true;
  const std::size_t nw = walls.size();
  boxes_.assign(nw, Box{});
  unbounded_.clear();
  start_.clear();
  walls_.clear();
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo_all = Vec3::Constant(inf), hi_all = Vec3::Constant(-inf);
  for (std::size_t w = 0; w < nw; ++w) {
    Box& b = boxes_[w];
    if (!walls[w].built_bounds(b.lo, b.hi) || !(b.lo.allFinite() && b.hi.allFinite())) {
      unbounded_.push_back(std::int32_t(w));
      continue;
    }
    b.lo += displacement[w];
    b.hi += displacement[w];
    // a margin far above the rounding of the exact test, far below any distance that matters
    const double margin = 1e-9 * (b.lo.cwiseAbs().maxCoeff() + b.hi.cwiseAbs().maxCoeff() + reach);
    b.lo.array() -= margin;
    b.hi.array() += margin;
    b.bounded = true;
    lo_all = lo_all.cwiseMin(Vec3(b.lo.array() - reach));
    hi_all = hi_all.cwiseMax(Vec3(b.hi.array() + reach));
  }
  if (unbounded_.size() == nw) return;  // no grid: every centre gets the unbounded walls
  const Vec3 extent = hi_all - lo_all;
  double cell = std::max(extent.maxCoeff() / kCellsPerAxis, 2 * reach);
  if (!(cell > 0) || !std::isfinite(cell)) cell = std::max(extent.maxCoeff(), 1.0);
  auto cells_along = [&](int a) { return std::max<std::int64_t>(1, std::int64_t(std::ceil(extent[a] / cell))); };
  while (cells_along(0) * cells_along(1) * cells_along(2) > kMaxCells) cell *= 1.25;
  for (int a = 0; a < 3; ++a) dims_[a] = cells_along(a);
  origin_ = lo_all;
  inv_cell_ = 1.0 / cell;
  const std::int64_t cells = dims_[0] * dims_[1] * dims_[2];
  // the cells a grown box covers, clamped to the grid
  auto cover = [&](const Box& b, std::int64_t k0[3], std::int64_t k1[3]) {
    for (int a = 0; a < 3; ++a) {
      k0[a] = std::clamp<std::int64_t>(std::int64_t(std::floor((b.lo[a] - reach - origin_[a]) * inv_cell_)), 0,
                                       dims_[a] - 1);
      k1[a] = std::clamp<std::int64_t>(std::int64_t(std::floor((b.hi[a] + reach - origin_[a]) * inv_cell_)), 0,
                                       dims_[a] - 1);
    }
  };
  auto for_each_cell = [&](const Box& b, auto&& f) {
    std::int64_t k0[3], k1[3];
    cover(b, k0, k1);
    for (std::int64_t z = k0[2]; z <= k1[2]; ++z)
      for (std::int64_t y = k0[1]; y <= k1[1]; ++y)
        for (std::int64_t x = k0[0]; x <= k1[0]; ++x) f(std::size_t((z * dims_[1] + y) * dims_[0] + x));
  };
  // counting pass, then a filling pass in ascending wall order: each cell's list comes out ascending
  start_.assign(std::size_t(cells) + 1, 0);
  for (const Box& b : boxes_)
    if (b.bounded) for_each_cell(b, [&](std::size_t c) { ++start_[c + 1]; });
  for (std::size_t c = 0; c < std::size_t(cells); ++c) start_[c + 1] += start_[c];
  walls_.resize(start_.back());
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t w = 0; w < nw; ++w)
    if (boxes_[w].bounded) for_each_cell(boxes_[w], [&](std::size_t c) { walls_[fill[c]++] = std::int32_t(w); });
}

}  // namespace demcal::kernel
