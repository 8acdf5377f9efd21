#pragma once
// Fixed wall particles (section 2.4, first kind): placed on every wall face at a given spacing;
// they only exert the Lennard-Jones repulsion (eq. 10) and never enter the SPH sums.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/boundary/wall.hpp"
#include "core/particle_store.hpp"

namespace sph {

/// Appends wall particles on each wall face at `spacing`, on a lattice spanning the face (its edges and corners
/// included; along each edge the spacing is the nearest that divides it). Returns how many.
template <int D>
std::size_t add_wall_particles(ParticleStore<D>& store, const std::vector<Wall<D>>& walls, double spacing,
                               double rho0) {
  std::size_t added = 0;
  for (const Wall<D>& w : walls) {
    std::array<std::size_t, D> segments{};
    std::size_t count = 1;
    for (int a = 0; a < D; ++a) {
      segments[static_cast<std::size_t>(a)] =
          a == w.axis ? 0 : static_cast<std::size_t>(std::max(1.0, std::ceil((w.hi[a] - w.lo[a]) / spacing - 1e-9)));
      count *= segments[static_cast<std::size_t>(a)] + 1;
    }
    const std::size_t first = store.append(count);
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t i = first + k;
      Vec<D> x = w.lo;
      std::size_t rest = k;  // k's digits along the axes, the first axis fastest
      for (int a = 0; a < D; ++a) {
        const std::size_t n = segments[static_cast<std::size_t>(a)];
        const std::size_t digit = rest % (n + 1);
        rest /= n + 1;
        if (n > 0) x[a] += (w.hi[a] - w.lo[a]) * static_cast<double>(digit) / static_cast<double>(n);
      }
      store.x[i] = x;
      store.v[i].setZero();
      store.a[i].setZero();
      store.rho[i] = rho0;
      store.p[i] = 0.0;
      store.m[i] = 0.0;
      store.h[i] = 0.0;  // reached only through the fluid particle's own support
      store.d[i] = spacing;
      store.level[i] = 0;
      store.kind[i] = Kind::wall;
      store.drho[i] = 0.0;
    }
    added += count;
  }
  return added;
}

}  // namespace sph
