#pragma once
// Neighbour queries on the store as it stands between steps (positions have moved since the step's grid
// was built): a cell grid built over the current positions without reordering the store.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/cell_grid.hpp"
#include "core/neighbour_cells.hpp"
#include "core/particle_store.hpp"

namespace sph::refine {

class NeighbourQuery {
 public:
  explicit NeighbourQuery(const ParticleStore<2>& store) : store_(store) {
    // The step's cells and layers (core/neighbour_cells.hpp). The store may still hold the last step's ghosts,
    // of a level no fluid has any more: they go to the deepest layer there is (the query skips them anyway).
    const SmoothingRange hr = smoothing_range(store);
    const int layers = hr.layers();
    const std::size_t n = store.size();
    layer_.resize(n);
    using Box = CellGrid<2>::Box;
    const LayerBoxes<2> boxes = par::accumulate(
        n, LayerBoxes<2>{},
        [&](LayerBoxes<2>& b, std::size_t i) {
          const auto l = static_cast<std::uint8_t>(std::min(grid_layer(store.level[i]), layers - 1));
          layer_[i] = l;
          b[l] = b[l].merged(Box::of(store.x[i]));
        },
        [](const LayerBoxes<2>& a, const LayerBoxes<2>& b) { return merged<2>(a, b); });
    std::array<CellGrid<2>::LayerSpec, kGridLayers> spec;
    neighbour_layers<2>(hr, boxes, spec);
    grid_.build_layers(spec.data(), layers, store.x.data(), layer_.data(), n);
  }

  /// Calls f(j, r) for every fluid particle j != i with r_ij < 2 h_ij, in a fixed order.
  template <class F>
  void for_each_fluid_neighbour(std::size_t i, F&& f) const {
    const auto& order = grid_.order();
    const Vec<2> xi = store_.x[i];
    const double hi = store_.h[i];
    grid_.for_each_support_run(xi, hi, [&](std::uint32_t b, std::uint32_t e) {
      for (std::uint32_t k = b; k < e; ++k) {
        const std::uint32_t j = order[k];
        if (j == i || store_.kind[j] != Kind::fluid) continue;
        const double r2 = (xi - store_.x[j]).squaredNorm();
        const double support = hi + store_.h[j];
        if (r2 < support * support) f(static_cast<std::size_t>(j), std::sqrt(r2));
      }
    });
  }

 private:
  const ParticleStore<2>& store_;
  CellGrid<2> grid_;
  std::vector<std::uint8_t> layer_;  // each particle's grid layer
};

}  // namespace sph::refine
