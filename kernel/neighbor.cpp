#include "kernel/neighbor.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace demcal::kernel {

bool NeighborList::needs_rebuild(const std::vector<Vec3>& x, int threads) const {
  if (!valid_ || x.size() != x_built_.size()) return true;
  const double allowance = displacement_allowance();
  const double lim2 = allowance * allowance;
  const std::int64_t n = std::int64_t(x.size());
  int moved = 0;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(| : moved)
  for (std::int64_t i = 0; i < n; ++i)
    if ((x[i] - x_built_[i]).squaredNorm() > lim2) moved = 1;
  return moved != 0;
}

void NeighborList::spend(double amount) {
  if (!(amount > 0)) return;
  spent_ += amount;
  if (!(spent_ < 0.5 * skin_)) valid_ = false;
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
                         const std::vector<std::int32_t>& group, double skin, int threads, double reach) {
  const std::size_t n = x.size();
  skin_ = skin;
  spent_ = 0;
  ++builds_;
  // keep the old list for the history carry-over
  std::vector<std::uint32_t> old_row;
  std::vector<std::int32_t> old_nbr;
  std::vector<double> old_hist;
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
  if (!grid.fit(x, r, skin + reach))
    throw std::runtime_error("NeighborList::build: a sphere position is not finite (the simulation blew up?)");
  const std::int64_t nx = grid.nx, ny = grid.ny, nz = grid.nz;
  const std::size_t nc = grid.count();
  cell_of_.resize(n);
  const std::int64_t sn = std::int64_t(n);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t i = 0; i < sn; ++i) cell_of_[std::size_t(i)] = grid.cell_of(x[std::size_t(i)]);
  cell_start_.assign(nc + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++cell_start_[cell_of_[i] + 1];
  for (std::size_t c = 0; c < nc; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(n);
  {
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) cell_items_[fill[cell_of_[i]]++] = std::uint32_t(i);  // ascending i per cell
  }
  binned_.resize(n);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t k = 0; k < sn; ++k) {
    const std::uint32_t i = cell_items_[std::size_t(k)];
    binned_[std::size_t(k)] = {x[i], r[i], group[i], i};
  }
  // One pass over the 27 cells around each sphere i finds its partners on both sides: j > i (its row of the half
  // list) and j < i (the pairs where i is the partner: its row of the transposed index). The test is symmetric
  // (|x_i - x_j|^2 and r_i + r_j + skin are the same bits either way), so the two sides agree exactly. Each thread
  // keeps what it found for its contiguous block of spheres and copies it into place once the row offsets are known:
  // no second visit to count, no serial transposition.
  trow.assign(n + 1, 0);  // row[i + 1], trow[i + 1]: first the counts of sphere i, then the offsets
  const int nthreads = std::max(1, threads);
  thread_fwd_.resize(std::size_t(nthreads));
  thread_bwd_.resize(std::size_t(nthreads));
  thread_found_.resize(std::size_t(nthreads));
#pragma omp parallel num_threads(nthreads)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const std::int64_t lo = sn * t / nt, hi = sn * (t + 1) / nt;  // this thread's block, in sphere order
    std::vector<std::int32_t>& fwd = thread_fwd_[std::size_t(t)];
    std::vector<std::int32_t>& bwd = thread_bwd_[std::size_t(t)];
    std::vector<std::int32_t>& found = thread_found_[std::size_t(t)];
    fwd.clear();
    bwd.clear();
    for (std::int64_t i = lo; i < hi; ++i) {
      const std::size_t f0 = fwd.size(), b0 = bwd.size();
      const std::uint32_t c = cell_of_[std::size_t(i)];
      const std::int64_t cx = c % nx, cy = (c / nx) % ny, cz = c / (nx * ny);
      const Vec3 xi = x[std::size_t(i)];
      const double ri = r[std::size_t(i)];
      const std::int32_t gi = group[std::size_t(i)];
      // the 3 x 3 rows of cells around i's cell: the three cells of a row are consecutive in cell order, so each row
      // is one range of binned_ (9 ranges, not 27 short loops whose ends the branch predictor misses)
      std::uint32_t range_begin[9], range_end[9];
      int ranges = 0;
      std::size_t candidates = 0;
      const std::int64_t x0 = std::max<std::int64_t>(cx - 1, 0), x1 = std::min(cx + 1, nx - 1);
      for (std::int64_t z = std::max<std::int64_t>(cz - 1, 0); z <= std::min(cz + 1, nz - 1); ++z)
        for (std::int64_t y = std::max<std::int64_t>(cy - 1, 0); y <= std::min(cy + 1, ny - 1); ++y) {
          const std::size_t row_cell = std::size_t((z * ny + y) * nx);
          range_begin[ranges] = cell_start_[row_cell + std::size_t(x0)];
          range_end[ranges] = cell_start_[row_cell + std::size_t(x1) + 1];
          candidates += range_end[ranges] - range_begin[ranges];
          ++ranges;
        }
      if (found.size() < candidates) found.resize(2 * candidates);
      // every candidate written, the count advanced only for a partner (no branch on the test's outcome)
      std::size_t count = 0;
      for (int q = 0; q < ranges; ++q)
        for (std::uint32_t k = range_begin[q]; k < range_end[q]; ++k) {
          const Binned& b = binned_[k];
          const double cut = ri + b.r + skin + reach;
          const bool partner = ((xi - b.x).squaredNorm() < cut * cut) & (b.index != std::uint32_t(i)) &
                               !((gi >= 0) & (b.group == gi));
          found[count] = std::int32_t(b.index);
          count += partner;
        }
      // sorted once: the partners below i are its transposed row, those above its row of the half list
      std::sort(found.begin(), found.begin() + std::ptrdiff_t(count));
      const auto split = std::lower_bound(found.begin(), found.begin() + std::ptrdiff_t(count), std::int32_t(i));
      bwd.insert(bwd.end(), found.begin(), split);
      fwd.insert(fwd.end(), split, found.begin() + std::ptrdiff_t(count));
      row[std::size_t(i) + 1] = std::uint32_t(fwd.size() - f0);
      trow[std::size_t(i) + 1] = std::uint32_t(bwd.size() - b0);
    }
#pragma omp barrier
#pragma omp single
    {
      for (std::size_t i = 0; i < n; ++i) {
        row[i + 1] += row[i];
        trow[i + 1] += trow[i];
      }
      nbr.resize(row[n]);
      hist.resize(row[n] * hsize_);
      tpair.resize(row[n]);
    }  // (implicit barrier)
    std::copy(fwd.begin(), fwd.end(), nbr.begin() + row[std::size_t(lo)]);
    for (std::int64_t i = lo; i < hi; ++i) {
      // carry the histories over (both rows sorted by j)
      std::uint32_t q = 0, qe = 0;
      if (std::size_t(i) < old_n) { q = old_row[std::size_t(i)]; qe = old_row[std::size_t(i) + 1]; }
      for (std::uint32_t k = row[std::size_t(i)]; k < row[std::size_t(i) + 1]; ++k) {
        while (q < qe && old_nbr[q] < nbr[k]) ++q;
        const bool kept = q < qe && old_nbr[q] == nbr[k];
        for (std::size_t m = 0; m < hsize_; ++m) hist[k * hsize_ + m] = kept ? old_hist[q * hsize_ + m] : 0.0;
      }
    }
#pragma omp barrier
    // the transposed index: pair p of (i, j), i < j, listed under j in ascending i; p found in i's sorted row
    std::size_t b = 0;
    for (std::int64_t j = lo; j < hi; ++j)
      for (std::uint32_t q = trow[std::size_t(j)]; q < trow[std::size_t(j) + 1]; ++q, ++b) {
        const std::size_t i = std::size_t(bwd[b]);
        const auto first = nbr.begin() + row[i], last = nbr.begin() + row[i + 1];
        tpair[q] = std::uint32_t(std::lower_bound(first, last, std::int32_t(j)) - nbr.begin());
      }
  }
  x_built_ = x;
  valid_ = true;
}

void NeighborList::renumber(const std::vector<std::int32_t>& old2new, std::size_t new_count,
                            void (*swap_history)(double*)) {
  const std::size_t old_n = row.empty() ? 0 : row.size() - 1;
  struct P { std::int32_t i, j; std::size_t h; };  // h: where its history starts in `carried`
  std::vector<double> carried;
  std::vector<P> keep;
  keep.reserve(nbr.size());
  for (std::size_t i = 0; i < old_n && i < old2new.size(); ++i) {
    const std::int32_t ni = old2new[i];
    if (ni < 0) continue;
    for (std::uint32_t p = row[i]; p < row[i + 1]; ++p) {
      if (std::size_t(nbr[p]) >= old2new.size()) continue;
      const std::int32_t nj = old2new[nbr[p]];
      if (nj < 0) continue;
      const double* h = hist.data() + std::size_t(p) * hsize_;
      if (std::all_of(h, h + hsize_, [](double v) { return v == 0.0; })) continue;  // nothing to carry
      const std::size_t at = carried.size();
      carried.insert(carried.end(), h, h + hsize_);
      if (ni < nj) {
        keep.push_back({ni, nj, at});
      } else {
        swap_history(carried.data() + at);
        keep.push_back({nj, ni, at});
      }
    }
  }
  std::sort(keep.begin(), keep.end(), [](const P& a, const P& b) { return a.i != b.i ? a.i < b.i : a.j < b.j; });
  row.assign(new_count + 1, 0);
  for (const P& k : keep) ++row[k.i + 1];
  for (std::size_t i = 0; i < new_count; ++i) row[i + 1] += row[i];
  nbr.resize(keep.size());
  hist.resize(keep.size() * hsize_);
  for (std::size_t p = 0; p < keep.size(); ++p) {
    nbr[p] = keep[p].j;
    std::copy_n(carried.begin() + std::ptrdiff_t(keep[p].h), hsize_, hist.begin() + std::ptrdiff_t(p * hsize_));
  }
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
  w.value(skin_); w.value(valid_); w.value(std::uint64_t(builds_)); w.value(spent_);
}

void NeighborList::load(StateReader& r, bool spent_in_state) {
  r.array(row, "neighbour rows"); r.array(nbr, "neighbours"); r.array(hist, "pair histories");
  r.array(trow, "transposed rows"); r.array(tpair, "transposed pairs"); r.array(x_built_, "build positions");
  r.value(skin_, "neighbour skin"); r.value(valid_, "neighbour list state");
  builds_ = std::size_t(r.value<std::uint64_t>("neighbour builds"));
  spent_ = 0;
  if (spent_in_state) r.value(spent_, "skin spent by growth");
  if (!(spent_ >= 0 && spent_ < 0.5 * skin_) && valid_) r.fail("skin spent by growth", "out of range");
  if (hist.size() != nbr.size() * hsize_ || (valid_ && (row.empty() || row.back() != nbr.size() || tpair.size() != nbr.size())))
    r.fail("neighbour list", "inconsistent sizes");
}

}  // namespace demcal::kernel
