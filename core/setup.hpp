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

/// Visits the lattice points (cell centres) of spacing d in [lo, hi], x fastest.
template <class Visit>
void each_rectangle_point(const Vec<2>& lo, const Vec<2>& hi, double d, Visit&& visit) {
  const auto nx = static_cast<long>(std::floor((hi[0] - lo[0]) / d + 1e-9));
  const auto ny = static_cast<long>(std::floor((hi[1] - lo[1]) / d + 1e-9));
  for (long iy = 0; iy < ny; ++iy)
    for (long ix = 0; ix < nx; ++ix)
      visit(Vec<2>(lo[0] + (static_cast<double>(ix) + 0.5) * d, lo[1] + (static_cast<double>(iy) + 0.5) * d));
}

/// Visits the lattice points (cell centres) of spacing d in the 3D box [lo, hi], x fastest.
template <class Visit>
void each_box_point(const Vec<3>& lo, const Vec<3>& hi, double d, Visit&& visit) {
  long n[3];
  for (int a = 0; a < 3; ++a) n[a] = static_cast<long>(std::floor((hi[a] - lo[a]) / d + 1e-9));
  for (long iz = 0; iz < n[2]; ++iz)
    for (long iy = 0; iy < n[1]; ++iy)
      for (long ix = 0; ix < n[0]; ++ix)
        visit(Vec<3>(lo[0] + (static_cast<double>(ix) + 0.5) * d, lo[1] + (static_cast<double>(iy) + 0.5) * d,
                     lo[2] + (static_cast<double>(iz) + 0.5) * d));
}

/// Visits the lattice points of spacing d through the centre inside the circle, x fastest (the paper's drop:
/// radius 2 m at d = 25/30 m gives its 21 particles).
template <class Visit>
void each_circle_point(const Vec<2>& centre, double radius, double d, Visit&& visit) {
  const auto n = static_cast<long>(std::ceil(radius / d)) + 1;
  for (long iy = -n; iy <= n; ++iy)
    for (long ix = -n; ix <= n; ++ix) {
      const Vec<2> p = centre + d * Vec<2>(static_cast<double>(ix), static_cast<double>(iy));
      if ((p - centre).norm() <= radius) visit(p);
    }
}

/// Visits the lattice points of spacing d through the centre inside the 3D ball, x fastest.
template <class Visit>
void each_ball_point(const Vec<3>& centre, double radius, double d, Visit&& visit) {
  const auto n = static_cast<long>(std::ceil(radius / d)) + 1;
  for (long iz = -n; iz <= n; ++iz)
    for (long iy = -n; iy <= n; ++iy)
      for (long ix = -n; ix <= n; ++ix) {
        const Vec<3> p = centre + d * Vec<3>(static_cast<double>(ix), static_cast<double>(iy), static_cast<double>(iz));
        if ((p - centre).norm() <= radius) visit(p);
      }
}

/// The lattice of a box (a rectangle in 2D) or of a ball (a disc in 2D), in D dimensions, visited.
template <int D, class Visit>
void each_block_point(const Vec<D>& lo, const Vec<D>& hi, double d, Visit&& visit) {
  if constexpr (D == 2) {
    each_rectangle_point(lo, hi, d, visit);
  } else {
    each_box_point(lo, hi, d, visit);
  }
}
template <int D, class Visit>
void each_round_point(const Vec<D>& centre, double radius, double d, Visit&& visit) {
  if constexpr (D == 2) {
    each_circle_point(centre, radius, d, visit);
  } else {
    each_ball_point(centre, radius, d, visit);
  }
}

inline std::vector<Vec<2>> lattice_rectangle(const Vec<2>& lo, const Vec<2>& hi, double d) {
  std::vector<Vec<2>> pts;
  each_rectangle_point(lo, hi, d, [&](const Vec<2>& p) { pts.push_back(p); });
  return pts;
}
inline std::vector<Vec<3>> lattice_box(const Vec<3>& lo, const Vec<3>& hi, double d) {
  std::vector<Vec<3>> pts;
  each_box_point(lo, hi, d, [&](const Vec<3>& p) { pts.push_back(p); });
  return pts;
}
inline std::vector<Vec<2>> lattice_circle(const Vec<2>& centre, double radius, double d) {
  std::vector<Vec<2>> pts;
  each_circle_point(centre, radius, d, [&](const Vec<2>& p) { pts.push_back(p); });
  return pts;
}
inline std::vector<Vec<3>> lattice_ball(const Vec<3>& centre, double radius, double d) {
  std::vector<Vec<3>> pts;
  each_ball_point(centre, radius, d, [&](const Vec<3>& p) { pts.push_back(p); });
  return pts;
}
template <int D>
std::vector<Vec<D>> lattice_block(const Vec<D>& lo, const Vec<D>& hi, double d) {
  std::vector<Vec<D>> pts;
  each_block_point<D>(lo, hi, d, [&](const Vec<D>& p) { pts.push_back(p); });
  return pts;
}
template <int D>
std::vector<Vec<D>> lattice_round(const Vec<D>& centre, double radius, double d) {
  std::vector<Vec<D>> pts;
  each_round_point<D>(centre, radius, d, [&](const Vec<D>& p) { pts.push_back(p); });
  return pts;
}

/// One rank's share of a lattice (issue #19: no rank holds the whole set-up): of the `total` points a visit gives,
/// the k-th with k % stride == offset. With stride 1, the whole lattice.
template <int D>
struct LatticeShare {
  std::vector<Vec<D>> points;
  std::size_t total = 0;
  std::size_t stride = 1, offset = 0;
};
/// `each(visit)` visits a lattice's points in order (each_block_point, each_round_point).
template <int D, class Each>
LatticeShare<D> lattice_share(Each&& each, std::size_t stride, std::size_t offset) {
  LatticeShare<D> share;
  share.stride = stride;
  share.offset = offset;
  each([&](const Vec<D>& p) {
    if (share.total % stride == offset) share.points.push_back(p);
    ++share.total;
  });
  return share;
}

/// Appends fluid particles at a share of a lattice's points, at rest density rho0, mass rho0 d^D; returns the store
/// index of the first. The lattice's k-th point gets the k-th of its `total` fresh ids, so the ranks' shares together
/// are the whole set-up, ids included.
template <int D>
std::size_t add_fluid(ParticleStore<D>& store, const LatticeShare<D>& share, const FluidBlockSpecT<D>& spec, double rho0) {
  const ParticleId id0 = store.take_ids(share.total);
  const std::size_t first = store.size();
  const std::vector<Vec<D>>& points = share.points;
  store.resize(first + points.size());
  for (std::size_t c = 0; c < points.size(); ++c) {
    const std::size_t i = first + c;
    store.id[i] = id0 + c * share.stride + share.offset;
    store.x[i] = points[c];
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

/// Appends fluid particles at the given points (the whole lattice: ids in their order).
template <int D>
std::size_t add_fluid(ParticleStore<D>& store, const std::vector<Vec<D>>& points, const FluidBlockSpecT<D>& spec,
                      double rho0) {
  LatticeShare<D> whole;
  whole.points = points;
  whole.total = points.size();
  return add_fluid(store, whole, spec, rho0);
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
