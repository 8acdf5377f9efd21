#pragma once
// The cell size of the neighbour grid, in one place for the step (Simulation::prepare_neighbours) and for
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
#include <algorithm>
#include <cstddef>
#include <limits>

#include "core/particle_store.hpp"
#include "core/types.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

/// Cell edge over the finest smoothing length present.
inline constexpr double kCellPerFinestH = 1.0;

/// The smallest and largest h of the fluid particles.
struct SmoothingRange {
  double min = std::numeric_limits<double>::infinity();
  double max = 0.0;
  bool empty() const { return !(min <= max); }
  /// One particle's contribution.
  static SmoothingRange of(Kind kind, double h) { return kind == Kind::fluid ? SmoothingRange{h, h} : SmoothingRange{}; }
  SmoothingRange merged(const SmoothingRange& o) const {
    return SmoothingRange{std::min(min, o.min), std::max(max, o.max)};
  }
};

/// The range over a whole store (one parallel reduction).
template <int D>
SmoothingRange smoothing_range(const ParticleStore<D>& store) {
  return par::reduce(
      store.size(), SmoothingRange{}, [&](std::size_t i) { return SmoothingRange::of(store.kind[i], store.h[i]); },
      [](const SmoothingRange& a, const SmoothingRange& b) { return a.merged(b); });
}

/// The grid's cell size for a range: kCellPerFinestH h_min. A set without fluid searches nothing: any positive
/// size does, and 1 m keeps the grid small.
inline double neighbour_cell_size(const SmoothingRange& r) {
  if (r.empty() || !(r.min > 0.0)) return 1.0;
  return kCellPerFinestH * r.min;
}

}  // namespace sph
