#pragma once
// Fixed wall particles (section 2.4, first kind): placed along every wall segment at a given spacing;
// they only exert the Lennard-Jones repulsion (eq. 10) and never enter the SPH sums.
#include <cmath>

#include "core/boundary/wall.hpp"
#include "core/particle_store.hpp"

namespace sph {

/// Appends wall particles along each wall at `spacing` (both end points included). Returns how many.
inline std::size_t add_wall_particles(ParticleStore<2>& store, const std::vector<Wall2>& walls, double spacing,
                                      double rho0) {
  std::size_t added = 0;
  for (const Wall2& w : walls) {
    const double len = w.length();
    const auto segments = static_cast<std::size_t>(std::max(1.0, std::ceil(len / spacing - 1e-9)));
    const std::size_t first = store.append(segments + 1);
    for (std::size_t k = 0; k <= segments; ++k) {
      const std::size_t i = first + k;
      const double s = len * static_cast<double>(k) / static_cast<double>(segments);
      store.x[i] = w.p0 + s * w.tangent();
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
    added += segments + 1;
  }
  return added;
}

}  // namespace sph
