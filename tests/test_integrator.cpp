// Time integration (core/integrator.hpp): the bins' clock, the single-rate scheme as the one-bin case, and a
// cloud on three levels stepped per level: momentum and angular momentum exact, and the same bits at 1 and 2
// threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "core/cell_grid.hpp"
#include "core/integrator.hpp"
#include "core/refinement/split_pass.hpp"
#include "core/setup.hpp"
#include "core/simulation.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;

TEST(Integrator, TheActiveBinFollowsThePowerOfTwoClock) {
  const Integrator per_level(TimeStepping::per_level, TaitEquationOfState{});
  // Three bins (0, 1, 2): four substeps. Bin 2 is due at every substep, bin 1 at the second and fourth,
  // bin 0 at the fourth only, where every bin ends its step.
  EXPECT_EQ(per_level.activity(1, 2).active_bin, 2);
  EXPECT_EQ(per_level.activity(2, 2).active_bin, 1);
  EXPECT_EQ(per_level.activity(3, 2).active_bin, 2);
  EXPECT_EQ(per_level.activity(4, 2).active_bin, 0);
  EXPECT_EQ(per_level.activity(1, 0).active_bin, 0);
  EXPECT_EQ(per_level.activity(8, 3).active_bin, 0);
  EXPECT_EQ(per_level.activity(6, 3).active_bin, 2);
  EXPECT_EQ(per_level.bin(3), 3);
  EXPECT_EQ(per_level.bin(100), Integrator::kMaxBin);
  const Integrator global(TimeStepping::global, TaitEquationOfState{});
  EXPECT_EQ(global.bin(3), 0);
  EXPECT_EQ(global.activity(1, 0).active_bin, 0);
}

// The prediction for an evaluation at substep k: v_n + (t_k - t_n) a_n, and with the extrapolated predictor also
// (t_k - t_n)^2 / 2 jerk: exact for an acceleration linear in time, which the last-rate prediction is not. A
// particle in bin 1 of a step with four substeps (bin 2 the finest) over two of its steps, the second opened by the
// combined kick (vh += dt0 kick, with the first step's closing rate equal to the second's opening one). Tolerance: a
// few roundings of sums of terms of order |v| (1e-15 relative), 1e-13 of the speed scale.
TEST(Integrator, ThePredictionIsExactForRatesLinearInTime) {
  const double dt0 = 0.1, tau = dt0 / 4.0;
  const Vec<2> v0(1.0, -2.0), a0(3.0, 0.5), jerk(-4.0, 7.0);
  const double rho0 = 1000.0, drho0 = 20.0, density_jerk = -300.0;
  for (const TimePredictor predictor : {TimePredictor::extrapolated, TimePredictor::last_rate}) {
    SCOPED_TRACE(predictor == TimePredictor::extrapolated ? "extrapolated" : "last_rate");
    const Integrator integ(TimeStepping::per_level, TaitEquationOfState{}, kDefaultBinJump, predictor);
    const double e = predictor == TimePredictor::extrapolated ? 1.0 : 0.0;
    ParticleStore<2> store;
    store.resize(1);
    store.kind[0] = Kind::fluid;
    store.bin[0] = store.next_bin[0] = 1;
    store.v[0] = v0;
    store.rho[0] = rho0;
    store.a[0] = store.full_a[0] = a0;  // every pair in the particle's own bin: a is the rate at full weight
    store.drho[0] = store.full_drho[0] = drho0;
    store.jerk[0] = jerk;
    store.density_jerk[0] = density_jerk;
    const auto s = store.view();
    integ.open(s, 0, dt0, 2);
    const double step = 0.5 * dt0;  // bin 1
    for (int k = 1; k <= 4; ++k) {
      if (k == 3) {  // the second step opens: the rates at t = step, as the exact motion has them
        const Vec<2> a1 = a0 + step * jerk;
        const double drho1 = drho0 + step * density_jerk;
        // The driver's combined kick, vh += dt0 kick with kick = 2^-1 a1: the closing half-kick (vh = v_n + step/2 a_n
        // closes to the trapezoid of a_n and a1, exact for a linear rate) and the opening one with a1.
        s.vh[0] += step * a1;
        s.rhoh[0] += step * drho1;
        s.a[0] = s.full_a[0] = a1;
        s.drho[0] = s.full_drho[0] = drho1;
      }
      integ.drift(s, 0, tau, k, 2);
      const double t = k * tau;                 // since the first step's start
      const double since = k <= 2 ? t : t - step;  // since the particle's current step began
      const Vec<2> v_start = k <= 2 ? v0 : Vec<2>(v0 + step * a0 + 0.5 * step * step * jerk);
      const Vec<2> a_start = k <= 2 ? a0 : Vec<2>(a0 + step * jerk);
      // The last-rate prediction, and the extrapolated one on top of it.
      const Vec<2> expected = v_start + since * a_start + e * (0.5 * since * since) * jerk;
      EXPECT_LE((s.v[0] - expected).norm(), 1e-13 * v0.norm()) << "substep " << k;
      if (predictor == TimePredictor::extrapolated) {
        const Vec<2> exact = v0 + t * a0 + 0.5 * t * t * jerk;
        EXPECT_LE((s.v[0] - exact).norm(), 1e-13 * v0.norm()) << "substep " << k << ": the exact motion";
      }
    }
    // The density at the last substep (the same algebra, one rate; its second step's rhoh from the trapezoid).
    const double t = 4 * tau;
    const double drho1 = drho0 + step * density_jerk;
    const double rho_start = rho0 + 0.5 * step * (drho0 + drho1);
    EXPECT_NEAR(s.rho[0], rho_start + step * drho1 + e * 0.5 * step * step * density_jerk, 1e-13 * rho0);
    if (predictor == TimePredictor::extrapolated) {
      EXPECT_NEAR(s.rho[0], rho0 + t * drho0 + 0.5 * t * t * density_jerk, 1e-13 * rho0);
    }
  }
}

// The prediction inside a step of a particle with pairs of finer bins than its own. Its forces split into classes by
// the pairs' bins: F_c from the pairs of bin c (gravity in its own bin's). The sweep gives it a = 2^b sum_c 2^-c F_c
// (each class weighted for its own step) and the full-weight rate A = sum_c F_c; a finer class delivers its impulses
// at its own substeps (the driver's combined kick, vh += dt0 kick). With forces constant in time the motion is
// v(t) = v_n + (t - t_n) A, and the prediction at every substep must be that, whichever classes have delivered.
// vh + (t_k - t_mid) a, the prediction before, falls short by a quarter step of a one-bin-finer class at the
// particle's mid-step (docs/METHOD.md, "Prediction inside a step"). Two cases: bin 0 with classes 0 and 1 (two
// substeps), and bin 1 with classes 1 and 2 over both its steps in a step of four substeps (the second opened by
// the combined kick, which sets the start of its step, v_open). Tolerance as the test above: a few roundings of
// sums of terms of order |v|, 1e-13 of the speed scale.
TEST(Integrator, ThePredictionInsideAStepCountsTheFinerPairsAtFullWeight) {
  const double dt0 = 0.1;
  const Vec<2> v0(1.0, -2.0);
  const double rho0 = 1000.0;
  struct Case {
    int bin, finest;
    Vec<2> own, finer;       // F_b and F_(b+1)
    double own_rho, finer_rho;
  };
  for (const Case& c : {Case{0, 1, Vec<2>(3.0, -9.0), Vec<2>(-2.0, 8.0), 5.0, -40.0},
                        Case{1, 2, Vec<2>(-1.0, 4.0), Vec<2>(6.0, -3.0), -7.0, 25.0}}) {
    for (const TimePredictor predictor : {TimePredictor::extrapolated, TimePredictor::last_rate}) {
      SCOPED_TRACE(testing::Message() << "bin " << c.bin << (predictor == TimePredictor::extrapolated ? ", extrapolated" : ", last_rate"));
      const Integrator integ(TimeStepping::per_level, TaitEquationOfState{}, kDefaultBinJump, predictor);
      const int substeps = 1 << c.finest, period = 1 << (c.finest - c.bin);
      const double tau = dt0 / substeps, w_own = std::ldexp(1.0, -c.bin), w_finer = std::ldexp(1.0, -c.bin - 1);
      ParticleStore<2> store;
      store.resize(1);
      store.kind[0] = Kind::fluid;
      store.bin[0] = store.next_bin[0] = c.bin;
      store.v[0] = v0;
      store.rho[0] = rho0;
      // The sweep's rates for these classes (2^b (2^-b F_b + 2^-(b+1) F_(b+1)), and at full weight), no jerk.
      store.a[0] = std::ldexp(1.0, c.bin) * (w_own * c.own + w_finer * c.finer);
      store.drho[0] = std::ldexp(1.0, c.bin) * (w_own * c.own_rho + w_finer * c.finer_rho);
      store.full_a[0] = c.own + c.finer;
      store.full_drho[0] = c.own_rho + c.finer_rho;
      const Vec<2> A = store.full_a[0];
      const double R = store.full_drho[0];
      const auto s = store.view();
      integ.open(s, 0, dt0, c.finest);
      std::size_t inside = 0;
      for (int k = 1; k <= substeps; ++k) {
        integ.drift(s, 0, tau, k, c.finest);
        const double t = k * tau;
        EXPECT_LE((s.v[0] - (v0 + t * A)).norm(), 1e-13 * v0.norm()) << "substep " << k;
        EXPECT_NEAR(s.rho[0], rho0 + t * R, 1e-13 * rho0) << "substep " << k;
        inside += k % period != 0;
        // The evaluation at t_k: the finer class is due at every substep, the particle's own at the end of its step.
        const bool own_due = k % period == 0;
        s.kick[0] = w_finer * c.finer + (own_due ? Vec<2>(w_own * c.own) : Vec<2>::Zero());
        s.kick_rho[0] = w_finer * c.finer_rho + (own_due ? w_own * c.own_rho : 0.0);
        integ.kick(s, 0, dt0, k, c.finest);
      }
      EXPECT_EQ(inside, static_cast<std::size_t>(substeps - substeps / period)) << "substeps inside the particle's steps";
      EXPECT_GT(inside, 0u);
      // The closing kick ends the coarse step at the exact motion too.
      EXPECT_LE((s.v[0] - (v0 + dt0 * A)).norm(), 1e-13 * v0.norm());
      EXPECT_NEAR(s.rho[0], rho0 + dt0 * R, 1e-13 * rho0);
    }
  }
}

/// A rotating, drifting, perturbed circular cloud (as the single-rate conservation test), with a band refined to
/// level 1 and a smaller patch inside it to level 2, so that pairs of every level combination interact.
/// With the last-rate predictor the AAP daughters at the level jumps, whose coarse neighbours are heavier, sum a
/// stiffer neighbourhood than their lattice's and step a bin finer than their level, so bins change from step to
/// step; with the extrapolated one (the default) their stiffness stays within what it keeps stable (AcousticLimit).
Simulation three_level_cloud(TimeStepping stepping, int bin_jump = kDefaultBinJump,
                             TimePredictor predictor = TimePredictor::extrapolated) {
  SolverSettings st = test::isolated_settings(20.0, true);
  st.geometry.container = {Vec<2>(-100, -100), Vec<2>(100, 100)};  // no walls: only the watchdog sees it
  st.stepping = stepping;
  st.bin_jump = bin_jump;
  st.predictor = predictor;
  Simulation sim(st);
  FluidBlockSpec spec;
  spec.spacing = 0.1;
  auto& s = sim.store();
  add_fluid(s, lattice_circle(Vec<2>(1.0, 2.0), 1.0, 0.1), spec, 1000.0);
  std::vector<std::uint8_t> marks(s.size(), 0);
  for (std::size_t i = 0; i < s.size(); ++i) marks[i] = s.x[i][0] > 0.9 ? 1 : 0;
  refine::split_marked(s, marks, refine::Pattern::aap, 1.0, 2, {});
  marks.assign(s.size(), 0);
  for (std::size_t i = 0; i < s.size(); ++i) marks[i] = s.level[i] == 1 && s.x[i][0] > 1.3 && s.x[i][1] > 1.8 ? 1 : 0;
  refine::split_marked(s, marks, refine::Pattern::aap, 1.0, 2, {});
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec<2> r = s.x[i] - Vec<2>(1.0, 2.0);
    s.v[i] = Vec<2>(-r[1], r[0]) * 2.0 + Vec<2>(0.3, -0.2) + 0.2 * Vec<2>(u(rng), u(rng));
    s.rho[i] = 1000.0 * (1.0 + 0.01 * u(rng));
  }
  sim.refresh();
  return sim;
}

/// Fluid indices in id order (daughters' ids carry their generation in the top bits, so no id-indexed table).
std::vector<std::size_t> fluid_by_id(const ParticleStore<2>& s) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.kind[i] == Kind::fluid) idx.push_back(i);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return s.id[a] < s.id[b]; });
  return idx;
}

/// Mass, linear and angular momentum (about the origin), summed in id order.
struct Totals {
  double mass = 0.0;
  Vec<2> P = Vec<2>::Zero();
  double L = 0.0;
};

Totals totals(const ParticleStore<2>& s) {
  Totals t;
  for (const std::size_t i : fluid_by_id(s)) {
    t.mass += s.m[i];
    t.P += s.m[i] * s.v[i];
    t.L += s.m[i] * (s.x[i][0] * s.v[i][1] - s.x[i][1] * s.v[i][0]);
  }
  return t;
}

std::size_t count_level(const ParticleStore<2>& s, int level) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < s.size(); ++i) n += s.kind[i] == Kind::fluid && s.level[i] == level;
  return n;
}

// The target: over 1000 coarse steps with three levels, linear momentum to 1e-12 of sum m|v| and angular
// momentum to 1e-10 of sum m|x||v| (the single-rate test's bounds: every impulse is a pair's, equal and opposite
// and along x_ij, so both are exact up to the rounding of the sums, which grows with the number of steps).
// Both predictors: the kicks, which alone change the momenta, are the same; with the last-rate one the bins change
// from step to step (three_level_cloud), so the checks cover the steps that rebin.
TEST(Integrator, ThreeLevelCloudPerLevelConservesMomentumAndAngularMomentumOver1000CoarseSteps) {
  for (const TimePredictor predictor : {TimePredictor::extrapolated, TimePredictor::last_rate}) {
  SCOPED_TRACE(predictor == TimePredictor::extrapolated ? "extrapolated" : "last_rate");
  Simulation sim = three_level_cloud(TimeStepping::per_level, kDefaultBinJump, predictor);
  auto& s = sim.store();
  ASSERT_GT(count_level(s, 0), 100u);
  ASSERT_GT(count_level(s, 1), 100u);
  ASSERT_GT(count_level(s, 2), 50u);
  const Totals m0 = totals(s);
  const test::MomentumScales sc = test::momentum_scales(s);
  const std::uint64_t n0 = count_level(s, 0), n1 = count_level(s, 1), n2 = count_level(s, 2);
  // The sanitizer preset runs 200 coarse steps (the bounds hold a fortiori); the release suite all 1000.
  const std::uint64_t steps = test::short_runs() ? 200 : 1000;
  int substeps = 0;
  for (std::uint64_t k = 0; k < steps; ++k) substeps = std::max(substeps, sim.step().substeps);
  // Level l steps in bin l or finer: finer where a particle's own limit asks (Integrator::bin_for).
  EXPECT_GE(substeps, 4) << "three levels step in at least four substeps";
  EXPECT_GE(sim.work().evaluations[0], steps * n0);
  EXPECT_GE(sim.work().evaluations[1], 2 * steps * n1);
  EXPECT_GE(sim.work().evaluations[2], 4 * steps * n2);
  // With the last-rate predictor the bins change from step to step (so the checks below cover the steps that
  // rebin): some particles of some level take more evaluations than their level's bin gives them. Which level
  // depends on the bin choice's cost model (Simulation::choose_bins: a finer bin for a few stiff level-2 daughters
  // doubles every particle's substeps, so the coarse step may shrink instead and put coarser particles one bin
  // finer).
  if (predictor == TimePredictor::last_rate) {
    EXPECT_GT(sim.work().evaluations[0] + sim.work().evaluations[1] + sim.work().evaluations[2],
              steps * (n0 + 2 * n1 + 4 * n2))
        << "some particles step finer than their level: " << sim.work().evaluations[0] << " "
        << sim.work().evaluations[1] << " " << sim.work().evaluations[2] << " against " << steps * n0 << " "
        << 2 * steps * n1 << " " << 4 * steps * n2;
  }
  EXPECT_GE(sim.work().substeps, 4 * steps);
  EXPECT_EQ(sim.fine_step_count(), sim.work().substeps);
  sim.remove_ghosts();
  const Totals m1 = totals(sim.store());
  EXPECT_EQ(m1.mass, m0.mass);
  EXPECT_LE((m1.P - m0.P).norm(), 1e-12 * sc.linear);
  EXPECT_LE(std::abs(m1.L - m0.L), 1e-10 * sc.angular);
  EXPECT_TRUE(test::all_finite(sim.store()));
  }
}

// Per-level stepping takes fewer, longer coarse steps than the global step over the same time. The cloud's step
// is CFL-limited (c0 = 20 m/s against speeds of about 2 m/s), and the CFL limit h / (c0 + mu) of a level-2
// particle is a quarter of a level-0 particle's: the global step is set by level 2, the coarse step by all
// levels alike, so the ratio is close to 4 (at least 2.5 leaves room for the force limit and mu). After 0.05 s
// the two clouds' centres of mass agree: momentum is exact in both, so the centre moves by P/M t in both, to the
// rounding of the sums.
TEST(Integrator, PerLevelTakesLongerCoarseStepsThanTheGlobalStep) {
  Simulation global = three_level_cloud(TimeStepping::global);
  Simulation per_level = three_level_cloud(TimeStepping::per_level);
  const double end = test::short_runs() ? 0.02 : 0.05;  // shorter under the sanitizer preset
  global.run_until(end);
  per_level.run_until(end);
  EXPECT_GT(static_cast<double>(global.step_count()), 2.5 * static_cast<double>(per_level.step_count()))
      << global.step_count() << " global steps, " << per_level.step_count() << " per-level coarse steps";
  global.remove_ghosts();
  per_level.remove_ghosts();
  const auto centre = [](const ParticleStore<2>& s) {
    Vec<2> c = Vec<2>::Zero();
    double m = 0.0;
    for (const std::size_t i : fluid_by_id(s)) {
      c += s.m[i] * s.x[i];
      m += s.m[i];
    }
    return Vec<2>(c / m);
  };
  // The centre of mass moves at the constant total momentum / mass: 0.05 s * |(0.3, -0.2)| ~ 0.018 m; both
  // schemes move it by exactly that, to rounding of the position sums (~1e-16 of ~2 m per particle).
  EXPECT_LE((centre(global.store()) - centre(per_level.store())).norm(), 1e-12);
}

/// The limiter's fixed point by brute force: Jacobi passes over every pair of fluid particles within h_i + h_j,
/// each raising a next bin to the neighbours' minus `jump` (capped), until none changes.
std::vector<std::int32_t> limited_bins_brute_force(const ParticleStore<2>& s, std::vector<std::int32_t> b, int jump) {
  for (bool changed = true; changed;) {
    std::vector<std::int32_t> nb = b;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.kind[i] != Kind::fluid) continue;
      for (std::size_t j = 0; j < s.size(); ++j) {
        const double support = s.h[i] + s.h[j];
        if (j == i || s.kind[j] != Kind::fluid || (s.x[i] - s.x[j]).squaredNorm() >= support * support) continue;
        nb[i] = std::max(nb[i], b[j] - jump);
      }
      nb[i] = std::min<std::int32_t>(nb[i], Integrator::kMaxBin);
    }
    changed = nb != b;
    b = nb;
  }
  return b;
}

// The bin limiter (Integrator::limit_bins) on the solver's grid against its brute-force twin: a few particles put
// five bins finer than their level, then passes until none changes. The result is the brute force's fixed point,
// every pair of neighbours ends at most bin_jump apart, and bins are only ever raised.
TEST(Integrator, BinLimiterEqualsBruteForceAndBoundsNeighbours) {
  Simulation sim = three_level_cloud(TimeStepping::per_level);
  sim.remove_ghosts();
  ParticleStore<2> s = sim.store();
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> one_in(0, 40);
  for (std::size_t i = 0; i < s.size(); ++i) s.next_bin[i] = s.level[i] + (one_in(rng) == 0 ? 5 : 0);
  CellGrid<2> grid;
  test::build_level_grid_in_order(s, grid);
  ASSERT_EQ(grid.layer_count(), 3);
  const std::vector<std::int32_t> chosen(s.next_bin.data(), s.next_bin.data() + s.size());
  for (const int jump : {1, 2, 3}) {
    SCOPED_TRACE(testing::Message() << "bin_jump " << jump);
    std::copy(chosen.begin(), chosen.end(), s.next_bin.data());
    const Integrator integ(TimeStepping::per_level, TaitEquationOfState{}, jump);
    Integrator::BinLimiterWork work;
    int passes = 0;
    while (integ.limit_bins(s.view(), grid, work)) {
      ++passes;
      ASSERT_LE(passes, Integrator::kMaxBin) << "each pass that changes raises some bin, and bins stop at the cap";
    }
    // A bin five above its neighbours' raises ring after ring of neighbours, the k-th pass's ring to 5 - k jump
    // above theirs while that is positive: at least ceil(5 / jump) - 1 passes that change something.
    EXPECT_GE(passes, (5 + jump - 1) / jump - 1) << "the raise propagates over several passes";
    const std::vector<std::int32_t> twin = limited_bins_brute_force(s, chosen, jump);
    std::size_t raised_count = 0, pairs = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      EXPECT_EQ(s.next_bin[i], twin[i]) << "particle " << i;
      EXPECT_GE(s.next_bin[i], chosen[i]);
      raised_count += s.next_bin[i] > chosen[i];
      for (std::size_t j = 0; j < s.size(); ++j) {
        const double support = s.h[i] + s.h[j];
        if (j == i || (s.x[i] - s.x[j]).squaredNorm() >= support * support) continue;
        ++pairs;
        EXPECT_LE(std::abs(s.next_bin[i] - s.next_bin[j]), jump);
      }
    }
    EXPECT_GT(raised_count, 20u);
    EXPECT_GT(pairs, 1000u);
  }
}

// Integrator::neighbourhood_bins on the solver's grid against its brute-force twin: on the three-level cloud, each
// fluid particle's next bin is bin_for(dt0) of the smallest of its own limit and each non-wall neighbour's scaled
// by h_i / h_j, exactly; the store's limits are left as they were. Two fields of limits: random over a decade
// (most particles have a neighbour a bin shorter, and the walk decides) and within 3 % of one value (a calm region:
// the pre-tests decide for most), each at coarse steps that put the bins at every level and a few finer.
TEST(Integrator, NeighbourhoodBinsEqualBruteForce) {
  Simulation sim = three_level_cloud(TimeStepping::per_level);
  sim.remove_ghosts();
  ParticleStore<2> s = sim.store();
  CellGrid<2> grid;
  test::build_level_grid_in_order(s, grid);  // reorders the store by cells
  const Integrator integ(TimeStepping::per_level, TaitEquationOfState{});
  Integrator::NeighbourhoodWork work;
  const double cfl = 0.2;
  for (const double spread : {0.9, 0.03}) {
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> U(1.0 - spread, 1.0);
    for (std::size_t i = 0; i < s.size(); ++i) s.dt_limit[i] = 1e-3 * U(rng);
    const std::vector<double> own(s.dt_limit.data(), s.dt_limit.data() + s.size());
    for (const double dt0 : {1e-4, 8e-4, 3e-3, 2e-2}) {
      SCOPED_TRACE("spread " + std::to_string(spread) + ", dt0 " + std::to_string(dt0));
      integ.neighbourhood_bins(s.view(), grid, dt0, cfl, work);
      std::size_t raised = 0, fluid = 0;
      std::set<std::int32_t> bins;
      for (std::size_t i = 0; i < s.size(); ++i) {
        EXPECT_EQ(s.dt_limit[i], own[i]) << "the store keeps each particle's own limit";
        if (s.kind[i] != Kind::fluid) continue;
        ++fluid;
        double m = own[i];
        for (std::size_t j = 0; j < s.size(); ++j) {
          const double support = s.h[i] + s.h[j];
          if (j == i || s.kind[j] == Kind::wall || (s.x[i] - s.x[j]).squaredNorm() >= support * support) continue;
          m = std::min(m, own[j] * (s.h[i] / s.h[j]));
        }
        const int expected = integ.bin_for(s.view(), i, dt0, cfl, m);
        ASSERT_EQ(s.next_bin[i], expected) << "particle " << i;
        raised += expected > integ.bin_for(s.view(), i, dt0, cfl);
        bins.insert(s.next_bin[i]);
      }
      // The premise of the comparison: the neighbourhood moves some particles, and the bins are not all one.
      if (dt0 >= 8e-4 && spread > 0.5) {
        EXPECT_GT(raised, fluid / 10);
      }
      EXPECT_GE(bins.size(), 2u);
    }
  }
}

// Integrator::bins_for_shares, the one walk behind Simulation::choose_bins' nine candidate steps, equals bin_for at
// each candidate, exactly. Limits spread over three decades around the candidates' steps (so that each particle's
// bin falls at its level, a few bins finer, or at the cap), on every level of the three-level cloud, and the edge
// cases bin_from treats apart: no limit yet (0), a NaN limit and an infinite target.
TEST(Integrator, BinsForSharesEqualBinForAtEachCandidate) {
  ASSERT_EQ(Integrator::shrink(Integrator::kShrinks - 1), 0.5) << "the premise: the last candidate is half the first";
  Simulation sim = three_level_cloud(TimeStepping::per_level);
  ParticleStore<2> s = sim.store();
  const Integrator integ(TimeStepping::per_level, TaitEquationOfState{});
  const double cfl = 0.2;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> decades(-3.0, 0.0);
  for (std::size_t i = 0; i < s.size(); ++i) s.dt_limit[i] = 1e-3 * std::pow(10.0, decades(rng));
  s.dt_limit[0] = 0.0;
  s.dt_limit[1] = std::numeric_limits<double>::quiet_NaN();
  std::set<int> seen;
  std::size_t moved = 0;  // particles whose bin differs between the first and the last candidate
  for (const double target : {2e-4, 1.3e-3, 7e-3, std::numeric_limits<double>::infinity()}) {
    std::array<double, Integrator::kShrinks> candidate{};
    for (int k = 0; k < Integrator::kShrinks; ++k) candidate[static_cast<std::size_t>(k)] = target * Integrator::shrink(k);
    for (std::size_t i = 0; i < s.size(); ++i) {
      std::array<int, Integrator::kShrinks> bins{};
      integ.bins_for_shares(s.view(), i, candidate, cfl, bins);
      for (std::size_t k = 0; k < bins.size(); ++k) {
        ASSERT_EQ(bins[k], integ.bin_for(s.view(), i, candidate[k], cfl)) << "particle " << i << ", candidate " << k;
        seen.insert(bins[k]);
      }
      moved += bins.front() != bins.back();
    }
  }
  // The premise of the comparison: bins from the coarsest to the cap, and candidates that move particles a bin.
  EXPECT_TRUE(seen.count(0) && seen.count(Integrator::kMaxBin));
  EXPECT_GT(moved, s.size() / 10);
}

// With bin_jump = 1 (the default), over 200 coarse steps of the three-level cloud with the last-rate predictor
// (whose stiff daughters step a bin finer than their level, three_level_cloud, which gives the limiter work): after
// every step no two neighbours' bins differ by more than one; the limiter acted (the run takes more evaluations
// than with bin_jump = 2, where the daughters at the level jumps that step a bin finer than their level sit two bins from their coarse
// neighbours); linear and angular momentum stay exact (the bounds of the conservation test above: raised bins
// change from step to step, so steps rebin); and the run is the same at 1 and 2 threads.
TEST(Integrator, BinJumpOneKeepsNeighboursWithinOneBinAndMomentumExact) {
  const int threads = omp_get_max_threads();
  const std::uint64_t steps = test::short_runs() ? 40 : 200;
  std::uint64_t jump2_evaluations = 0;
  {
    omp_set_num_threads(1);
    Simulation sim = three_level_cloud(TimeStepping::per_level, 2, TimePredictor::last_rate);
    for (std::uint64_t k = 0; k < steps; ++k) sim.step();
    for (const std::uint64_t e : sim.work().evaluations) jump2_evaluations += e;
  }
  ParticleStore<2> result[2];
  for (int t = 1; t <= 2; ++t) {
    omp_set_num_threads(t);
    Simulation sim = three_level_cloud(TimeStepping::per_level, 1, TimePredictor::last_rate);
    const Totals m0 = totals(sim.store());
    const test::MomentumScales sc = test::momentum_scales(sim.store());
    std::size_t violations = 0;
    for (std::uint64_t k = 0; k < steps; ++k) {
      sim.step();
      const auto& s = sim.store();
      for (std::size_t i = 0; i < s.size(); ++i) {
        if (s.kind[i] != Kind::fluid) continue;
        for (std::size_t j = i + 1; j < s.size(); ++j) {
          const double support = s.h[i] + s.h[j];
          if (s.kind[j] != Kind::fluid || (s.x[i] - s.x[j]).squaredNorm() >= support * support) continue;
          violations += std::abs(s.bin[i] - s.bin[j]) > 1;
        }
      }
    }
    EXPECT_EQ(violations, 0u);
    std::uint64_t evaluations = 0;
    for (const std::uint64_t e : sim.work().evaluations) evaluations += e;
    EXPECT_GT(evaluations, jump2_evaluations) << "the limiter raised some bins that bin_jump 2 leaves";
    sim.remove_ghosts();
    const Totals m1 = totals(sim.store());
    EXPECT_LE((m1.P - m0.P).norm(), 1e-12 * sc.linear);
    EXPECT_LE(std::abs(m1.L - m0.L), 1e-10 * sc.angular);
    result[t - 1] = sim.store();
  }
  omp_set_num_threads(threads);
  const auto idx0 = fluid_by_id(result[0]), idx1 = fluid_by_id(result[1]);
  ASSERT_EQ(idx0.size(), idx1.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < idx0.size(); ++k) {
    const std::size_t i = idx0[k], j = idx1[k];
    differing += result[0].x[i] != result[1].x[j] || result[0].v[i] != result[1].v[j] ||
                 result[0].rho[i] != result[1].rho[j] || result[0].bin[i] != result[1].bin[j];
  }
  EXPECT_EQ(differing, 0u);
}

// The same bits at 1 and 2 threads with per-level steps (the due-particle prefix, the substep kicks and the
// cross-level impulses all run in parallel loops).
TEST(Integrator, PerLevelIsBitwiseIdenticalAtOneAndTwoThreads) {
  const int threads = omp_get_max_threads();
  ParticleStore<2> result[2];
  for (int t = 1; t <= 2; ++t) {
    omp_set_num_threads(t);
    Simulation sim = three_level_cloud(TimeStepping::per_level);
    const int steps = test::short_runs() ? 30 : 100;  // shorter under the sanitizer preset
    for (int k = 0; k < steps; ++k) sim.step();
    sim.remove_ghosts();
    result[t - 1] = sim.store();
  }
  omp_set_num_threads(threads);
  ASSERT_EQ(result[0].size(), result[1].size());
  const auto idx0 = fluid_by_id(result[0]), idx1 = fluid_by_id(result[1]);
  ASSERT_EQ(idx0.size(), idx1.size());
  std::size_t differing = 0, compared = 0;
  for (std::size_t k = 0; k < idx0.size(); ++k) {
    const std::size_t i = idx0[k], j = idx1[k];
    ++compared;
    differing += result[0].id[i] != result[1].id[j];
    differing += result[0].x[i] != result[1].x[j] || result[0].v[i] != result[1].v[j] ||
                 result[0].rho[i] != result[1].rho[j] || result[0].a[i] != result[1].a[j];
  }
  EXPECT_GT(compared, 500u);
  EXPECT_EQ(differing, 0u);
}

}  // namespace
