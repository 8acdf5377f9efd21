#pragma once
// Time integration: kick-drift-kick leapfrog (PHYSICS.md), with one global step or power-of-two time bins
// per refinement level. The driver (core/simulation.cpp) owns the loops and the force evaluations; this
// component says what each particle does in them, and which pairs each evaluation must cover.
//
// One step advances the fluid by dt0 in K = 2^B substeps of tau = dt0 / K, B the finest bin present. Particle
// i is in bin b_i (the store's `bin`: at least its level, finer where its own time-step limit asks, bin_for;
// 0 with one global step) and is due every 2^(B - b_i) substeps; a pair steps at its finer member's rate,
// b_ij = max(b_i, b_j). The step is:
//   open:   vh = v + (dt0 2^-b / 2) a,  rhoh = rho + (dt0 2^-b / 2) drho       (a, drho: the last rates)
//   for k = 1..K:
//     drift:   x += tau vh for every fluid particle, and the prediction where it is needed:
//              v = vh + (t_k - t_mid) a + e (t_k - t_n)^2 / 2 jerk, and the same for rho with drho and its jerk;
//              t_n and t_mid the start and middle of i's own step, e = 1 with time.predictor = "extrapolated" (the
//              rates extrapolated linearly from the particle's last two evaluations: jerk = their difference over
//              the time between them, core/sweep.hpp), 0 with "last_rate" (the last evaluation's rates held).
//              Inside i's step, where it has pairs in finer bins than its own (full_a != a), vh lacks the share
//              of those pairs' impulses not yet delivered, so the prediction starts from the step's start instead:
//              v = v_open + (t_k - t_n) full_a + e (t_k - t_n)^2 / 2 jerk, full_a the rate of all its pairs at
//              full weight (sweep.hpp), v_open its velocity at t_n (docs/METHOD.md, "Prediction inside a step")
//     forces:  the pairs with b_ij >= the active bin of substep k (core/sweep.hpp), each weighted by 2^-b_ij
//     kick:    k < K:  vh += dt0 kick, rhoh += dt0 kick_rho  (a closing and an opening half-kick at once); where
//                      k ends i's own step, first v_open = vh + (dt0 / 2) kick (its velocity at the new step's start)
//              k = K:  v = vh + (dt0 / 2) kick, rho = rhoh + (dt0 / 2) kick_rho  (every pair closes)
// Bins change between steps only. Before the last evaluation each particle's next bin is chosen (bin_for); where
// any changes, that evaluation sums every pair twice, with this step's weights for the closing kick and with the
// next step's for the rates a and drho that open it (Activity::rebin), so each pair's closing and opening
// impulses are equal and opposite in both members whatever the bins do.
// This is a multiple-time-step leapfrog split by pairs (r-RESPA): every pair impulse is applied to both
// members at the same instant, equal and opposite and along x_ij, so linear and angular momentum are exact to
// rounding whatever the bins. With bin_cap = 0 (B = 0, K = 1) it is, operation for operation, the single-rate
// scheme:
//   v_h = v_n + dt/2 a_n,  x_{n+1} = x_n + dt v_h,  forces at x_{n+1} with v = v_h + dt/2 a_n + e dt/2 (a_n - a_{n-1}),
//   v_{n+1} = v_h + dt/2 a_{n+1}   (and the same for rho).
// The prediction is the only place the two predictors differ; the kicks, and so every conservation property, are
// the same. For an acoustic mode of frequency omega (z = omega dt) the last-rate prediction grows the mode by about
// z^4/4 a step, the extrapolated one damps it (by about z^4/2) up to z = 0.67 (docs/METHOD.md, "The predictor").
// Coarse particles take their own pairs' forces once per coarse step; the pairs they share with finer ones are
// evaluated at the finer rate, from both sides. Steps end with every bin synchronised, so refinement,
// coarsening, output and checkpoints only ever see synchronised particles.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"
#include "core/solver_settings.hpp"
#include "core/sweep.hpp"
#include "parallel/range_max.hpp"

namespace sph {

class Integrator {
 public:
  /// The finest bin a step may have: 2^kMaxBin substeps. Levels beyond it share its bin.
  static constexpr int kMaxBin = kBinCount - 1;
  static_assert(kMaxBin < 31, "1 << bins must fit an int");

  Integrator(TimeStepping mode, TaitEquationOfState eos, int bin_jump = kDefaultBinJump,
             TimePredictor predictor = TimePredictor::extrapolated)
      : mode_(mode), eos_(eos), bin_jump_(bin_jump), predictor_(predictor) {}

  TimeStepping mode() const { return mode_; }
  int bin_cap() const { return mode_ == TimeStepping::global ? 0 : kMaxBin; }
  int bin(std::int32_t b) const { return Activity{0, bin_cap()}.bin(b); }
  int bin_jump() const { return bin_jump_; }

  /// The candidate shares of the target step (below): 2^(-k/8), k = 0..8.
  static constexpr int kShrinks = 9;
  static double shrink(int k) { return std::exp2(-0.125 * static_cast<double>(k)); }

  /// A substep's own work per fluid particle, due or not, in units of one particle's force evaluation: the
  /// drift and prediction, the ghosts' expansion, the cell sort and the gather of every field, and the walk of
  /// a particle that is not due over its candidate cells. The bin choice (Simulation::choose_bins) weighs it,
  /// so that a few stiff particles in a finer bin do not buy every particle twice the substeps. Measured
  /// (docs/PERFORMANCE.md, "The substeps' cost measured again"): on dam_break_aap per level, two runs with the
  /// same evaluations (1.507e7 and 1.508e7) and 3,450 substeps apart differ by 2.41 s, 0.45 us per fluid
  /// particle and substep (1,540 on average); the pair sweep takes 0.70 us per evaluation (perf: 67.5 % of the
  /// run). 0.45 / 0.70 = 0.65. (It was 0.25, from perf alone, which missed the sweep's walk of the particles that
  /// are not due.)
  static constexpr double kSubstepCost = 0.65;

  /// The coarse step the levels alone would allow: cfl times the smallest 2^level_i times particle i's limit
  /// without its acoustic stiffness (dt_limit_i s_i: its acoustic limit at h_i, or its force limit if that is
  /// shorter, which this overestimates, and the bins below then catch). Infinite before any evaluation.
  template <int D>
  double level_target(const ParticleView<D>& s, std::size_t i, double cfl) const {
    if (s.kind[i] != Kind::fluid || !(s.dt_limit[i] > 0.0)) return std::numeric_limits<double>::infinity();
    return cfl * std::ldexp(s.dt_limit[i] * std::max(1.0, s.stiffness[i]), bin(s.level[i]));
  }

  /// The bin particle i steps in when the coarse step is dt0: its level's, or the fewest bins finer whose step
  /// dt0 / 2^b is within cfl times its own limit dt_limit_i (force and acoustic, from its last evaluation). With
  /// one global step, or before any evaluation, its level's (0 with one global step).
  template <int D>
  int bin_for(const ParticleView<D>& s, std::size_t i, double dt0, double cfl) const {
    return bin_for(s, i, dt0, cfl, s.dt_limit[i]);
  }
  /// The same with the limit given (a neighbour's, in neighbourhood_bins).
  template <int D>
  int bin_for(const ParticleView<D>& s, std::size_t i, double dt0, double cfl, double limit) const {
    return bin_from(bin(s.level[i]), dt0, cfl, limit);
  }
  /// The fewest bins from `start` on whose step dt0 / 2^b is within cfl times `limit` (`start` itself when the
  /// limit is not positive, dt0 not finite, or with one global step). Non-increasing in the limit.
  int bin_from(int start, double dt0, double cfl, double limit) const {
    int b = start;
    if (bin_cap() == 0 || !(limit > 0.0) || !std::isfinite(dt0)) return b;
    const double allowed = cfl * limit;
    // dt0 2^-b by the table: a power of two, so the product is exact (as std::ldexp, at a fraction of its cost;
    // this runs nine times per particle and step in Simulation::choose_bins).
    while (b < bin_cap() && dt0 * kBinWeight[static_cast<std::size_t>(b)] > allowed) ++b;
    return b;
  }
  /// bin_for at each of the kShrinks candidate steps target * shrink(k) (Simulation::choose_bins), each equal to
  /// bin_for's. One walk, for k = 0; the others follow from it: the candidates fall with k and a bin's step
  /// dt0 2^-b is exact, so the bins do not rise with k, and the last candidate, exactly half the first, is at
  /// most one bin coarser (its test at bin b is the first's at b + 1). So bin k is the first's or one less, by one
  /// comparison, the walk's own. (Nine walks per particle and step were 2 % of a per-level run.)
  template <int D>
  void bins_for_shares(const ParticleView<D>& s, std::size_t i, const std::array<double, kShrinks>& candidate,
                       double cfl, std::array<int, kShrinks>& out) const {
    static_assert(kShrinks >= 2);
    const int start = bin(s.level[i]);
    const double limit = s.dt_limit[i];
    const int b0 = bin_from(start, candidate[0], cfl, limit);
    out[0] = b0;
    const double allowed = cfl * limit;
    const double w = b0 > start ? kBinWeight[static_cast<std::size_t>(b0 - 1)] : 0.0;
    for (std::size_t k = 1; k < kShrinks; ++k) {
      out[k] = b0 > start && !(candidate[k] * w > allowed) ? b0 - 1 : b0;
    }
  }

  /// neighbourhood_bins' workspace, reused from step to step.
  struct NeighbourhoodWork {
    std::vector<std::uint32_t> fast;       // the particles whose limit could put a neighbour in a finer bin
    std::vector<std::uint8_t> near_fast;   // 1 where a fluid particle has one of them for a neighbour
  };

  /// Each fluid particle's next bin for the coarse step dt0 from its limit over its kernel neighbourhood: the
  /// smallest of its own dt_limit and each fluid, ghost or halo neighbour's (|x_i - x_j| < h_i + h_j), the
  /// neighbour's scaled to i's smoothing length (dt_j h_i / h_j: a coarse particle is not held to a fine
  /// neighbour's shorter reach, only to a stiffer or faster one): bin_for(dt0, that limit). The store's dt_limit
  /// stays each particle's own (the coarse step's target uses it). Called on the grid of the last substep (per-level
  /// steps only). With one global step every particle steps at C times the smallest limit of all; with its own
  /// limit alone, a particle at the tip of the dam break's surge front, stepping at C times its own, went wrong at
  /// 4x and 16x (docs/METHOD.md, "the surge front").
  /// A neighbour j moves i from its own bin b_i to a finer one only when dt_j h_i / h_j < dt0 2^-b_i / C, i.e. when
  /// its pace dt_j / h_j is below dt0 2^-b_i / (C h_i). The largest of these thresholds over the fluid bounds them
  /// all, and few particles are below it (the stiff few: 0.26 % of the particle-steps of the paper's dam break per
  /// level). Those mark their neighbours, and only a marked particle walks its neighbourhood; every other keeps
  /// its own bin, which walking would give it too. So the result is that of walking every particle's neighbours,
  /// and does not depend on the order or the threads (a mark is a set bit).
  /// With `own_level` (buffered levels, whose particles pair only within their level: core/sweep.hpp) the
  /// neighbourhood is i's own level's.
  template <int D>
  void neighbourhood_bins(const ParticleView<D>& s, const CellGrid<D>& grid, double dt0, double cfl,
                          NeighbourhoodWork& work, bool own_level = false) const {
    const auto pairs = [&](std::size_t i, std::size_t j) { return !own_level || s.level[i] == s.level[j]; };
    // Each fluid particle's bin from its own limit, and the largest pace a neighbour could move it a bin below.
    const double threshold = par::reduce(
        s.n, 0.0,
        [&](std::size_t i) {
          if (s.kind[i] != Kind::fluid) return 0.0;
          const int b = bin_for(s, i, dt0, cfl, s.dt_limit[i]);
          s.next_bin[i] = b;
          if (!(s.dt_limit[i] > 0.0) || b >= bin_cap() || !std::isfinite(dt0)) return 0.0;
          return dt0 * kBinWeight[static_cast<std::size_t>(b)] / (cfl * s.h[i]);
        },
        [](double a, double b) { return std::max(a, b); });
    if (!(threshold > 0.0)) return;
    // The particles below it, with a margin (1e-9 relative) far beyond the roundings of the quotients and products
    // that compare a scaled limit with a bin's step, so that every neighbour that could move a bin is among them.
    const double bound = threshold * (1.0 + 1e-9);
    work.fast.clear();
    for (std::size_t j = 0; j < s.n; ++j) {
      if (s.kind[j] != Kind::wall && s.dt_limit[j] > 0.0 && s.dt_limit[j] / s.h[j] < bound)
        work.fast.push_back(static_cast<std::uint32_t>(j));
    }
    if (work.fast.empty()) return;
    work.near_fast.assign(s.n, 0);
    par::parallel_for(work.fast.size(), [&](std::size_t k) {
      const std::uint32_t j = work.fast[k];
      grid.for_each_neighbour(j, s.x, s.h, [&](std::uint32_t i, double) {
        if (s.kind[i] == Kind::fluid && pairs(i, j))
          std::atomic_ref<std::uint8_t>(work.near_fast[i]).store(1, std::memory_order_relaxed);
      });
    });
    par::parallel_for(s.n, [&](std::size_t i) {
      if (!work.near_fast[i] || s.next_bin[i] >= bin_cap()) return;
      double m = s.dt_limit[i];
      if (!(m > 0.0)) return;
      grid.for_each_neighbour(i, s.x, s.h, [&](std::size_t j, double) {
        if (s.kind[j] != Kind::wall && s.dt_limit[j] > 0.0 && pairs(i, j))
          m = std::min(m, s.dt_limit[j] * (s.h[i] / s.h[j]));
      });
      s.next_bin[i] = bin_for(s, i, dt0, cfl, m);
    });
  }

  /// The bin limiter, one Jacobi pass: each fluid particle's next bin is raised to at least each fluid or halo
  /// neighbour's (|x_i - x_j| < h_i + h_j, from `grid`, which must be built on the store as it is) minus bin_jump.
  /// The limiter's workspace, reused from pass to pass.
  struct BinLimiterWork {
    std::vector<std::int32_t> raised;
    par::RangeMax<std::int8_t> reach;  // the next bins of the fluid and halos in store order (others -1)
  };

  /// Reads the next bins as they are and writes them once every particle has read (`work.raised`), so the
  /// result does not depend on the order or the threads. Returns whether any changed on this store. Repeated
  /// (with the halos' copies refreshed between passes) until none changes, every pair of neighbours ends at most
  /// bin_jump bins apart, at the coarsest such bins above those chosen.
  /// A particle is first tested against the largest next bin in the store, then against the largest in each of
  /// its candidate runs (the store ranges the grid scans for it, a superset of its neighbours), in constant time a
  /// run (par::RangeMax); only the runs whose largest is more than bin_jump above its own are walked. The result
  /// is the same as walking every particle's neighbours; most particles, in a region of one bin, skip the walk.
  /// With `own_level` (buffered levels) only neighbours of i's own level count, the only ones it pairs with.
  template <int D>
  bool limit_bins(const ParticleView<D>& s, const CellGrid<D>& grid, BinLimiterWork& work, bool own_level = false) const {
    const auto pairs = [&](std::size_t i, std::size_t j) { return !own_level || s.level[i] == s.level[j]; };
    static_assert(kBinCount <= 127, "next bins are held as int8 in the range table");
    std::vector<std::int32_t>& raised = work.raised;
    raised.resize(s.n);
    work.reach.build(s.n, [&](std::size_t j) {
      return static_cast<std::int8_t>(s.kind[j] == Kind::fluid || s.kind[j] == Kind::halo ? s.next_bin[j] : -1);
    });
    // No particle within bin_jump of the largest next bin in the store can be raised.
    const std::int32_t top = s.n > 0 ? work.reach.max(0, s.n) : -1;
    const bool changed = par::reduce(
        s.n, false,
        [&](std::size_t i) {
          raised[i] = s.next_bin[i];
          if (s.kind[i] != Kind::fluid || top - bin_jump_ <= s.next_bin[i]) return false;
          // One scan of the candidate runs: a run is walked only where its largest next bin is more than bin_jump
          // above i's (no particle of another run can raise it).
          std::int32_t need = s.next_bin[i];
          const auto walk = [&](std::uint32_t b, std::uint32_t e) {
            return e > b && work.reach.max(b, e) - bin_jump_ > s.next_bin[i];
          };
          grid.for_each_neighbour_in(i, s.x, s.h, walk, [&](std::size_t j, double) {
            if ((s.kind[j] == Kind::fluid || s.kind[j] == Kind::halo) && pairs(i, j))
              need = std::max(need, s.next_bin[j] - bin_jump_);
          });
          raised[i] = std::min<std::int32_t>(need, bin_cap());
          return raised[i] != s.next_bin[i];
        },
        [](bool a, bool b) { return a || b; });
    if (changed) {
      par::parallel_for(s.n, [&](std::size_t i) { s.next_bin[i] = raised[i]; });
    }
    return changed;
  }

  /// The pairs the evaluation after substep k (1..2^finest) covers: those of the bins due at t_k.
  Activity activity(int k, int finest) const {
    const int substeps = 1 << finest;
    if (k >= substeps) return {0, bin_cap()};  // the end of the step: every bin
    int trailing = 0;                          // k is a multiple of 2^(finest - b) for b >= finest - trailing
    while (((k >> trailing) & 1) == 0) ++trailing;
    return {finest - trailing, bin_cap()};
  }

  /// Opening half-kick of a step of dt0 in 2^finest substeps (fluid particles only). A particle whose step spans
  /// several substeps also keeps its velocity and density at the step's start (v_open, rho_open: drift).
  template <int D>
  void open(const ParticleView<D>& s, std::size_t i, double dt0, int finest) const {
    const int b = bin(s.bin[i]);
    const double half = (0.5 * dt0) * kBinWeight[static_cast<std::size_t>(b)];
    s.vh[i] = s.v[i] + half * s.a[i];
    s.rhoh[i] = s.rho[i] + half * s.drho[i];
    if (b < finest) {
      s.v_open[i] = s.v[i];
      s.rho_open[i] = s.rho[i];
    }
  }

  /// Drift over substep k of 2^finest (tau = dt0 / 2^finest) and the prediction of v, rho and p at t_k.
  template <int D>
  void drift(const ParticleView<D>& s, std::size_t i, double tau, int k, int finest) const {
    s.x[i] += tau * s.vh[i];
    const int period = 1 << (finest - bin(s.bin[i]));  // substeps per step of i's bin
    const int start = ((k - 1) / period) * period;       // substep at which i's current step began
    const double offset = static_cast<double>(2 * (k - start) - period) * (0.5 * tau);  // t_k - t_mid
    const double since = static_cast<double>(k - start) * tau;  // t_k - t_n
    const double e = predictor_ == TimePredictor::extrapolated ? 1.0 : 0.0;
    const double half_square = e * (0.5 * since * since);
    if (k - start < period && (s.full_a[i] != s.a[i] || s.full_drho[i] != s.drho[i])) {
      // Inside i's step, with pairs of finer bins than its own: vh holds only the impulses those pairs have delivered
      // so far (a finer pair's opening kick and its kicks at the substeps it was due), not their share up to t_k, so
      // vh + offset a falls short by up to a quarter step of their force (a pair one bin finer, at i's mid-step): in a
      // still tank with a strip of particles a bin finer, 0.42 m/s after 4 s against 0.009 m/s (docs/METHOD.md,
      // "Prediction inside a step"). The motion from the step's start with every pair at full weight has no such gap.
      s.v[i] = s.v_open[i] + since * s.full_a[i] + half_square * s.jerk[i];
      s.rho[i] = s.rho_open[i] + since * s.full_drho[i] + half_square * s.density_jerk[i];
    } else if (predictor_ == TimePredictor::extrapolated) {
      // The rates a + (t - t_n) jerk integrated from t_n: vh holds v_n + (t_mid - t_n) a, so this adds the jerk's
      // (t_k - t_n)^2 / 2 (exact for rates linear in time).
      s.v[i] = s.vh[i] + offset * s.a[i] + half_square * s.jerk[i];
      s.rho[i] = s.rhoh[i] + offset * s.drho[i] + half_square * s.density_jerk[i];
    } else {
      s.v[i] = s.vh[i] + offset * s.a[i];
      s.rho[i] = s.rhoh[i] + offset * s.drho[i];
    }
    s.p[i] = eos_.pressure(s.rho[i]);
  }

  /// Kick after the evaluation of substep k: full (closing and opening) inside the step, closing at its end.
  /// A passive particle (buffered levels, core/refinement/buffer.hpp) is neither kicked nor predicted: over a substep
  /// of length tau it moves with the velocity of its last fit.
  template <int D>
  void carry(const ParticleView<D>& s, std::size_t i, double tau) const {
    s.x[i] += tau * s.v[i];
  }

  /// Kick with the evaluation of substep k of 2^finest: closing at the end of the coarse step (k = 2^finest), else a
  /// closing and an opening kick at once. Where that closes i's own step (k a multiple of its period), the closing
  /// half gives its velocity and density at the start of its next step (v_open, rho_open: Integrator::drift).
  template <int D>
  void kick(const ParticleView<D>& s, std::size_t i, double dt0, int k, int finest) const {
    const double half = 0.5 * dt0;
    if (k == 1 << finest) {
      s.v[i] = s.vh[i] + half * s.kick[i];
      s.rho[i] = s.rhoh[i] + half * s.kick_rho[i];
      s.p[i] = eos_.pressure(s.rho[i]);
      return;
    }
    const int period = 1 << (finest - bin(s.bin[i]));
    if (period > 1 && k % period == 0) {  // (a step of one substep never predicts inside itself: open() likewise)
      s.v_open[i] = s.vh[i] + half * s.kick[i];
      s.rho_open[i] = s.rhoh[i] + half * s.kick_rho[i];
    }
    s.vh[i] += dt0 * s.kick[i];
    s.rhoh[i] += dt0 * s.kick_rho[i];
  }

 private:
  TimeStepping mode_;
  TaitEquationOfState eos_;
  int bin_jump_ = kDefaultBinJump;
  TimePredictor predictor_ = TimePredictor::extrapolated;
};

}  // namespace sph
