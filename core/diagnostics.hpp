#pragma once
// Global diagnostics of the fluid: conserved quantities, energies, extremes and counts per level.
// Every sum is a deterministic chunked reduction, identical at any thread count.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

struct Diagnostics {
  double time = 0.0;
  std::uint64_t step = 0;
  double dt = 0.0;
  double mass = 0.0;
  double kinetic = 0.0;    // sum m v^2 / 2
  double potential = 0.0;  // sum -m g . x
  double elastic = 0.0;    // sum m e(rho), the equation of state's stored energy
  Vec<2> momentum = Vec<2>::Zero();
  double angular_momentum = 0.0;  // about the origin, z component
  double max_speed = 0.0;
  double max_density_error = 0.0;  // max |rho/rho0 - 1|
  std::size_t fluid = 0, ghosts = 0, walls = 0;
  std::vector<std::size_t> per_level;  // fluid particles per refinement level

  double total_energy() const { return kinetic + potential + elastic; }
};

/// Neumaier-compensated sum: its result is the exact sum correctly rounded in all but pathological cases,
/// so it does not change when the particles are reordered or split (mass is compared with ==).
struct CompensatedSum {
  double sum = 0.0, c = 0.0;
  void add(double x) {
    const double t = sum + x;
    c += std::abs(sum) >= std::abs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
  }
  CompensatedSum& merge(const CompensatedSum& o) {
    add(o.sum);
    add(o.c);
    return *this;
  }
  double value() const { return sum + c; }
};

inline Diagnostics compute_diagnostics(const ParticleStore<2>& store, const TaitEquationOfState& eos,
                                       const Vec<2>& gravity) {
  struct Acc {
    CompensatedSum mass;
    double ke = 0, pe = 0, el = 0, L = 0, vmax = 0, derr = 0;
    Vec<2> P = Vec<2>::Zero();
    std::size_t fluid = 0, ghosts = 0, walls = 0;
  };
  const auto& x = store.x.values();
  const auto& v = store.v.values();
  const auto& m = store.m.values();
  const auto& rho = store.rho.values();
  const auto& kind = store.kind.values();
  const Acc acc = par::reduce(
      store.size(), Acc{},
      [&](std::size_t i) {
        Acc a;
        if (kind[i] == Kind::ghost) {
          a.ghosts = 1;
          return a;
        }
        if (kind[i] == Kind::wall) {
          a.walls = 1;
          return a;
        }
        a.fluid = 1;
        a.mass.add(m[i]);
        a.ke = 0.5 * m[i] * v[i].squaredNorm();
        a.pe = -m[i] * gravity.dot(x[i]);
        a.el = m[i] * eos.specific_energy(rho[i]);
        a.P = m[i] * v[i];
        a.L = m[i] * (x[i][0] * v[i][1] - x[i][1] * v[i][0]);
        a.vmax = v[i].norm();
        a.derr = std::abs(rho[i] / eos.rho0 - 1.0);
        return a;
      },
      [](const Acc& a, const Acc& b) {
        Acc c;
        c.mass = a.mass;
        c.mass.merge(b.mass);
        c.ke = a.ke + b.ke;
        c.pe = a.pe + b.pe;
        c.el = a.el + b.el;
        c.P = a.P + b.P;
        c.L = a.L + b.L;
        c.vmax = std::max(a.vmax, b.vmax);
        c.derr = std::max(a.derr, b.derr);
        c.fluid = a.fluid + b.fluid;
        c.ghosts = a.ghosts + b.ghosts;
        c.walls = a.walls + b.walls;
        return c;
      });
  Diagnostics d;
  d.mass = acc.mass.value();
  d.kinetic = acc.ke;
  d.potential = acc.pe;
  d.elastic = acc.el;
  d.momentum = acc.P;
  d.angular_momentum = acc.L;
  d.max_speed = acc.vmax;
  d.max_density_error = acc.derr;
  d.fluid = acc.fluid;
  d.ghosts = acc.ghosts;
  d.walls = acc.walls;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (kind[i] != Kind::fluid) continue;
    const auto l = static_cast<std::size_t>(std::max(0, store.level[i]));
    if (d.per_level.size() <= l) d.per_level.resize(l + 1, 0);
    ++d.per_level[l];
  }
  return d;
}

}  // namespace sph
