#pragma once
// Helpers shared by the physics tests: building small particle sets by hand, running one pair sweep on
// them, and reading a simulation's fluid state back in id order (independent of the store's cell order).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "core/cell_grid.hpp"
#include "core/diagnostics.hpp"
#include "core/setup.hpp"
#include "core/neighbour_cells.hpp"
#include "core/particle_store.hpp"
#include "core/simulation.hpp"
#include "core/solver_settings.hpp"
#include "core/sweep_factory.hpp"
#include "core/types.hpp"

namespace sph::test {

/// One particle's data, for building stores by hand.
template <int D>
struct ParticleInitT {
  Vec<D> x = Vec<D>::Zero();
  Vec<D> v = Vec<D>::Zero();
  double rho = 1000.0;
  double m = 1.0;
  double h = 1.0;
  double d = 1.0;
  int level = 0;
  Kind kind = Kind::fluid;
};
using ParticleInit = ParticleInitT<2>;

/// Appends one particle; its pressure comes from `eos` (fluid and ghosts) or is zero (walls).
template <int D>
std::size_t add_particle(ParticleStore<D>& s, const ParticleInitT<D>& p, const TaitEquationOfState& eos) {
  const std::size_t i = s.append(1);
  s.x[i] = p.x;
  s.v[i] = p.v;
  s.rho[i] = p.rho;
  s.p[i] = p.kind == Kind::wall ? 0.0 : eos.pressure(p.rho);
  s.m[i] = p.m;
  s.h[i] = p.h;
  s.d[i] = p.d;
  s.level[i] = p.level;
  s.kind[i] = p.kind;
  return i;
}

/// A fixed wall particle at x (no mass, no smoothing length: reached through the fluid particle's support).
template <int D>
ParticleInitT<D> wall_particle(const Vec<D>& x, double spacing, double rho0) {
  ParticleInitT<D> w;
  w.x = x;
  w.m = 0.0;
  w.h = 0.0;
  w.d = spacing;
  w.rho = rho0;
  w.kind = Kind::wall;
  return w;
}

/// A random cloud of `n` fluid particles in [0, side]^D on two refinement levels (level 1: half the
/// spacing, 2^-D of the mass, half the smoothing length), with random velocities and densities
/// within 1 % of rho0. Positions are jittered lattice-free uniform draws, so pair geometries are generic.
template <int D = 2>
ParticleStore<D> random_cloud(std::size_t n, double side, double d0, const TaitEquationOfState& eos,
                              std::uint32_t seed, double speed = 1.0) {
  ParticleStore<D> s;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(0.0, side), unit(-1.0, 1.0);
  for (std::size_t k = 0; k < n; ++k) {
    const int level = (k % 3 == 0) ? 1 : 0;
    const double d = level == 1 ? 0.5 * d0 : d0;
    ParticleInitT<D> p;
    if constexpr (D == 2) {
      p.x = Vec<2>(pos(rng), pos(rng));
      p.v = speed * Vec<2>(unit(rng), unit(rng));
    } else {
      for (int a = 0; a < D; ++a) p.x[a] = pos(rng);
      for (int a = 0; a < D; ++a) p.v[a] = speed * unit(rng);
    }
    p.rho = eos.rho0 * (1.0 + 0.01 * unit(rng));
    p.m = lattice_mass<D>(eos.rho0, d);
    p.h = 1.2 * d;
    p.d = d;
    p.level = level;
    add_particle(s, p, eos);
  }
  return s;
}

template <int D>
double max_h(const ParticleStore<D>& s) {
  double hmax = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) hmax = std::max(hmax, s.h[i]);
  return hmax;
}

/// Builds the cell grid over the store and reorders the store into cell order (as the solver does).
template <int D>
void build_grid(ParticleStore<D>& s, CellGrid<D>& grid) {
  grid.build(s.x.data(), s.size(), std::max(2.0 * max_h(s), 1e-12));
  s.gather(grid.order());
}

/// The solver's grid with one layer per level (build_level_grid), the store reordered into its order.
template <int D>
void build_level_grid_in_order(ParticleStore<D>& s, CellGrid<D>& grid) {
  std::vector<std::uint8_t> layer;
  build_level_grid(s, grid, layer);
  s.gather(grid.order());
}

/// Reorders the store into cell order and runs the sweep that `settings` selects on it.
template <int D>
SweepLimits run_sweep(ParticleStore<D>& s, const SolverSettingsT<D>& settings) {
  CellGrid<D> grid;
  build_grid(s, grid);
  return make_sweep(settings)->run(s.view(), grid);
}

/// Settings of an isolated system: no gravity, no walls, no ghosts, no wall repulsion.
template <int D = 2>
SolverSettingsT<D> isolated_settings(double c0 = 10.0, bool viscosity = true) {
  SolverSettingsT<D> st;
  st.eos.rho0 = 1000.0;
  st.eos.c0 = c0;
  st.gravity.reset();
  st.ghosts.reset();
  st.lennard_jones.reset();
  if (!viscosity) st.viscosity.reset();
  return st;
}

/// Index of each id in the store (ids must be below the store's next id).
template <int D>
std::vector<std::size_t> index_by_id(const ParticleStore<D>& s, Kind kind = Kind::fluid) {
  std::vector<std::size_t> idx(static_cast<std::size_t>(s.next_id()), static_cast<std::size_t>(-1));
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.kind[i] == kind) idx[static_cast<std::size_t>(s.id[i])] = i;
  return idx;
}

/// Sum of the fluid masses taken in id order, so it does not depend on the store's (cell) order.
template <int D>
double mass_by_id(const ParticleStore<D>& s) {
  double total = 0.0;
  for (std::size_t i : index_by_id(s))
    if (i != static_cast<std::size_t>(-1)) total += s.m[i];
  return total;
}

/// Sum over fluid particles of m |v| and of m |x| |v| (scales for momentum and angular momentum).
struct MomentumScales {
  double linear = 0.0;
  double angular = 0.0;
};

template <int D>
MomentumScales momentum_scales(const ParticleStore<D>& s) {
  MomentumScales sc;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    sc.linear += s.m[i] * s.v[i].norm();
    sc.angular += s.m[i] * s.x[i].norm() * s.v[i].norm();
  }
  return sc;
}

/// Total linear and angular momentum (about the origin) of the fluid, summed in id order.
template <int D>
struct MomentaT {
  Vec<D> P = Vec<D>::Zero();
  Angular<D> L = zero_angular<D>();
};
using Momenta = MomentaT<2>;

template <int D>
MomentaT<D> momenta_by_id(const ParticleStore<D>& s) {
  MomentaT<D> out;
  for (std::size_t i : index_by_id(s)) {
    if (i == static_cast<std::size_t>(-1)) continue;
    out.P += s.m[i] * s.v[i];
    out.L += s.m[i] * cross<D>(s.x[i], s.v[i]);
  }
  return out;
}

template <int D>
bool all_finite(const ParticleStore<D>& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!s.x[i].allFinite() || !s.v[i].allFinite() || !s.a[i].allFinite()) return false;
    if (!std::isfinite(s.rho[i]) || !std::isfinite(s.p[i]) || !std::isfinite(s.drho[i])) return false;
  }
  return true;
}

}  // namespace sph::test
