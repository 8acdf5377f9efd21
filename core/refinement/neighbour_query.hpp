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

template <int D>
class NeighbourQueryIn {
 public:
  explicit NeighbourQueryIn(const ParticleStore<D>& store) : store_(store) {
    // The step's cells and layers (core/neighbour_cells.hpp). The store may still hold the last step's ghosts,
    // of a level no fluid has any more: they go to the deepest layer there is (the query skips them anyway).
    build_level_grid(store, grid_, layer_);
    // Each cell in id order, as in the step (ghosts of one source share its id; the queries skip them): a query
    // meets equal candidates, such as RSP's equally near lattice neighbours, in an order of the particles' own,
    // whatever the store's order.
    const ParticleId* id = store.id.data();
    const Kind* kind = store.kind.data();
    grid_.order_cells_by([id, kind](std::uint32_t a, std::uint32_t b) {
      return id[a] != id[b] ? id[a] < id[b] : kind[a] < kind[b];
    });
  }

  /// Calls f(j, r) for every fluid particle j != i with r_ij < 2 h_ij, in a fixed order; distributed, another rank's
  /// fluid (a halo) is a fluid neighbour too.
  template <class F>
  void for_each_fluid_neighbour(std::size_t i, F&& f) const {
    const auto& order = grid_.order();
    const Vec<D> xi = store_.x[i];
    const double hi = store_.h[i];
    grid_.for_each_support_run(xi, hi, [&](std::uint32_t b, std::uint32_t e) {
      for (std::uint32_t k = b; k < e; ++k) {
        const std::uint32_t j = order[k];
        if (j == i || (store_.kind[j] != Kind::fluid && store_.kind[j] != Kind::halo)) continue;
        const double r2 = (xi - store_.x[j]).squaredNorm();
        const double support = hi + store_.h[j];
        if (r2 < support * support) f(static_cast<std::size_t>(j), std::sqrt(r2));
      }
    });
  }

 private:
  const ParticleStore<D>& store_;
  CellGrid<D> grid_;
  std::vector<std::uint8_t> layer_;  // each particle's grid layer
};
using NeighbourQuery = NeighbourQueryIn<2>;

}  // namespace sph::refine
