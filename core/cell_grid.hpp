#pragma once
// Uniform cell grids over the particles' bounding boxes. Built by count -> exclusive scan -> stable scatter
// (a parallel counting sort by cell); the caller reorders the store by `order()` so that each cell's
// particles, and the runs of cells along x, are contiguous in memory.
//
// Layers: the particles can be sorted into up to kGridLayers layers (the refinement level, the last layer
// holding every deeper level), each with a grid of its own over its own particles' bounding box, with its own
// cell size. The store is then ordered layer by layer, each layer by cell. A query for particle i scans each
// layer l with the reach h_i + max_h(l): a fine particle among fine ones no longer scans the reach a coarse
// neighbour would need, and a coarse particle far from the fine zone skips its layer. With one layer (a uniform
// run) the grid is exactly the single grid it always was.
//
// Neighbour traversal visits, for particle i, every j != i with r_ij < 2 h_ij = h_i + h_j, in a fixed
// order (layers in order, cells in lexicographic order, particles in store order): deterministic at any
// thread count.
//
// The cell size is free: a query scans the cells that overlap the square [x_i - R, x_i + R]^D, each row of
// cells along x as one contiguous run. The solver's choice, and why, is in core/neighbour_cells.hpp.
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

/// Layers a grid can hold (the refinement levels 0, 1, 2, and 3 and deeper together).
inline constexpr int kGridLayers = 4;

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

  /// One layer's set-up: the bounding box of its particles (an empty Box: the layer has none), its cell size
  /// and the largest smoothing length among its particles (a query around i reaches h_i + max_h there).
  struct LayerSpec {
    Box box;
    double cell_size = 1.0;
    double max_h = 0.0;
    // With `anchored`, the cells lie on a lattice fixed at `anchor` (e.g. below the scene's container): cell
    // boundaries at anchor + k cell_size, whatever the box. Two grids over different subsets of the particles
    // (two ranks' shares with their halos) then put a point in the same cell and walk shared cells in the same
    // order. Points below the anchor fall in its first cell. Without it, the lattice starts at the box's corner.
    bool anchored = false;
    VecD anchor = VecD::Zero();
  };

  /// Sorts particles into cells of size >= `min_cell_size`, one layer. `max_h` is the largest smoothing length
  /// of the particles (a query around particle i reaches h_i + max_h); by default min_cell_size / 2, the
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
    if (max_h < 0.0) max_h = 0.5 * min_cell_size;
    const LayerSpec one{box, min_cell_size, max_h};
    build_layers(&one, 1, x, nullptr, n);
  }

  /// Sorts particles into `count` layers (particle i into layer[i] < count; every particle into layer 0 when
  /// `layer` is null), layer l with the cells and reach of spec[l].
  void build_layers(const LayerSpec* spec, int count, const VecD* x, const std::uint8_t* layer, std::size_t n) {
    if (count < 1 || count > kGridLayers) throw std::invalid_argument("CellGrid::build: layer count out of range");
    n_ = n;
    count_ = count;
    // A relative margin over the requested size: coords() rounds, and a pair at distance ~cell size (up to
    // rounding) could otherwise land two cells apart and be missed. 1e-6 exceeds the rounding error of
    // (p - origin) * inv_cell for any coordinate below kMaxCells cells.
    std::array<double, kGridLayers> size{};
    std::array<Box, kGridLayers> box{};
    for (int l = 0; l < count; ++l) {
      const LayerSpec& sp = spec[l];
      if (!(sp.cell_size > 0.0) || !std::isfinite(sp.cell_size)) {
        throw std::invalid_argument("CellGrid::build: cell size must be positive and finite");
      }
      if (!std::isfinite(sp.max_h)) throw std::invalid_argument("CellGrid::build: max_h must be finite");
      box[l] = sp.box;
      if (n == 0 && count == 1) box[l] = Box{VecD::Zero(), VecD::Zero()};
      if (!empty(box[l])) {
        for (int k = 0; k < D; ++k) {
          if (!std::isfinite(box[l].lo[k]) || !std::isfinite(box[l].hi[k])) {
            throw std::runtime_error("CellGrid::build: a particle position is not finite");
          }
        }
      }
      size[l] = sp.cell_size * (1.0 + 1e-6);
    }
    // The cell counts are sized in floating point first: a far-flung particle (a run going wrong) can make a
    // box so large that the count per axis does not fit an integer. While the layers' cells together exceed the
    // budget, the cells of the layer with the most grow (a few dozen doublings even for an absurd box).
    const auto budget = static_cast<double>(cell_budget(n));
    for (;;) {
      double total = 0.0, most = -1.0;
      int worst = 0;
      for (int l = 0; l < count; ++l) {
        const double c = cells_in(box[l], size[l]);
        total += c;
        if (c > most) most = c, worst = l;
      }
      if (total <= budget) break;
      size[worst] *= 2.0;
    }
    cells_ = 0;
    for (int l = 0; l < count; ++l) {
      Layer& L = layers_[l];
      L = Layer{};
      L.first = cells_;
      L.cell_size = size[l];
      L.inv_cell = 1.0 / size[l];
      L.max_h = spec[l].max_h;
      if (empty(box[l])) continue;
      L.cells = 1;
      L.anchor = box[l].lo;
      if (spec[l].anchored) {
        // The box's cells on the anchored lattice, by the same arithmetic as coords(): offset and dims are whole
        // cells, so every grid anchored alike numbers a point's cell the same way (up to its own offset).
        L.anchor = spec[l].anchor;
        for (int k = 0; k < D; ++k) {
          L.offset[k] = std::max<std::int64_t>(0, static_cast<std::int64_t>((box[l].lo[k] - L.anchor[k]) * L.inv_cell));
          const auto top = static_cast<std::int64_t>((box[l].hi[k] - L.anchor[k]) * L.inv_cell);
          L.dims[k] = std::max<std::int64_t>(1, top - L.offset[k] + 1);
          L.origin[k] = L.anchor[k] + static_cast<double>(L.offset[k]) * size[l];
          L.cells *= static_cast<std::size_t>(L.dims[k]);
        }
      } else {
        for (int k = 0; k < D; ++k) {
          L.dims[k] = static_cast<std::int64_t>(std::floor((box[l].hi[k] - box[l].lo[k]) / size[l])) + 1;
          L.cells *= static_cast<std::size_t>(L.dims[k]);
        }
        L.origin = box[l].lo;
      }
      cells_ += L.cells;
    }
    par::counting_sort(
        n, cells_,
        [&](std::size_t i) {
          const Layer& L = layers_[layer != nullptr ? layer[i] : 0];
          return L.first + L.linear(L.coords(x[i]));
        },
        sorted_, scratch_);
  }

  /// Orders the particles of each cell by `less(a, b)`, a strict total order on the input indices of the cell's
  /// particles (e.g. by particle id). The counting sort keeps each cell's particles in their input order; after
  /// this, the order within a cell, and so every sum that walks the cells, depends on the particles alone and
  /// not on the order they came in: a shuffled store, or a rank's own share of the particles (issue #19).
  template <class Less>
  void order_cells_by(Less&& less) {
    std::uint32_t* order = sorted_.order.data();
    const std::uint32_t* start = sorted_.bucket_start.data();
    par::parallel_for(cells_, [&](std::size_t c) {
      std::uint32_t* b = order + start[c];
      std::uint32_t* e = order + start[c + 1];
      if (e - b > 16) {  // a crowded cell (a grid coarsened to its memory budget): a full sort
        std::sort(b, e, less);
        return;
      }
      for (std::uint32_t* k = b + 1; k < e; ++k) {  // a few particles, mostly in order already
        const std::uint32_t item = *k;
        std::uint32_t* m = k;
        for (; m > b && less(item, m[-1]); --m) *m = m[-1];
        *m = item;
      }
    });
  }

  /// Source index (in the store before reordering) of the k-th particle in cell order.
  const std::vector<std::uint32_t>& order() const { return sorted_.order; }
  /// cell_start()[c] .. cell_start()[c+1]: particles of cell c (after reordering); layer l's cells follow
  /// layer l - 1's.
  const std::vector<std::uint32_t>& cell_start() const { return sorted_.bucket_start; }

  /// Cells of every layer together.
  std::size_t cell_count() const { return cells_; }
  int layer_count() const { return count_; }
  /// The largest smoothing length the grid was built for: particle i's neighbours lie within h_i + max_h().
  double max_h() const {
    double m = 0.0;
    for (int l = 0; l < count_; ++l) m = std::max(m, layers_[static_cast<std::size_t>(l)].max_h);
    return m;
  }
  /// The largest smoothing length of layer l's particles.
  double max_h(int l) const { return layers_[static_cast<std::size_t>(l)].max_h; }
  /// Layer l's cell edge, cell counts per axis and origin (layer 0: a grid of one layer).
  double cell_size(int l = 0) const { return layers_[static_cast<std::size_t>(l)].cell_size; }
  const std::array<std::int64_t, D>& dims(int l = 0) const { return layers_[static_cast<std::size_t>(l)].dims; }
  const VecD& origin(int l = 0) const { return layers_[static_cast<std::size_t>(l)].origin; }
  std::size_t particle_count() const { return n_; }

  /// Layer 0's cell coordinates, linear cell index and cell of a point.
  std::array<std::int64_t, D> coords(const VecD& p) const { return layers_[0].coords(p); }
  std::size_t linear(const std::array<std::int64_t, D>& c) const { return layers_[0].linear(c); }
  std::size_t cell_of(const VecD& p) const { return layers_[0].linear(layers_[0].coords(p)); }

  /// The runs that can hold a neighbour of a particle at p with smoothing length h: in layer l, those within
  /// h + max_h(l). Only the layers for which keep(begin, end) holds, given the layer's particle range.
  template <class F, class Keep>
  SPH_ALWAYS_INLINE void for_each_support_run(const VecD& p, double h, F&& f, Keep&& keep) const {
    const std::uint32_t* start = sorted_.bucket_start.data();
    for (int l = 0; l < count_; ++l) {
      const Layer& L = layers_[static_cast<std::size_t>(l)];
      if (L.cells != 0 && keep(start[L.first], start[L.first + L.cells])) scan(L, p, h + L.max_h, f);
    }
  }
  template <class F>
  void for_each_support_run(const VecD& p, double h, F&& f) const {
    for_each_support_run(p, h, f, [](std::uint32_t, std::uint32_t) { return true; });
  }

  /// Calls f(j, r2) for every j != i with |x_i - x_j| < h_i + h_j (= 2 h_ij), in a fixed order.
  template <class F>
  void for_each_neighbour(std::size_t i, const VecD* x, const double* h, F&& f) const {
    for_each_neighbour_in(i, x, h, [](std::uint32_t, std::uint32_t) { return true; }, f);
  }
  /// for_each_neighbour, walking only the candidate runs [b, e) for which walk(b, e) holds: for a caller that can
  /// tell from a run's range (a range table over the store order) that none of its particles matters.
  template <class Walk, class F>
  void for_each_neighbour_in(std::size_t i, const VecD* x, const double* h, Walk&& walk, F&& f) const {
    for_each_neighbour_in_layers(i, x, h, [](std::uint32_t, std::uint32_t) { return true; }, walk, f);
  }
  /// for_each_neighbour_in, in the layers for which keep(begin, end) holds, given the layer's particle range.
  template <class Keep, class Walk, class F>
  void for_each_neighbour_in_layers(std::size_t i, const VecD* x, const double* h, Keep&& keep, Walk&& walk,
                                    F&& f) const {
    const VecD xi = x[i];
    const double hi = h[i];
    for_each_support_run(
        xi, hi,
        [&](std::uint32_t b, std::uint32_t e) {
          if (!walk(b, e)) return;
          for (std::uint32_t j = b; j < e; ++j) {
            if (j == i) continue;
            const double r2 = (xi - x[j]).squaredNorm();
            const double support = hi + h[j];
            if (r2 < support * support) f(j, r2);
          }
        },
        keep);
  }

 private:
  struct Layer {
    std::size_t first = 0;  // its first cell in the grid's numbering
    std::size_t cells = 0;  // 0: the layer holds no particle
    double cell_size = 1.0;
    double inv_cell = 1.0;
    double max_h = 0.0;
    VecD origin = VecD::Zero();  // the first cell's corner: anchor + offset cell_size
    std::array<std::int64_t, D> dims{};
    VecD anchor = VecD::Zero();             // the lattice's origin (the box's corner when not anchored)
    std::array<std::int64_t, D> offset{};  // the first cell's index on that lattice (>= 0)

    /// The cell index along axis k of the coordinate v (clamped into the layer).
    std::int64_t coord(int k, double v) const {
      const auto ck = static_cast<std::int64_t>((v - anchor[k]) * inv_cell) - offset[k];
      return std::clamp<std::int64_t>(ck, 0, dims[k] - 1);
    }
    std::array<std::int64_t, D> coords(const VecD& p) const {
      std::array<std::int64_t, D> c{};
      for (int k = 0; k < D; ++k) c[k] = coord(k, p[k]);
      return c;
    }
    std::size_t linear(const std::array<std::int64_t, D>& c) const {
      std::size_t idx = 0;
      for (int k = D - 1; k >= 0; --k) idx = idx * static_cast<std::size_t>(dims[k]) + static_cast<std::size_t>(c[k]);
      return idx;
    }
  };

  static bool empty(const Box& b) { return b.lo[0] > b.hi[0]; }
  static double cells_in(const Box& b, double size) {
    if (empty(b)) return 0.0;
    double total = 1.0;
    for (int k = 0; k < D; ++k) total *= std::floor((b.hi[k] - b.lo[k]) / size) + 1.0;
    return total;
  }

  /// The runs of layer L within `reach` of p. coords() is monotone in p, so a particle with
  /// |x_j - p|_inf < reach lies in a scanned cell; the reach is padded by rounding's worth to keep that true
  /// in floating point. A query square that misses the layer's cells on some axis holds none of its particles
  /// (they lie in [origin, origin + dims * cell)), and is skipped.
  template <class F>
  SPH_ALWAYS_INLINE void scan(const Layer& L, const VecD& p, double reach, F& f) const {
    if (L.cells == 0) return;
    const double r = reach * (1.0 + 1e-9) + 1e-15 * p.cwiseAbs().maxCoeff();
    for (int k = 0; k < D; ++k) {
      if (p[k] + r < L.origin[k] || p[k] - r > L.origin[k] + static_cast<double>(L.dims[k]) * L.cell_size) return;
    }
    const auto lo = L.coords(p - VecD::Constant(r));
    const auto hi = L.coords(p + VecD::Constant(r));
    const std::uint32_t* start = sorted_.bucket_start.data() + L.first;
    // One run per row of cells along x, the whole row (rows in memory order). The rows are not clipped to the
    // query's ball: f31f907 clipped them (3D candidates 189 -> 131 per particle-step), but each row's distance,
    // square root and end cells cost more than the candidates they save, in 2D and in 3D. Binaries run in turn,
    // one thread, 1e5 particles (docs/PERFORMANCE.md, 2026-12-03): the 2D pressure sweep took 44-48 ms clipped,
    // 28-34 ms with whole rows; the 3D still tank's step 203-231 ms and 155-219 ms; skipping only the rows
    // beyond reach, without shortening the others, kept most of the cost (2D sweep 30-34 ms against 22-26 ms).
    const auto x_len = static_cast<std::size_t>(hi[0] - lo[0]);
    if constexpr (D == 1) {
      f(start[static_cast<std::size_t>(lo[0])], start[static_cast<std::size_t>(lo[0]) + x_len + 1]);
    } else {
      std::array<std::int64_t, D> q = lo;
      for (;;) {
        const std::size_t first = L.linear(q);
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

  std::size_t n_ = 0;
  std::size_t cells_ = 0;
  int count_ = 1;
  std::array<Layer, kGridLayers> layers_{};
  par::CountingSortResult sorted_;
  std::vector<std::uint32_t> scratch_;
};

}  // namespace sph
