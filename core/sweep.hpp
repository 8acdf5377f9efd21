#pragma once
// The pair sweep: for every fluid particle i, visit its neighbours j (fluid and ghosts for the SPH sums,
// wall particles for the wall repulsion), compute the pair geometry once, and call each effect of the
// pack inline. Gather-only: i writes its own sums, so no atomics and a fixed summation order.
//
// It also returns the time-step limit of PHYSICS.md:
//   dt_max / C = min( min_i sqrt(h_i / |a_i|), min_i h_i / (c0 + max_j |h_ij v_ij.x_ij / (r_ij^2 + 0.01 h_ij^2)|) ).
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "core/cell_grid.hpp"
#include "core/effects/pair.hpp"
#include "core/kernel.hpp"
#include "core/particle_store.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

struct SweepLimits {
  double dt_force = std::numeric_limits<double>::infinity();  // min sqrt(h/|a|)
  double dt_cfl = std::numeric_limits<double>::infinity();    // min h / (c0 + max mu)
  std::size_t pairs = 0;                                      // interacting pairs visited
};

template <int D, class FluidEffects, class WallEffects>
class PairSweep {
 public:
  PairSweep(FluidEffects fluid, WallEffects wall, double c0, Vec<D> gravity)
      : fluid_(std::move(fluid)), wall_(std::move(wall)), c0_(c0), gravity_(std::move(gravity)) {}

  /// Computes a and drho of every fluid particle (others get zero) from the current state.
  SweepLimits operator()(ParticleView<D> s, const CellGrid<D>& grid) const {
    using Kernel = CubicSpline<D>;
    constexpr bool has_wall_effects = std::tuple_size_v<WallEffects> > 0;
    const double inf = std::numeric_limits<double>::infinity();
    SweepLimits init;
    return par::reduce(
        s.n, init,
        [&](std::size_t i) {
          SweepLimits lim;
          if (s.kind[i] != Kind::fluid) {
            s.a[i].setZero();
            s.drho[i] = 0.0;
            return lim;
          }
          PairSums<D> acc;
          double mu_max = 0.0;
          std::size_t pairs = 0;
          Pair<D> pr;
          pr.i = i;
          const Vec<D> xi = s.x[i];
          const Vec<D> vi = s.v[i];
          const double hi = s.h[i];
          const double inv_hi = 1.0 / hi;
          pr.p_rho2_i = s.p[i] / (s.rho[i] * s.rho[i]);
          grid.for_each_candidate_run(xi, hi + grid.max_h(), [&](std::uint32_t b, std::uint32_t e) {
            for (std::uint32_t j = b; j < e; ++j) {
              const Vec<D> xij = xi - s.x[j];
              const double r2 = xij.squaredNorm();
              const double support = hi + s.h[j];
              if (r2 >= support * support || j == i) continue;
              pr.j = j;
              pr.xij = xij;
              pr.r2 = r2;
              pr.r = std::sqrt(r2);
              pr.hij = 0.5 * support;
              pr.vij = vi - s.v[j];
              pr.vx = pr.vij.dot(xij);
              ++pairs;
              if (s.kind[j] == Kind::wall) {
                if constexpr (has_wall_effects) {
                  std::apply([&](const auto&... eff) { (eff(s, pr, acc), ...); }, wall_);
                }
                continue;
              }
              const double inv_hij = s.h[j] == hi ? inv_hi : 1.0 / pr.hij;
              pr.gradW = Kernel::gradient_factor_inv(pr.r, inv_hij) * xij;
              pr.mu = pr.hij * pr.vx / (r2 + 0.01 * pr.hij * pr.hij);
              std::apply([&](const auto&... eff) { (eff(s, pr, acc), ...); }, fluid_);
              mu_max = std::max(mu_max, std::abs(pr.mu));
            }
          });
          acc.a += gravity_;
          s.a[i] = acc.a;
          s.drho[i] = acc.drho;
          const double an = acc.a.norm();
          lim.dt_force = an > 0.0 ? std::sqrt(hi / an) : inf;
          lim.dt_cfl = hi / (c0_ + mu_max);
          lim.pairs = pairs;
          return lim;
        },
        [](const SweepLimits& x, const SweepLimits& y) {
          return SweepLimits{std::min(x.dt_force, y.dt_force), std::min(x.dt_cfl, y.dt_cfl), x.pairs + y.pairs};
        });
  }

 private:
  FluidEffects fluid_;
  WallEffects wall_;
  double c0_;
  Vec<D> gravity_;
};

}  // namespace sph
