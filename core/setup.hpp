#pragma once
// Set-up helpers: square lattices of spacing d filling a rectangle or a circle (particles at the centres
// of the lattice cells, so a region starts d/2 from its edges and refining every particle with AAP gives
// the lattice of spacing d/2), and the hydrostatic initial density.
#include <cmath>
#include <vector>

#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"

namespace sph {

/// The mass of a lattice particle of spacing d at density rho: rho d^D (evaluated left to right, as the 2D set-up
/// always has, so its masses are unchanged to the bit).
template <int D>
double lattice_mass(double rho, double d) {
  return D == 2 ? rho * d * d : rho * d * d * d;
}

template <int D>
struct FluidBlockSpecT {
  double spacing = 1.0;   // d^0
  double h_factor = 1.2;  // h = h_factor * d
  int level = 0;
  Vec<D> velocity = Vec<D>::Zero();
};
using FluidBlockSpec = FluidBlockSpecT<2>;

/// Lattice points (cell centres) of spacing d in [lo, hi].
inline std::vector<Vec<2>> lattice_rectangle(const Vec<2>& lo, const Vec<2>& hi, double d) {
  std::vector<Vec<2>> pts;
  const auto nx = static_cast<long>(std::floor((hi[0] - lo[0]) / d + 1e-9));
  const auto ny = static_cast<long>(std::floor((hi[1] - lo[1]) / d + 1e-9));
  pts.reserve(static_cast<std::size_t>(std::max(0L, nx * ny)));
  for (long iy = 0; iy < ny; ++iy)
    for (long ix = 0; ix < nx; ++ix)
      pts.emplace_back(lo[0] + (static_cast<double>(ix) + 0.5) * d, lo[1] + (static_cast<double>(iy) + 0.5) * d);
  return pts;
}

/// Lattice points (cell centres) of spacing d in the 3D box [lo, hi], x fastest.
inline std::vector<Vec<3>> lattice_box(const Vec<3>& lo, const Vec<3>& hi, double d) {
  std::vector<Vec<3>> pts;
  long n[3];
  for (int a = 0; a < 3; ++a) n[a] = static_cast<long>(std::floor((hi[a] - lo[a]) / d + 1e-9));
  pts.reserve(static_cast<std::size_t>(std::max(0L, n[0] * n[1] * n[2])));
  for (long iz = 0; iz < n[2]; ++iz)
    for (long iy = 0; iy < n[1]; ++iy)
      for (long ix = 0; ix < n[0]; ++ix)
        pts.emplace_back(lo[0] + (static_cast<double>(ix) + 0.5) * d, lo[1] + (static_cast<double>(iy) + 0.5) * d,
                         lo[2] + (static_cast<double>(iz) + 0.5) * d);
  return pts;
}

/// Lattice points of spacing d through the centre, inside the circle (the paper's drop: radius 2 m at
/// d = 25/30 m gives its 21 particles).
inline std::vector<Vec<2>> lattice_circle(const Vec<2>& centre, double radius, double d) {
  std::vector<Vec<2>> pts;
  const auto n = static_cast<long>(std::ceil(radius / d)) + 1;
  for (long iy = -n; iy <= n; ++iy)
    for (long ix = -n; ix <= n; ++ix) {
      const Vec<2> p = centre + d * Vec<2>(static_cast<double>(ix), static_cast<double>(iy));
      if ((p - centre).norm() <= radius) pts.push_back(p);
    }
  return pts;
}

/// Lattice points of spacing d through the centre, inside the 3D ball (x fastest).
inline std::vector<Vec<3>> lattice_ball(const Vec<3>& centre, double radius, double d) {
  std::vector<Vec<3>> pts;
  const auto n = static_cast<long>(std::ceil(radius / d)) + 1;
  for (long iz = -n; iz <= n; ++iz)
    for (long iy = -n; iy <= n; ++iy)
      for (long ix = -n; ix <= n; ++ix) {
        const Vec<3> p = centre + d * Vec<3>(static_cast<double>(ix), static_cast<double>(iy), static_cast<double>(iz));
        if ((p - centre).norm() <= radius) pts.push_back(p);
      }
  return pts;
}

/// The lattice of a box (a rectangle in 2D) or of a ball (a disc in 2D), in D dimensions.
template <int D>
std::vector<Vec<D>> lattice_block(const Vec<D>& lo, const Vec<D>& hi, double d) {
  if constexpr (D == 2) {
    return lattice_rectangle(lo, hi, d);
  } else {
    return lattice_box(lo, hi, d);
  }
}
template <int D>
std::vector<Vec<D>> lattice_round(const Vec<D>& centre, double radius, double d) {
  if constexpr (D == 2) {
    return lattice_circle(centre, radius, d);
  } else {
    return lattice_ball(centre, radius, d);
  }
}

/// Appends fluid particles at the given points, at rest density rho0, mass rho0 d^D; returns the store index of the
/// first. The k-th point gets the k-th of points.size() fresh ids. With a `stride` > 1, only the points with
/// k % stride == offset are added (with the ids they would have): the share of one of `stride` ranks, which together
/// hold the block once (issue #19: no rank holds the whole set-up).
template <int D>
std::size_t add_fluid(ParticleStore<D>& store, const std::vector<Vec<D>>& points, const FluidBlockSpecT<D>& spec,
                      double rho0, std::size_t stride = 1, std::size_t offset = 0) {
  const ParticleId id0 = store.take_ids(points.size());
  const std::size_t first = store.size();
  const std::size_t count = points.size() / stride + (offset < points.size() % stride ? 1 : 0);
  store.resize(first + count);
  for (std::size_t c = 0; c < count; ++c) {
    const std::size_t k = c * stride + offset;
    const std::size_t i = first + c;
    store.id[i] = id0 + k;
    store.x[i] = points[k];
    store.v[i] = spec.velocity;
    store.a[i].setZero();
    store.rho[i] = rho0;
    store.p[i] = 0.0;
    store.m[i] = lattice_mass<D>(rho0, spec.spacing);
    store.h[i] = spec.h_factor * spec.spacing;
    store.d[i] = spec.spacing;
    store.level[i] = spec.level;
    store.kind[i] = Kind::fluid;
    store.drho[i] = 0.0;
  }
  return first;
}

/// Hydrostatic initial density for fluid particles in [first, end): p = rho0 g (surface - height), the height
/// along the last axis, rho from the inverse equation of state, so that still water starts near equilibrium.
template <int D>
void set_hydrostatic(ParticleStore<D>& store, std::size_t first, std::size_t end, double surface, double g,
                     const TaitEquationOfState& eos) {
  for (std::size_t i = first; i < end; ++i) {
    const double depth = std::max(0.0, surface - store.x[i][D - 1]);
    store.p[i] = eos.rho0 * g * depth;
    store.rho[i] = eos.density(store.p[i]);
  }
}

}  // namespace sph
