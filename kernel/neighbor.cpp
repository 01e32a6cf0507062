#include "kernel/neighbor.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace demcal::kernel {

bool NeighborList::needs_rebuild(const std::vector<Vec3>& x, int threads) const {
  if (!valid_ || x.size() != x_built_.size()) return true;
  const double lim2 = 0.25 * skin_ * skin_;
  const std::int64_t n = std::int64_t(x.size());
  int moved = 0;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(| : moved)
  for (std::int64_t i = 0; i < n; ++i)
    if ((x[i] - x_built_[i]).squaredNorm() > lim2) moved = 1;
  return moved != 0;
}

bool CellGrid::fit(const std::vector<Vec3>& x, const std::vector<double>& r, double skin) {
  const std::size_t n = x.size();
  if (n == 0) return false;
  Vec3 hi = x[0];
  lo = x[0];
  double rmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(x[i]);
    hi = hi.cwiseMax(x[i]);
    rmax = std::max(rmax, r[i]);
  }
  if (!lo.allFinite() || !hi.allFinite()) return false;
  size = 2 * rmax + skin;
  const double max_cells = std::max<double>(64.0, 4.0 * double(n));
  auto ncell = [&](double c, int d) { return std::int64_t((hi[d] - lo[d]) / c) + 1; };
  while (double(ncell(size, 0)) * double(ncell(size, 1)) * double(ncell(size, 2)) > max_cells) size *= 1.26;
  nx = ncell(size, 0);
  ny = ncell(size, 1);
  nz = ncell(size, 2);
  return true;
}

std::uint32_t CellGrid::cell_of(const Vec3& p) const {
  const double inv = 1.0 / size;
  const std::int64_t cx = std::min<std::int64_t>(nx - 1, std::int64_t((p.x() - lo.x()) * inv));
  const std::int64_t cy = std::min<std::int64_t>(ny - 1, std::int64_t((p.y() - lo.y()) * inv));
  const std::int64_t cz = std::min<std::int64_t>(nz - 1, std::int64_t((p.z() - lo.z()) * inv));
  return std::uint32_t((cz * ny + cy) * nx + cx);
}

void NeighborList::build(const std::vector<Vec3>& x, const std::vector<double>& r,
                         const std::vector<std::int32_t>& group, double skin, int threads) {
  const std::size_t n = x.size();
  skin_ = skin;
  ++builds_;
  // keep the old list for the history carry-over
  std::vector<std::uint32_t> old_row;
  std::vector<std::int32_t> old_nbr;
  std::vector<Vec3> old_hist;
  old_row.swap(row);
  old_nbr.swap(nbr);
  old_hist.swap(hist);
  const std::size_t old_n = old_row.empty() ? 0 : old_row.size() - 1;

  row.assign(n + 1, 0);
  if (n == 0) {
    nbr.clear(); hist.clear(); trow.assign(1, 0); tpair.clear();
    x_built_ = x; valid_ = true;
    return;
  }
  // grid
  CellGrid grid;
  if (!grid.fit(x, r, skin))
    throw std::runtime_error("NeighborList::build: a sphere position is not finite (the simulation blew up?)");
  const std::int64_t nx = grid.nx, ny = grid.ny, nz = grid.nz;
  const std::size_t nc = grid.count();
  cell_of_.resize(n);
  cell_start_.assign(nc + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    cell_of_[i] = grid.cell_of(x[i]);
    ++cell_start_[cell_of_[i] + 1];
  }
  for (std::size_t c = 0; c < nc; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(n);
  {
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) cell_items_[fill[cell_of_[i]]++] = std::uint32_t(i);  // ascending i per cell
  }
  // visit the partners of i (j > i) in the 27 cells around i's cell
  auto visit = [&](std::size_t i, auto&& fn) {
    const std::uint32_t c = cell_of_[i];
    const std::int64_t cx = c % nx, cy = (c / nx) % ny, cz = c / (nx * ny);
    const double ri = r[i];
    const std::int32_t gi = group[i];
    for (std::int64_t dz = -1; dz <= 1; ++dz) {
      const std::int64_t z = cz + dz;
      if (z < 0 || z >= nz) continue;
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const std::int64_t y = cy + dy;
        if (y < 0 || y >= ny) continue;
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const std::int64_t xx = cx + dx;
          if (xx < 0 || xx >= nx) continue;
          const std::size_t cc = std::size_t((z * ny + y) * nx + xx);
          for (std::uint32_t k = cell_start_[cc]; k < cell_start_[cc + 1]; ++k) {
            const std::uint32_t j = cell_items_[k];
            if (j <= i) continue;
            if (gi >= 0 && group[j] == gi) continue;
            const double cut = ri + r[j] + skin;
            if ((x[i] - x[j]).squaredNorm() < cut * cut) fn(j);
          }
        }
      }
    }
  };
  const std::int64_t sn = std::int64_t(n);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t i = 0; i < sn; ++i) {
    std::uint32_t cnt = 0;
    visit(std::size_t(i), [&](std::uint32_t) { ++cnt; });
    row[i + 1] = cnt;
  }
  for (std::size_t i = 0; i < n; ++i) row[i + 1] += row[i];
  nbr.resize(row[n]);
  hist.resize(row[n]);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t i = 0; i < sn; ++i) {
    std::uint32_t p = row[i];
    visit(std::size_t(i), [&](std::uint32_t j) { nbr[p++] = std::int32_t(j); });
    std::sort(nbr.begin() + row[i], nbr.begin() + row[i + 1]);
    // carry the histories over (both rows sorted by j)
    std::uint32_t q = 0, qe = 0;
    if (std::size_t(i) < old_n) { q = old_row[i]; qe = old_row[i + 1]; }
    for (std::uint32_t k = row[i]; k < row[i + 1]; ++k) {
      while (q < qe && old_nbr[q] < nbr[k]) ++q;
      hist[k] = (q < qe && old_nbr[q] == nbr[k]) ? old_hist[q] : Vec3::Zero();
    }
  }
  // transposed index, ascending i within each j (serial counting sort: deterministic)
  trow.assign(n + 1, 0);
  for (std::size_t p = 0; p < nbr.size(); ++p) ++trow[nbr[p] + 1];
  for (std::size_t j = 0; j < n; ++j) trow[j + 1] += trow[j];
  tpair.resize(nbr.size());
  {
    std::vector<std::uint32_t> fill(trow.begin(), trow.end() - 1);
    for (std::size_t p = 0; p < nbr.size(); ++p) tpair[fill[nbr[p]]++] = std::uint32_t(p);
  }
  x_built_ = x;
  valid_ = true;
}

void NeighborList::renumber(const std::vector<std::int32_t>& old2new, std::size_t new_count) {
  const std::size_t old_n = row.empty() ? 0 : row.size() - 1;
  struct P { std::int32_t i, j; Vec3 s; };
  std::vector<P> keep;
  keep.reserve(nbr.size());
  for (std::size_t i = 0; i < old_n && i < old2new.size(); ++i) {
    const std::int32_t ni = old2new[i];
    if (ni < 0) continue;
    for (std::uint32_t p = row[i]; p < row[i + 1]; ++p) {
      if (std::size_t(nbr[p]) >= old2new.size()) continue;
      const std::int32_t nj = old2new[nbr[p]];
      if (nj < 0) continue;
      if (hist[p].squaredNorm() == 0.0) continue;  // nothing to carry
      if (ni < nj) keep.push_back({ni, nj, hist[p]});
      else keep.push_back({nj, ni, -hist[p]});
    }
  }
  std::sort(keep.begin(), keep.end(), [](const P& a, const P& b) { return a.i != b.i ? a.i < b.i : a.j < b.j; });
  row.assign(new_count + 1, 0);
  for (const P& k : keep) ++row[k.i + 1];
  for (std::size_t i = 0; i < new_count; ++i) row[i + 1] += row[i];
  nbr.resize(keep.size());
  hist.resize(keep.size());
  for (std::size_t p = 0; p < keep.size(); ++p) { nbr[p] = keep[p].j; hist[p] = keep[p].s; }
  trow.clear();
  tpair.clear();
  valid_ = false;
}

std::vector<std::pair<std::int32_t, std::int32_t>> brute_force_contacts(const std::vector<Vec3>& x,
                                                                        const std::vector<double>& r,
                                                                        const std::vector<std::int32_t>& group) {
  std::vector<std::pair<std::int32_t, std::int32_t>> out;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j) {
      if (group[i] >= 0 && group[i] == group[j]) continue;
      const double c = r[i] + r[j];
      if ((x[i] - x[j]).squaredNorm() < c * c) out.emplace_back(std::int32_t(i), std::int32_t(j));
    }
  return out;
}

}  // namespace demcal::kernel

namespace demcal::kernel {

void NeighborList::save(StateWriter& w) const {
  w.array(row); w.array(nbr); w.array(hist); w.array(trow); w.array(tpair); w.array(x_built_);
  w.value(skin_); w.value(valid_); w.value(std::uint64_t(builds_));
}

void NeighborList::load(StateReader& r) {
  r.array(row, "neighbour rows"); r.array(nbr, "neighbours"); r.array(hist, "pair histories");
  r.array(trow, "transposed rows"); r.array(tpair, "transposed pairs"); r.array(x_built_, "build positions");
  r.value(skin_, "neighbour skin"); r.value(valid_, "neighbour list state");
  builds_ = std::size_t(r.value<std::uint64_t>("neighbour builds"));
  if (hist.size() != nbr.size() || (valid_ && (row.empty() || row.back() != nbr.size() || tpair.size() != nbr.size())))
    r.fail("neighbour list", "inconsistent sizes");
}

}  // namespace demcal::kernel
