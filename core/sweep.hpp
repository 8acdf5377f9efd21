#pragma once
// The pair sweep: for every fluid particle i, visit its neighbours j (fluid and ghosts for the SPH sums,
// wall particles for the wall repulsion), compute the pair geometry once, and call each effect of the
// pack inline. Gather-only: i writes its own sums, so no atomics and a fixed summation order.
//
// It also returns the time-step limit of PHYSICS.md:
//   dt_max / C = min( min_i sqrt(h_i / |a_i|), min_i h_i / (c0 + max_j |h_ij v_ij.x_ij / (r_ij^2 + 0.01 h_ij^2)|) ).
//
// Time bins (core/integrator.hpp): particle i is in bin b_i = min(level_i, bin_cap) and steps dt0 / 2^b_i. A
// pair steps at its finer member's rate, b_ij = max(b_i, b_j). A sweep at a substep where the bins >= active_bin
// are due evaluates only the pairs with b_ij >= active_bin, each weighted by 2^-b_ij, and writes for every fluid
// particle the weighted sums (kick, kick_rho: the integrator kicks v and rho by dt0 times them, so a pair's
// impulse on i and on j is equal and opposite, at the same instant). A particle that is due (b_i >= active_bin)
// also gets its rates a = 2^b_i kick and drho, and its limits, scaled by 2^b_i to a limit on dt0. With
// bin_cap = 0 (one global step) every weight is 1 and the sweep is the plain one.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <new>
#include <stdexcept>
#include <tuple>
#include <type_traits>

#include "core/cell_grid.hpp"
#include "core/effects/pair.hpp"
#include "core/kernel.hpp"
#include "core/particle_store.hpp"
#include "core/sweep_probe.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

struct SweepLimits {
  double dt_force = std::numeric_limits<double>::infinity();  // min 2^b sqrt(h/|a|)
  double dt_cfl = std::numeric_limits<double>::infinity();    // min 2^b h / (c0 + max mu)
  std::size_t pairs = 0;                                      // interacting pairs evaluated
  int finest_bin = 0;                                         // largest bin of a due fluid particle
  std::size_t candidates = 0;                                 // candidates checked (in the runs scanned)

  /// The limits of two sets of particles together (threads' shares of a sweep, or ranks').
  SweepLimits merged(const SweepLimits& o) const {
    return SweepLimits{std::min(dt_force, o.dt_force), std::min(dt_cfl, o.dt_cfl), pairs + o.pairs,
                       std::max(finest_bin, o.finest_bin), candidates + o.candidates};
  }
};

/// 2^-b and 2^b for a bin b (a table: std::ldexp in the pair loop cost 6 % of a step).
inline constexpr auto kBinWeight = [] {
  std::array<double, kBinCount> w{};
  for (int b = 0; b < kBinCount; ++b) w[static_cast<std::size_t>(b)] = 1.0 / static_cast<double>(1u << b);
  return w;
}();
inline constexpr auto kBinScale = [] {
  std::array<double, kBinCount> w{};
  for (int b = 0; b < kBinCount; ++b) w[static_cast<std::size_t>(b)] = static_cast<double>(1u << b);
  return w;
}();

/// Which pairs a sweep evaluates: those whose bin max(b_i, b_j) is at least active_bin, with
/// b_i = min(bin_i, bin_cap) (the store's time bin). The default (0, 0) is the single-rate sweep: every pair,
/// weight 1.
struct Activity {
  int active_bin = 0;
  int bin_cap = 0;
  // The last evaluation of a step in which some particle's bin changes (active_bin 0): kick and kick_rho take the
  // pairs weighted by this step's bins (the closing kick), a, drho and the limits by next_bin's (the next step's
  // opening kick and dt0).
  bool rebin = false;
  // Optional, with active_bin > 0: due_prefix[k] counts the due particles (fluid or ghost, bin >= active_bin)
  // among the first k of the store. A particle that is not due skips every candidate run without one.
  const std::uint32_t* due_prefix = nullptr;
  // Optional, with due_prefix: the store indices of the due particles in store order, so that the due particles of
  // a run [b, e) are due_index[due_prefix[b] .. due_prefix[e]). A particle that is not due then walks only those,
  // in the same order as the run's: the same pairs and sums, without the candidates that cannot pair with it.
  const std::uint32_t* due_index = nullptr;
  // The coarse step dt0 of the step this evaluation belongs to: a due particle's last evaluation was dt0 2^-b ago, and
  // the sweep sets its jerk from the two. 0 for an evaluation that does not end a step (Simulation::refresh, after a
  // refinement pass or at set-up): the jerk is then left as it is.
  double dt0 = 0.0;
  // Buffered levels (LevelCoupling::buffered, core/refinement/buffer.hpp): a fluid particle pairs only with fluid and
  // ghosts of its own level, and a passive particle gets no sums (as a wall); wall particles pair as always.
  bool own_level_only = false;
  // The finest bin (bin(), capped) of any particle in the store but the walls, so of any particle a fluid particle
  // pairs with by bins: a due particle in it pairs at its own bin with all of them, and the binned loop walks its
  // pairs without reading their bins. kBinCount where unknown: no particle is in it.
  int top_bin = kBinCount;
  int bin(std::int32_t b) const { return b < bin_cap ? static_cast<int>(b) : bin_cap; }
};

/// The acoustic length L_i of a particle's time-step limit dt_cfl,i = L_i / (c0 + max_j |mu_ij|), before the
/// Courant number: h_i, or shorter where the neighbourhood is stiff enough to take the particle's fastest acoustic
/// mode beyond what the predictor keeps stable (docs/METHOD.md, "The predictor").
struct AcousticLimit {
  /// The fastest acoustic mode's frequency over (c0 / rho_i) sum_j m_j |grad W_ij| at the particles it lives on:
  /// 0.53-0.61, measured on the three-level dam break's frames, 0.59 on the 2D lattice (docs/METHOD.md, "Time step and
  /// three refinement levels"); the upper end, so that the bound holds for each.
  static constexpr double kFastestModeShare = 0.61;
  /// The largest z = omega dt allowed with the extrapolated predictor: it damps every mode up to z = 0.67 (the linear
  /// analysis of one acoustic mode, tools/acoustic_amplification.py), and grows them beyond. Three quarters of that,
  /// because the analysis holds the positions fixed and takes one mode at a time.
  static constexpr double kMaxZ = 0.5;

  TimePredictor predictor = TimePredictor::extrapolated;
  double cfl = 0.2;  // the Courant number the limit is multiplied by (time.cfl)

  /// last_rate: kappa(h / d) rho / grad_mass where shorter than h (LatticeGradientSum::acoustic_length), which keeps
  /// every particle's fastest mode at its own lattice's z; the last-rate prediction grows every mode, and on the
  /// lattice the artificial viscosity outweighs that. extrapolated: kMaxZ rho / (kFastestModeShare cfl grad_mass)
  /// where shorter than h, so that omega dt <= kMaxZ (at C = 0.2 in 2D a neighbourhood about twice as stiff as the
  /// lattice's).
  template <int D>
  double length(const LatticeGradientSum<D>& lattice, double h, double d, double rho, double grad_mass) const {
    if (predictor == TimePredictor::last_rate) return lattice.acoustic_length(h, d, rho, grad_mass);
    if (!(grad_mass > 0.0)) return h;
    return std::min(h, kMaxZ * rho / (kFastestModeShare * cfl * grad_mass));
  }
};

template <int D, class FluidEffects, class WallEffects>
class PairSweep {
 public:
  PairSweep(FluidEffects fluid, WallEffects wall, double c0, Vec<D> gravity, AcousticLimit acoustic = {})
      : fluid_(std::move(fluid)), wall_(std::move(wall)), c0_(c0), gravity_(std::move(gravity)), acoustic_(acoustic) {}


  /// Computes kick and kick_rho of every fluid particle, and a and drho of the due ones (others get zero),
  /// from the current state.
  SweepLimits operator()(ParticleView<D> s, const CellGrid<D>& grid, Activity act = {}) const {
    // One loop per kind of evaluation, chosen once per sweep: the single-rate sweep (every bin 0, weight 1, no
    // lists of due particles) carries no per-pair bin look-ups, due tests or second sums. In six alternating pairs
    // the 2D pressure sweep at 1e5 took a median 25.5 ms against 31.6 ms in the shared loop (docs/PERFORMANCE.md,
    // 2026-12-03). Where they overlap the loops give the same bits: with bin_cap 0 every weight is 1.
    // Own level only (buffered levels): the same three loops, each with the pairs of other levels skipped.
    const bool binned = act.bin_cap > 0 || act.active_bin > 0 || act.due_prefix != nullptr;
    if (act.own_level_only) {
      if (act.rebin) return sweep<true, true, true>(s, grid, act);
      if (binned) return sweep<true, false, true>(s, grid, act);
      return sweep<false, false, true>(s, grid, act);
    }
    if (act.rebin) return sweep<true, true>(s, grid, act);
    if (binned) return sweep<true, false>(s, grid, act);
    return sweep<false, false>(s, grid, act);
  }

 private:
  /// Binned: the pairs' bins, weights and the due particles' lists are read (a step of a per-level run).
  /// Rebin: also the sums by the next step's bins (Activity::rebin). Neither: every particle is due, in bin 0.
  template <bool Binned, bool Rebin, bool OwnLevel = false>
  SweepLimits sweep(ParticleView<D> s, const CellGrid<D>& grid, const Activity& act) const {
    static_assert(Binned || !Rebin, "a rebin sweep reads the bins");
    using Kernel = CubicSpline<D>;
    constexpr bool has_wall_effects = std::tuple_size_v<WallEffects> > 0;
    const double inf = std::numeric_limits<double>::infinity();
    SweepLimits init;
    // One particle's sums, rates and limits.
    const auto particle = [&](std::size_t i) SPH_ALWAYS_INLINE {
      SweepLimits lim;
      if (s.kind[i] != Kind::fluid || is_passive(s.role[i])) {
        s.a[i].setZero();
        s.drho[i] = 0.0;
        s.kick[i].setZero();
        s.kick_rho[i] = 0.0;
        // A passive particle has no limit of its own: its bin is its level's (Integrator::bin_for with no limit),
        // and it sets neither the coarse step nor a neighbour's bin. (Ghosts keep the limit copied from their
        // source, which the neighbourhood bins read.)
        if (s.kind[i] == Kind::fluid) {
          s.dt_limit[i] = 0.0;
          s.stiffness[i] = 1.0;
        }
        return lim;
      }
      const int bi = Binned ? act.bin(s.bin[i]) : 0;
      const int nbi = Rebin ? act.bin(s.next_bin[i]) : bi;
      const bool due = !Binned || bi >= act.active_bin;
      const bool top = Binned && !Rebin && due && bi >= act.top_bin;  // every pair in i's own bin (Activity::top_bin)
      PairSums<D> acc;
      PairSums<D> next;  // with act.rebin: the sums weighted by the next bins
      // A due particle's pairs by their bin b_ij (binned loop), each class weighted 2^-b_ij; acc is then their sum
      // in class order, and the full-weight rates (full_a) sum them at 2^b_ij. The class of i's own bin, which holds
      // nearly every pair, is summed in acc itself and the finer classes in by_bin: the same terms in the same order
      // as one array of classes, so the same bits. by_bin's classes are constructed when first used: zeroing all
      // kBinCount of them at every evaluation was part of what the binned loop cost over the single-rate one
      // (docs/PERFORMANCE.md, "The binned loop's own cost").
      ClassSums<Binned && !Rebin ? kBinCount : 1> by_bin;
      std::uint32_t bins_used = 0;  // the classes finer than i's own bin that hold a pair
      bool own_used = false;        // whether i's own class holds a pair
      const auto finer_sums = [&](int b) -> PairSums<D>& {
        const auto k = static_cast<std::size_t>(b);
        if (!(bins_used & (1u << b))) {
          ::new (static_cast<void*>(&by_bin.c[k])) PairSums<D>{};
          bins_used |= 1u << b;
        }
        return by_bin.c[k];
      };
      PairSums<D> full;  // with act.rebin: the sums at full weight
      double mu_max = 0.0;
      double grad_mass = 0.0;  // sum_j m_j |grad W_ij| over the fluid and ghost pairs: the acoustic stiffness
      std::size_t pairs = 0, candidates = 0;
      Pair<D> pr;
      pr.i = i;
      const Vec<D> xi = s.x[i];
      const Vec<D> vi = s.v[i];
      const double hi = s.h[i];
      const double inv_hi = 1.0 / hi;
      pr.p_rho2_i = s.p[i] / (s.rho[i] * s.rho[i]);
      // Wall particles act only within the wall effects' reach (Lennard-Jones: r0 = r0_factor d_i, well inside
      // the support h_i), so those beyond it are skipped before the pair's geometry is computed. The bound is
      // widened by a relative 1e-12 so that every pair the effect's own test (r < r0) keeps passes it: the
      // results do not change, only the work.
      double wall_reach2 = 0.0;
      if constexpr (has_wall_effects) {
        double reach = 0.0;
        std::apply([&](const auto&... eff) { ((reach = std::max(reach, eff.reach(s, i))), ...); }, wall_);
        reach *= 1.0 + 1e-12;
        wall_reach2 = reach * reach;
      }
      // A particle that is not due only meets due ones: it skips a layer (a level) or a run without any.
      const bool all = !Binned || due || act.due_prefix == nullptr;
      const auto holds_due = [&](std::uint32_t b, std::uint32_t e) { return all || act.due_prefix[e] != act.due_prefix[b]; };
      // Only the due candidates of a run when i is not due and their list is there: a pair with i is due only
      // when j is (b_ij = b_j >= active bin), and walls pair only with due particles.
      const bool due_only = Binned && !all && act.due_index != nullptr;
      // The candidate runs, walked by one of two loops: for a particle in the top bin, b_ij = b_i without a look-up.
      const auto walk = [&](auto top_tag, std::uint32_t b, std::uint32_t e) SPH_ALWAYS_INLINE {
        constexpr bool Top = decltype(top_tag)::value;
        if (!holds_due(b, e)) return;
        const std::uint32_t first = due_only ? act.due_prefix[b] : b;
        const std::uint32_t last = due_only ? act.due_prefix[e] : e;
        candidates += last - first;
        for (std::uint32_t q = first; q < last; ++q) {
          const std::uint32_t j = due_only ? act.due_index[q] : q;
          const Vec<D> xij = xi - s.x[j];
          const double r2 = xij.squaredNorm();
          const double support = hi + s.h[j];
          if (r2 >= support * support || j == i) continue;
          if constexpr (OwnLevel) {
            if (s.kind[j] != Kind::wall && s.level[j] != s.level[i]) continue;
          }
          if (s.kind[j] == Kind::wall && !((!Binned || due) && r2 < wall_reach2)) continue;
          pr.j = j;
          pr.xij = xij;
          pr.r2 = r2;
          pr.r = std::sqrt(r2);
          pr.hij = 0.5 * support;
          pr.vij = vi - s.v[j];
          pr.vx = pr.vij.dot(xij);
          if (s.kind[j] == Kind::wall) {  // due, and within the wall effects' reach
            ++pairs;
            if constexpr (has_wall_effects) {
              if constexpr (!Rebin) {  // a wall pair is in i's own class
                pr.weight = Binned ? kBinWeight[static_cast<std::size_t>(bi)] : 1.0;
                own_used = true;
                std::apply([&](const auto&... eff) { (eff(s, pr, acc), ...); }, wall_);
              } else {
                PairSums<D> one;
                pr.weight = 1.0;
                std::apply([&](const auto&... eff) { (eff(s, pr, one), ...); }, wall_);
                add_weighted(acc, one, bi);
                add_weighted(next, one, nbi);
                add_weighted(full, one, 0);
              }
            }
            continue;
          }
          int bij = 0;
          if constexpr (Top) {
            bij = bi;
          } else if constexpr (Binned) {
            const int bj = act.bin(s.bin[j]);
            bij = bi > bj ? bi : bj;
            if (bij < act.active_bin) continue;
          }
          ++pairs;
          const double inv_hij = s.h[j] == hi ? inv_hi : 1.0 / pr.hij;
          const double factor = Kernel::gradient_factor_inv(pr.r, inv_hij);
          grad_mass += s.m[j] * std::abs(factor) * pr.r;
          pr.mu = pr.hij * pr.vx / (r2 + 0.01 * pr.hij * pr.hij);
          if constexpr (!Binned) {
            pr.weight = 1.0;
            pr.gradW = factor * xij;
            std::apply([&](const auto&... eff) { (eff(s, pr, acc), ...); }, fluid_);
          } else if constexpr (!Rebin) {
            // 2^-b_ij scales every fluid pair term (each is linear in grad W); a power of two, so exact.
            pr.weight = kBinWeight[static_cast<std::size_t>(bij)];
            pr.gradW = (pr.weight * factor) * xij;
            // Into i's own class (acc), or for a particle that is not due its kick alone; else a finer class: one
            // copy of the effects' code for both.
            PairSums<D>* into = &acc;
            if (Top || bij == bi || !due) {
              own_used = true;
            } else {
              into = &finer_sums(bij);
            }
            std::apply([&](const auto&... eff) { (eff(s, pr, *into), ...); }, fluid_);
          } else {  // the pair once at weight 1, then at this step's and at the next step's weight
            const int nbj = act.bin(s.next_bin[j]);
            PairSums<D> one;
            pr.weight = 1.0;
            pr.gradW = factor * xij;
            std::apply([&](const auto&... eff) { (eff(s, pr, one), ...); }, fluid_);
            add_weighted(acc, one, bij);
            add_weighted(next, one, nbi > nbj ? nbi : nbj);
            add_weighted(full, one, 0);
          }
          mu_max = std::max(mu_max, std::abs(pr.mu));
        }
      };
      const auto walk_runs = [&](auto top_tag) SPH_ALWAYS_INLINE {
        grid.for_each_support_run(
            xi, hi, [&](std::uint32_t b, std::uint32_t e) SPH_ALWAYS_INLINE { walk(top_tag, b, e); }, holds_due);
      };
      if constexpr (Binned && !Rebin) {  // the finest bin's loop only where `top` can hold
        if (top) {
          walk_runs(std::true_type{});
        } else {
          walk_runs(std::false_type{});
        }
      } else {
        walk_runs(std::false_type{});
      }
      lim.pairs = pairs;
      lim.candidates = candidates;
      if (!due) {  // only the pairs with a due partner: their impulses, no rates, no limits
        s.kick[i] = acc.a;
        s.kick_rho[i] = acc.drho;
        return lim;
      }
      if constexpr (Binned && !Rebin) {  // acc and full from the classes: i's own (in acc), then the finer ones
        bool first = !own_used;
        if (own_used) {
          full.a = kBinScale[static_cast<std::size_t>(bi)] * acc.a;
          full.drho = kBinScale[static_cast<std::size_t>(bi)] * acc.drho;
        }
        for (std::uint32_t used = bins_used; used != 0; used &= used - 1) {  // the finer classes, coarsest first
          const int b = std::countr_zero(used);
          const PairSums<D>& c = by_bin.c[static_cast<std::size_t>(b)];
          if (first) {
            acc = c;
            full.a = kBinScale[static_cast<std::size_t>(b)] * c.a;
            full.drho = kBinScale[static_cast<std::size_t>(b)] * c.drho;
            first = false;
          } else {
            acc.a += c.a;
            acc.drho += c.drho;
            full.a += kBinScale[static_cast<std::size_t>(b)] * c.a;
            full.drho += kBinScale[static_cast<std::size_t>(b)] * c.drho;
          }
        }
      }
      acc.a += kBinWeight[static_cast<std::size_t>(bi)] * gravity_;
      s.kick[i] = acc.a;
      s.kick_rho[i] = acc.drho;
      // The rates and limits are those of the bin the particle opens its next step in.
      const double scale = kBinScale[static_cast<std::size_t>(nbi)];
      if constexpr (Rebin) {
        next.a += kBinWeight[static_cast<std::size_t>(nbi)] * gravity_;
      } else {
        next = acc;
      }
      {
        const Vec<D> a_new = scale * next.a;
        const double drho_new = scale * next.drho;
        // The rates at full weight: a and drho themselves where every pair is of i's own bin (bitwise: the classes'
        // scalings are powers of two), the single-rate loop included.
        Vec<D> full_a_new = a_new;
        double full_drho_new = drho_new;
        if constexpr (Binned) {
          full_a_new = full.a + gravity_;
          full_drho_new = full.drho;
        }
        if (act.dt0 > 0.0) {  // the rates' change since i's last evaluation, dt0 2^-b_i ago (Integrator::drift)
          const double since = act.dt0 * kBinWeight[static_cast<std::size_t>(bi)];
          s.jerk[i] = (full_a_new - s.full_a[i]) / since;
          s.density_jerk[i] = (full_drho_new - s.full_drho[i]) / since;
        }
        s.a[i] = a_new;
        s.drho[i] = drho_new;
        s.full_a[i] = full_a_new;
        s.full_drho[i] = full_drho_new;
      }
      const double an = s.a[i].norm();
      const double own_force = an > 0.0 ? std::sqrt(hi / an) : inf;
      // h_i / (c0 + max mu), with h_i shortened where the neighbours are stiffer than i's own lattice
      // (LatticeGradientSum::acoustic_length; docs/METHOD.md, "Time step and three refinement levels").
      const double length = acoustic_.length(lattice_, hi, s.d[i], s.rho[i], grad_mass);
      const double own_cfl = length / (c0_ + mu_max);
      s.stiffness[i] = hi / length;
      s.dt_limit[i] = std::min(own_force, own_cfl);
      lim.dt_force = scale * own_force;
      lim.dt_cfl = scale * own_cfl;
      lim.finest_bin = nbi;
      return lim;
    };
    return par::reduce(
        s.n, init,
        [&](std::size_t i) {
          if constexpr (!probe::kEnabled) {
            return particle(i);
          } else {  // the instrument of core/sweep_probe.hpp
            const std::uint64_t start = probe::now();
            const SweepLimits lim = particle(i);
            const std::uint64_t cycles = probe::now() - start;
            const bool fluid = s.kind[i] == Kind::fluid && !is_passive(s.role[i]);
            const bool due = !Binned || act.bin(s.bin[i]) >= act.active_bin;
            probe::record(Rebin ? probe::Loop::rebin : Binned ? probe::Loop::binned : probe::Loop::single, fluid, due,
                          s.level[i], cycles, lim.pairs, lim.candidates);
            return lim;
          }
        },
        [](const SweepLimits& x, const SweepLimits& y) { return x.merged(y); });
  }

  /// Storage for N classes of pair sums, constructed one at a time as the classes are first used.
  template <int N>
  union ClassSums {
    ClassSums() {}
    PairSums<D> c[N];
  };
  static_assert(std::is_trivially_destructible_v<PairSums<D>>, "ClassSums never destroys its classes");

  /// sum += 2^-b one: a power of two, so the scaling is exact.
  static void add_weighted(PairSums<D>& sum, const PairSums<D>& one, int b) {
    const double w = kBinWeight[static_cast<std::size_t>(b)];
    sum.a += w * one.a;
    sum.drho += w * one.drho;
  }

  LatticeGradientSum<D> lattice_;
  FluidEffects fluid_;
  WallEffects wall_;
  double c0_;
  Vec<D> gravity_;
  AcousticLimit acoustic_;
};

}  // namespace sph
