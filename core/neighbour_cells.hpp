#pragma once
// The cell size and layers of the neighbour grid, in one place for the step (Simulation::prepare_neighbours) and for
// the queries between steps (refinement's NeighbourQuery).
//
// Which particles count: the fluid ones. Ghosts carry their source's h (and the store may still hold the
// previous step's ghosts, about to be rebuilt). Wall particles (Lennard-Jones) have h = 0: a fluid particle
// finds them within its own h_i (h_i + h_j = h_i), and they never search. Counting them made the minimum 0,
// and the cells were then sized by the grid's memory budget (16 cells a particle) instead of by h: an
// accident of how many particles a scene has.
//
// The size itself, kCellPerFinestH * h_min, is chosen by measurement (docs/PERFORMANCE.md, "Robust by
// default"): a query around i scans the cells overlapping [x_i - R, x_i + R]^D with R = h_i + h_max, so
// smaller cells scan less area per particle but cost more cells to sort and more row runs per query. Whole
// step, dam-break block with walls, one thread, 1e5 / 1e6 particles: cells of 0.5 h_min 41.2 / 418 ms,
// h_min 26.5 / 262 ms, 2 h_min 28.0 / 272 ms; instructions over the paper's dam break (callgrind) favour
// h_min over 2 h_min by 5-7 %, fully refined and dynamic alike.
//
// Levels (issue #16): with refined particles present, the grid holds one layer per level (core/cell_grid.hpp),
// each with cells of its own finest h and a reach of its own largest h. A particle scans each layer only as
// far as a neighbour of that layer can be: a fine particle scans the fine layer within h_i + h_fine, not
// h_i + h_coarse, and the coarse layer's cells are as large as in a coarse-only run.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstddef>
#include <vector>
#include <limits>

#include "core/cell_grid.hpp"
#include "core/particle_store.hpp"
#include "core/types.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

/// Cell edge over the finest smoothing length present (in each layer of the grid, that layer's finest).
inline constexpr double kCellPerFinestH = 1.0;

/// The grid layer of a refinement level: its own up to kGridLayers - 2, then one for every deeper level; in a
/// grid of `count` layers, the deepest there is (the store may hold stale ghosts of a level no fluid has).
inline int grid_layer(std::int32_t level, int count = kGridLayers) {
  const int l = level <= 0 ? 0 : (level < kGridLayers - 1 ? static_cast<int>(level) : kGridLayers - 1);
  return l < count ? l : count - 1;
}

/// The smallest and largest h of the fluid particles per grid layer (and so overall).
struct SmoothingRange {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  std::array<double, kGridLayers> layer_min{kInf, kInf, kInf, kInf};
  std::array<double, kGridLayers> layer_max{};
  double min() const { return *std::min_element(layer_min.begin(), layer_min.end()); }
  double max() const { return *std::max_element(layer_max.begin(), layer_max.end()); }
  bool empty() const { return !(min() <= max()); }
  /// Layers up to the deepest that holds fluid (at least one).
  int layers() const {
    int n = 1;
    for (int l = 0; l < kGridLayers; ++l)
      if (layer_min[static_cast<std::size_t>(l)] <= layer_max[static_cast<std::size_t>(l)]) n = l + 1;
    return n;
  }
  /// Folds in one particle.
  void add(Kind kind, double h, std::int32_t level) {
    if (kind != Kind::fluid) return;
    const auto l = static_cast<std::size_t>(grid_layer(level));
    layer_min[l] = std::min(layer_min[l], h);
    layer_max[l] = std::max(layer_max[l], h);
  }
  SmoothingRange merged(const SmoothingRange& o) const {
    SmoothingRange r;
    for (std::size_t l = 0; l < layer_min.size(); ++l) {
      r.layer_min[l] = std::min(layer_min[l], o.layer_min[l]);
      r.layer_max[l] = std::max(layer_max[l], o.layer_max[l]);
    }
    return r;
  }
};

/// The range over a whole store (one parallel reduction).
template <int D>
SmoothingRange smoothing_range(const ParticleStore<D>& store) {
  return par::accumulate(
      store.size(), SmoothingRange{},
      [&](SmoothingRange& r, std::size_t i) { r.add(store.kind[i], store.h[i], store.level[i]); },
      [](const SmoothingRange& a, const SmoothingRange& b) { return a.merged(b); });
}

/// The grid's cell size for a range: kCellPerFinestH h_min. A set without fluid searches nothing: any positive
/// size does, and 1 m keeps the grid small.
inline double neighbour_cell_size(const SmoothingRange& r) {
  if (r.empty() || !(r.min() > 0.0)) return 1.0;
  return kCellPerFinestH * r.min();
}

/// The bounding boxes of the grid's layers, reduced with the particles' layers.
template <int D>
using LayerBoxes = std::array<typename CellGrid<D>::Box, kGridLayers>;

template <int D>
LayerBoxes<D> merged(const LayerBoxes<D>& a, const LayerBoxes<D>& b) {
  LayerBoxes<D> r;
  for (std::size_t l = 0; l < r.size(); ++l) r[l] = a[l].merged(b[l]);
  return r;
}

/// The layers of the neighbour grid for a range and the layers' boxes: layer l holds refinement level l (the
/// last one the deeper levels too); its cells are sized by its own finest fluid h (a layer without fluid, such
/// as walls alone, by the finest overall) and its queries reach h_i + its largest h. With `anchor`, every layer's
/// cells lie on the lattice anchored there (grid_anchor below). Returns the layer count.
template <int D>
int neighbour_layers(const SmoothingRange& r, const LayerBoxes<D>& boxes,
                     std::array<typename CellGrid<D>::LayerSpec, kGridLayers>& spec, const Vec<D>* anchor = nullptr) {
  const int count = r.layers();
  for (int l = 0; l < count; ++l) {
    const auto k = static_cast<std::size_t>(l);
    const bool fluid = r.layer_min[k] <= r.layer_max[k] && r.layer_min[k] > 0.0;
    spec[k].box = boxes[k];
    spec[k].cell_size = fluid ? kCellPerFinestH * r.layer_min[k] : neighbour_cell_size(r);
    spec[k].max_h = r.layer_max[k];
    spec[k].anchored = anchor != nullptr;
    if (anchor != nullptr) spec[k].anchor = *anchor;
  }
  return count;
}

/// Where the step's cell lattice is anchored (CellGrid::LayerSpec::anchor): one container size below the
/// container's lower corner, below any ghost. A function of the scene alone, so that a grid over part of the
/// particles (a rank's share and its halo, issue #19) cuts its cells where the whole grid does.
template <class Container>
auto grid_anchor(const Container& container) {
  return (container.lo - (container.hi - container.lo)).eval();
}

/// The solver's layered grid over a store as it stands (not reordered): the layers of neighbour_layers(), each
/// particle in the layer of its level (`layer` receives them), on the lattice anchored at `anchor` when given.
/// For queries between steps (refinement's NeighbourQuery) and the tests; the step builds its grid over the
/// ghost-expanded set in the same way (Simulation::build_neighbours), reducing the boxes in its expansion loop.
template <int D>
void build_level_grid(const ParticleStore<D>& store, CellGrid<D>& grid, std::vector<std::uint8_t>& layer,
                      const Vec<D>* anchor = nullptr) {
  using Box = typename CellGrid<D>::Box;
  const SmoothingRange hr = smoothing_range(store);
  const int layers = hr.layers();
  const std::size_t n = store.size();
  layer.resize(n);
  const LayerBoxes<D> boxes = par::accumulate(
      n, LayerBoxes<D>{},
      [&](LayerBoxes<D>& b, std::size_t i) {
        const auto l = static_cast<std::uint8_t>(grid_layer(store.level[i], layers));
        layer[i] = l;
        b[l] = b[l].merged(Box::of(store.x[i]));
      },
      [](const LayerBoxes<D>& a, const LayerBoxes<D>& b) { return merged<D>(a, b); });
  std::array<typename CellGrid<D>::LayerSpec, kGridLayers> spec;
  neighbour_layers<D>(hr, boxes, spec, anchor);
  grid.build_layers(spec.data(), layers, store.x.data(), layer.data(), n);
}

}  // namespace sph
