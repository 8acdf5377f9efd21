#pragma once
// Global diagnostics of the fluid: conserved quantities, energies, extremes and counts per level.
// Every sum is exact and rounded once (parallel/exact_sum.hpp): the same bits in any order, at any thread count.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <type_traits>
#include <vector>

#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"
#include "parallel/comm.hpp"
#include "parallel/exact_sum.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

/// Angular momentum's type: the z component in 2D, the vector in 3D.
template <int D>
using Angular = std::conditional_t<D == 2, double, Vec<3>>;

/// x cross v: a scalar (z component) in 2D, a vector in 3D.
template <int D>
Angular<D> cross(const Vec<D>& x, const Vec<D>& v) {
  if constexpr (D == 2) {
    return x[0] * v[1] - x[1] * v[0];
  } else {
    return x.cross(v);
  }
}

template <int D>
Angular<D> zero_angular() {
  if constexpr (D == 2) {
    return 0.0;
  } else {
    return Vec<3>::Zero();
  }
}

template <int D>
struct DiagnosticsT {
  double time = 0.0;
  std::uint64_t step = 0;
  double dt = 0.0;
  double mass = 0.0;
  double kinetic = 0.0;    // sum m v^2 / 2
  double potential = 0.0;  // sum -m g . x
  double elastic = 0.0;    // sum m e(rho), the equation of state's stored energy
  Vec<D> momentum = Vec<D>::Zero();
  Angular<D> angular_momentum = zero_angular<D>();  // about the origin (2D: its z component)
  double max_speed = 0.0;
  double max_density_error = 0.0;  // max |rho/rho0 - 1|
  std::size_t fluid = 0, ghosts = 0, walls = 0;
  std::vector<std::size_t> per_level;  // fluid particles per refinement level
  // Fluid removed through the open top so far (the simulation's count, not the store's): M + removed_mass = M0.
  std::uint64_t removed = 0;
  double removed_mass = 0.0;

  double total_energy() const { return kinetic + potential + elastic; }
};
using Diagnostics = DiagnosticsT<2>;

/// The diagnostics of the store's fluid. With `comm` (a distributed run, core/domain.hpp) of every rank's own fluid:
/// the exact sums are merged exactly, so the result has the same bits at any rank count; halos are never counted,
/// wall particles (which every rank holds) once, and ghosts as `own_ghosts` (this rank's own fluid's).
template <int D>
DiagnosticsT<D> compute_diagnostics(const ParticleStore<D>& store, const TaitEquationOfState& eos,
                                    const Vec<D>& gravity, const par::Comm* comm = nullptr,
                                    std::size_t own_ghosts = 0) {
  // Every sum is exact, rounded once (par::ExactSum): the diagnostics are the same bits whatever the store's order
  // and however its particles are split between threads or, in a distributed run, between ranks.
  struct Acc {
    par::ExactSum mass, ke, pe, el;
    std::array<par::ExactSum, D> P{};
    std::array<par::ExactSum, D == 2 ? 1 : 3> L{};
    double vmax = 0, derr = 0;
    std::size_t fluid = 0, ghosts = 0, walls = 0;
  };
  const auto& x = store.x.values();
  const auto& v = store.v.values();
  const auto& m = store.m.values();
  const auto& rho = store.rho.values();
  const auto& kind = store.kind.values();
  const Acc acc = par::accumulate(
      store.size(), Acc{},
      [&](Acc& a, std::size_t i) {
        if (kind[i] == Kind::halo) return;
        if (kind[i] == Kind::ghost) {
          ++a.ghosts;
          return;
        }
        if (kind[i] == Kind::wall) {
          ++a.walls;
          return;
        }
        if (is_passive(store.role[i])) return;  // a copy (buffered coupling): its mass is counted in the active level's
        ++a.fluid;
        a.mass.add(m[i]);
        a.ke.add(0.5 * m[i] * v[i].squaredNorm());
        a.pe.add(-m[i] * gravity.dot(x[i]));
        a.el.add(m[i] * eos.specific_energy(rho[i]));
        const Vec<D> p = m[i] * v[i];
        for (int k = 0; k < D; ++k) a.P[static_cast<std::size_t>(k)].add(p[k]);
        const Angular<D> l = m[i] * cross<D>(x[i], v[i]);
        if constexpr (D == 2) {
          a.L[0].add(l);
        } else {
          for (int k = 0; k < 3; ++k) a.L[static_cast<std::size_t>(k)].add(l[k]);
        }
        a.vmax = std::max(a.vmax, v[i].norm());
        a.derr = std::max(a.derr, std::abs(rho[i] / eos.rho0 - 1.0));
      },
      [](Acc a, const Acc& b) {
        a.mass.merge(b.mass);
        a.ke.merge(b.ke);
        a.pe.merge(b.pe);
        a.el.merge(b.el);
        for (std::size_t k = 0; k < a.P.size(); ++k) a.P[k].merge(b.P[k]);
        for (std::size_t k = 0; k < a.L.size(); ++k) a.L[k].merge(b.L[k]);
        a.vmax = std::max(a.vmax, b.vmax);
        a.derr = std::max(a.derr, b.derr);
        a.fluid += b.fluid;
        a.ghosts += b.ghosts;
        a.walls += b.walls;
        return a;
      });
  Acc all = acc;
  constexpr std::size_t kLevelSlots = 32;
  std::array<std::uint64_t, kLevelSlots> levels{};
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (kind[i] != Kind::fluid || is_passive(store.role[i])) continue;
    ++levels[std::min(kLevelSlots - 1, static_cast<std::size_t>(std::max(0, store.level[i])))];
  }
  if (comm != nullptr && comm->distributed()) {
    all.mass = comm->sum(acc.mass);
    all.ke = comm->sum(acc.ke);
    all.pe = comm->sum(acc.pe);
    all.el = comm->sum(acc.el);
    for (std::size_t k = 0; k < all.P.size(); ++k) all.P[k] = comm->sum(acc.P[k]);
    for (std::size_t k = 0; k < all.L.size(); ++k) all.L[k] = comm->sum(acc.L[k]);
    all.vmax = comm->max(acc.vmax);
    all.derr = comm->max(acc.derr);
    all.fluid = comm->sum(std::uint64_t{acc.fluid});
    all.ghosts = comm->sum(std::uint64_t{own_ghosts});
    all.walls = acc.walls;  // every rank holds them all
    const auto per_rank = comm->all_gather_value(levels);
    levels = {};
    for (const auto& r : per_rank)
      for (std::size_t l = 0; l < kLevelSlots; ++l) levels[l] += r[l];
  }
  DiagnosticsT<D> d;
  d.mass = all.mass.value();
  d.kinetic = all.ke.value();
  d.potential = all.pe.value();
  d.elastic = all.el.value();
  for (int k = 0; k < D; ++k) d.momentum[k] = all.P[static_cast<std::size_t>(k)].value();
  if constexpr (D == 2) {
    d.angular_momentum = all.L[0].value();
  } else {
    for (int k = 0; k < 3; ++k) d.angular_momentum[k] = all.L[static_cast<std::size_t>(k)].value();
  }
  d.max_speed = all.vmax;
  d.max_density_error = all.derr;
  d.fluid = all.fluid;
  d.ghosts = all.ghosts;
  d.walls = all.walls;
  for (std::size_t l = 0; l < kLevelSlots; ++l)
    if (levels[l] > 0) d.per_level.resize(l + 1, 0);
  for (std::size_t l = 0; l < d.per_level.size(); ++l) d.per_level[l] = levels[l];
  return d;
}

/// Stored energy of the Lennard-Jones wall repulsion (eq. 10), the potential of its force:
///   E_LJ = sum over fluid i and wall particles j with r_ij < r0_i of m_i D/12 ((r0/r)^12 - 2 (r0/r)^6 + 1),
/// r0_i = r0_factor d_i; -dphi/dr gives exactly the sweep's acceleration D ((r0/r)^12 - (r0/r)^6) / r and it
/// is zero (and continuous) at r = r0. Add it to Diagnostics::total_energy() in runs with Lennard-Jones walls.
/// Wall particles are binned once per call; each fluid particle sums its walls in store order and the
/// particle sums are reduced deterministically, so the result does not depend on the thread count.
template <int D>
double lennard_jones_energy(const ParticleStore<D>& store, double strength, double r0_factor) {
  const auto& x = store.x.values();
  const auto& kind = store.kind.values();
  const auto& d = store.d.values();
  const auto& m = store.m.values();
  double r0max = 0.0;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (kind[i] == Kind::fluid) r0max = std::max(r0max, r0_factor * d[i]);
  }
  if (!(r0max > 0.0)) return 0.0;
  auto cell = [r0max](double c) { return static_cast<std::int64_t>(std::floor(c / r0max)); };
  // A bin's key; bins whose keys collide share a list, which only adds candidates the distance test drops.
  auto key = [](const std::array<std::int64_t, D>& c) {
    if constexpr (D == 2) {
      return (c[0] << 32) ^ (c[1] & 0xffffffffLL);
    } else {
      return (c[0] << 42) ^ ((c[1] & 0x1fffffLL) << 21) ^ (c[2] & 0x1fffffLL);
    }
  };
  auto cells = [&](const Vec<D>& p) {
    std::array<std::int64_t, D> c{};
    for (int a = 0; a < D; ++a) c[static_cast<std::size_t>(a)] = cell(p[a]);
    return c;
  };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> bins;
  for (std::size_t j = 0; j < store.size(); ++j) {
    if (kind[j] == Kind::wall) bins[key(cells(x[j]))].push_back(j);
  }
  constexpr int kAround = D == 2 ? 9 : 27;  // the bin and its neighbours, first axis slowest
  return par::reduce(
      store.size(), 0.0,
      [&](std::size_t i) {
        if (kind[i] != Kind::fluid || !x[i].allFinite()) return 0.0;
        const double r0 = r0_factor * d[i];
        const std::array<std::int64_t, D> c = cells(x[i]);
        double e = 0.0;
        for (int k = 0; k < kAround; ++k) {
          std::array<std::int64_t, D> b = c;
          int rest = k;
          for (int a = D - 1; a >= 0; --a) {
            b[static_cast<std::size_t>(a)] += rest % 3 - 1;
            rest /= 3;
          }
          const auto it = bins.find(key(b));
          if (it == bins.end()) continue;
          for (const std::size_t j : it->second) {
            const double r2 = (x[i] - x[j]).squaredNorm();
            if (r2 >= r0 * r0 || r2 <= 0.0) continue;
            const double q2 = r0 * r0 / r2, q6 = q2 * q2 * q2;
            e += q6 * q6 - 2.0 * q6 + 1.0;
          }
        }
        return m[i] * strength / 12.0 * e;
      },
      [](double a, double b) { return a + b; });
}

}  // namespace sph
