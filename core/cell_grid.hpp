#pragma once
// Uniform cell grid over the particles' bounding box. Built by count -> exclusive scan -> stable scatter
// (a parallel counting sort by cell); the caller reorders the store by `order()` so that each cell's
// particles, and the runs of cells along x, are contiguous in memory.
//
// Neighbour traversal visits, for particle i, every j != i with r_ij < 2 h_ij = h_i + h_j, in a fixed
// order (cells in lexicographic order, particles in store order): deterministic at any thread count.
//
// The cell size is free: a query scans the cells that overlap the square [x_i - R_i, x_i + R_i]^D with
// R_i = h_i + max_h, each row of cells along x as one contiguous run. The solver's choice, and why, is in
// core/neighbour_cells.hpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/types.hpp"
#include "parallel/counting_sort.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

template <int D>
class CellGrid {
 public:
  using VecD = Vec<D>;
  /// Upper bound on the number of cells; past it the cell size grows (sparse, far-flung particles).
  static constexpr std::size_t kMaxCells = std::size_t{1} << 26;
  /// The cell budget for n particles: 16 cells a particle (at least 2^16), so a few far-flung particles
  /// cannot make the grid's memory grow beyond a small multiple of the store's.
  static std::size_t cell_budget(std::size_t n) {
    return std::min(kMaxCells, std::max<std::size_t>(std::size_t{1} << 16, 16 * n));
  }
  /// Upper bound on the bytes build() holds for n particles sorted with `threads` threads: the order and the
  /// keys (one index each a particle) and, at the full cell budget, the cell starts and the counting sort's
  /// histograms (one index a cell, and one a cell for each thread's chunk). For memory estimates.
  static std::size_t bytes_bound(std::size_t n, int threads) {
    const auto chunks = static_cast<std::size_t>(std::max(1, threads));
    return sizeof(std::uint32_t) * (2 * n + (1 + chunks) * cell_budget(n));
  }

  /// A bounding box; a non-finite point makes it infinite (a NaN would vanish in min/max), which build()
  /// refuses.
  struct Box {
    VecD lo = VecD::Constant(std::numeric_limits<double>::infinity());
    VecD hi = VecD::Constant(-std::numeric_limits<double>::infinity());
    static Box of(const VecD& p) {
      if (p.allFinite()) return Box{p, p};
      const double inf = std::numeric_limits<double>::infinity();
      return Box{VecD::Constant(-inf), VecD::Constant(inf)};
    }
    Box merged(const Box& o) const { return Box{lo.cwiseMin(o.lo), hi.cwiseMax(o.hi)}; }
  };

  /// Sorts particles into cells of size >= `min_cell_size`. `max_h` is the largest smoothing length of
  /// the particles (a query around particle i reaches h_i + max_h); by default min_cell_size / 2, the
  /// classic cell = support. After this call, the store must be gathered through order() before cell ranges
  /// refer to it.
  void build(const VecD* x, std::size_t n, double min_cell_size, double max_h = -1.0) {
    const Box box = par::reduce(
        n, Box{}, [&](std::size_t i) { return Box::of(x[i]); },
        [](const Box& a, const Box& b) { return a.merged(b); });
    build_in(box, x, n, min_cell_size, max_h);
  }

  /// build() with the particles' bounding box already known (Box::of merged over x[0..n)): a caller that
  /// writes the positions in a loop of its own reduces the box there, saving a parallel region.
  void build_in(Box box, const VecD* x, std::size_t n, double min_cell_size, double max_h = -1.0) {
    if (!(min_cell_size > 0.0) || !std::isfinite(min_cell_size)) {
      throw std::invalid_argument("CellGrid::build: cell size must be positive and finite");
    }
    if (max_h < 0.0) max_h = 0.5 * min_cell_size;
    if (!std::isfinite(max_h)) throw std::invalid_argument("CellGrid::build: max_h must be finite");
    max_h_ = max_h;
    n_ = n;
    if (n == 0) box = Box{VecD::Zero(), VecD::Zero()};
    for (int k = 0; k < D; ++k) {
      if (!std::isfinite(box.lo[k]) || !std::isfinite(box.hi[k])) {
        throw std::runtime_error("CellGrid::build: a particle position is not finite");
      }
    }
    // A relative margin over the requested size: coords() rounds, and a pair at distance ~min_cell_size
    // (up to rounding) could otherwise land two cells apart and be missed. 1e-6 exceeds the rounding error
    // of (p - origin) * inv_cell for any coordinate below kMaxCells cells.
    cell_size_ = min_cell_size * (1.0 + 1e-6);
    // The cell count is sized in floating point first: a far-flung particle (a run going wrong) can make the
    // box so large that the count per axis does not fit an integer; the cells grow until it fits the budget.
    const auto budget = static_cast<double>(cell_budget(n));
    for (;;) {
      double total = 1.0;
      for (int k = 0; k < D; ++k) total *= std::floor((box.hi[k] - box.lo[k]) / cell_size_) + 1.0;
      if (total <= budget) break;
      cell_size_ *= 2.0;  // a few dozen doublings even for an absurd box
    }
    cells_ = 1;
    for (int k = 0; k < D; ++k) {
      dims_[k] = static_cast<std::int64_t>(std::floor((box.hi[k] - box.lo[k]) / cell_size_)) + 1;
      cells_ *= static_cast<std::size_t>(dims_[k]);
    }
    origin_ = box.lo;
    inv_cell_ = 1.0 / cell_size_;
    par::counting_sort(n, cells_, [&](std::size_t i) { return cell_of(x[i]); }, sorted_, scratch_);
  }

  /// Source index (in the store before reordering) of the k-th particle in cell order.
  const std::vector<std::uint32_t>& order() const { return sorted_.order; }
  /// cell_start()[c] .. cell_start()[c+1]: particles of cell c (after reordering).
  const std::vector<std::uint32_t>& cell_start() const { return sorted_.bucket_start; }

  std::size_t cell_count() const { return cells_; }
  /// The largest smoothing length the grid was built for: particle i's neighbours lie within h_i + max_h().
  double max_h() const { return max_h_; }
  double cell_size() const { return cell_size_; }
  const std::array<std::int64_t, D>& dims() const { return dims_; }
  const VecD& origin() const { return origin_; }
  std::size_t particle_count() const { return n_; }

  std::array<std::int64_t, D> coords(const VecD& p) const {
    std::array<std::int64_t, D> c{};
    for (int k = 0; k < D; ++k) {
      auto ck = static_cast<std::int64_t>((p[k] - origin_[k]) * inv_cell_);
      c[k] = std::clamp<std::int64_t>(ck, 0, dims_[k] - 1);
    }
    return c;
  }

  std::size_t linear(const std::array<std::int64_t, D>& c) const {
    std::size_t idx = 0;
    for (int k = D - 1; k >= 0; --k) idx = idx * static_cast<std::size_t>(dims_[k]) + static_cast<std::size_t>(c[k]);
    return idx;
  }

  std::size_t cell_of(const VecD& p) const { return linear(coords(p)); }

  /// Calls f(begin, end) for each contiguous run of candidate particles within `reach` of point p along
  /// every axis: the cells overlapping [p - reach, p + reach]^D, each row along x one run. Runs come in a
  /// fixed order (rows in memory order). coords() is monotone in p, so a particle with |x_j - p|_inf < reach
  /// lies in a scanned cell; the reach is padded by rounding's worth to keep that true in floating point.
  template <class F>
  void for_each_candidate_run(const VecD& p, double reach, F&& f) const {
    const double r = reach * (1.0 + 1e-9) + 1e-15 * p.cwiseAbs().maxCoeff();
    const auto lo = coords(p - VecD::Constant(r));
    const auto hi = coords(p + VecD::Constant(r));
    const auto& start = sorted_.bucket_start;
    const auto x_len = static_cast<std::size_t>(hi[0] - lo[0]);
    if constexpr (D == 1) {
      f(start[static_cast<std::size_t>(lo[0])], start[static_cast<std::size_t>(hi[0]) + 1]);
    } else {
      std::array<std::int64_t, D> q = lo;
      for (;;) {
        const std::size_t first = linear(q);
        f(start[first], start[first + x_len + 1]);
        int k = 1;
        while (k < D && q[k] == hi[k]) {
          q[k] = lo[k];
          ++k;
        }
        if (k == D) break;
        ++q[k];
      }
    }
  }

  /// Calls f(j, r2) for every j != i with |x_i - x_j| < h_i + h_j (= 2 h_ij), in a fixed order.
  template <class F>
  void for_each_neighbour(std::size_t i, const VecD* x, const double* h, F&& f) const {
    const VecD xi = x[i];
    const double hi = h[i];
    for_each_candidate_run(xi, hi + max_h_, [&](std::uint32_t b, std::uint32_t e) {
      for (std::uint32_t j = b; j < e; ++j) {
        if (j == i) continue;
        const double r2 = (xi - x[j]).squaredNorm();
        const double support = hi + h[j];
        if (r2 < support * support) f(j, r2);
      }
    });
  }

 private:
  std::size_t n_ = 0;
  std::size_t cells_ = 0;
  double cell_size_ = 1.0;
  double inv_cell_ = 1.0;
  double max_h_ = 0.5;
  VecD origin_ = VecD::Zero();
  std::array<std::int64_t, D> dims_{};
  par::CountingSortResult sorted_;
  std::vector<std::uint32_t> scratch_;
};

}  // namespace sph
