// The pair sweep with time bins (core/sweep.hpp, Activity): each active bin of a step against the brute-force twin of
// the weighted sums, the rebin evaluation, the jerk, and the single-rate loop against the binned one. The sweep's
// other tests are in tests/test_sweep.cpp, with the same twin cloud (tests/support/brute_force_sweep.hpp).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "core/integrator.hpp"
#include "core/sweep_factory.hpp"
#include "tests/support/brute_force_sweep.hpp"
#include "tests/support/physics_helpers.hpp"

namespace {

using sph::CellGrid;
using sph::Kind;
using sph::ParticleStore;
using sph::SolverSettings;
using sph::Vec;
using namespace sph::test;

// Time bins: a cloud on levels 0, 1 and 2, swept at each active bin of a three-bin step (with and without the
// due-particle prefix that lets particles that are not due skip candidate runs), against the brute force of the
// same weighted sums. Particles that are not due keep their rates (a sentinel here).
TEST(Sweep, TimeBinsEqualBruteForce) {
  const SolverSettings st = twin_settings(true, true);
  ParticleStore<2> s = twin_cloud(st, 12u);
  std::size_t fine = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::wall || s.level[i] != 1 || i % 2 != 0) continue;
    s.level[i] = 2;  // a level-2 particle: half a level-1 particle's spacing and h, a quarter of its mass
    s.d[i] *= 0.5;
    s.h[i] *= 0.5;
    s.m[i] *= 0.25;
    fine += s.kind[i] == Kind::fluid;
  }
  ASSERT_GT(fine, 50u);
  for (std::size_t i = 0; i < s.size(); ++i) s.bin[i] = s.next_bin[i] = s.level[i];  // each level in its own bin
  const auto sweep = sph::make_sweep(st);
  // One grid for every level, and the solver's grid with a layer per level (whose layers without a due particle
  // a particle that is not due skips whole).
  for (const bool layered : {false, true}) {
    CellGrid<2> grid;
    if (layered) {
      sph::test::build_level_grid_in_order(s, grid);
      ASSERT_EQ(grid.layer_count(), 3);
    } else {
      build_grid(s, grid);
    }
    for (const int active : {2, 1, 0}) {
      // The kicks, rates and candidates of each variant: none, the prefix, the prefix and the due list, and those
      // with the top bin (Activity::top_bin: the level-2 particles walk their pairs without reading their bins).
      std::vector<std::vector<Vec<2>>> kicks, rates;
      std::vector<std::uint64_t> candidates;
      for (const int skip : {0, 1, 2, 3}) {
        SCOPED_TRACE(testing::Message() << "active bin " << active
                                        << (skip == 1 ? ", with the prefix" : (skip >= 2 ? ", with the due list" : ""))
                                        << (skip == 3 ? " and the top bin" : "")
                                        << (layered ? ", a layer per level" : ", one grid"));
        sph::Activity act{active, sph::Integrator::kMaxBin};
        const DueLists due = due_lists(s, act);
        if (skip >= 1) act.due_prefix = due.prefix.data();
        if (skip >= 2) act.due_index = due.index.data();
        if (skip == 3) act.top_bin = 2;
        const Vec<2> sentinel(1234.5, -6789.0);
        for (std::size_t i = 0; i < s.size(); ++i) {
          s.a[i] = sentinel;
          s.drho[i] = 42.0;
        }
        const sph::SweepLimits lim = sweep->run(s.view(), grid, act);
        expect_rates_match_brute_force(s, lim, st, "bins", act);
        std::size_t kept = 0, touched = 0;
        for (std::size_t i = 0; i < s.size(); ++i) {
          if (s.kind[i] != Kind::fluid || s.bin[i] >= active) continue;
          EXPECT_EQ(s.a[i], sentinel) << i;
          EXPECT_EQ(s.drho[i], 42.0) << i;
          ++kept;
          touched += s.kick[i] != Vec<2>::Zero();
        }
        if (active > 0) {
          EXPECT_GT(kept, 50u);
          EXPECT_GT(touched, 20u) << "coarser particles take the impulses of their due neighbours";
          EXPECT_EQ(lim.finest_bin, 2);
        }
        kicks.emplace_back(s.kick.values().begin(), s.kick.values().end());
        rates.emplace_back(s.full_a.values().begin(), s.full_a.values().end());
        candidates.push_back(lim.candidates);
      }
      // The prefix and the due list only skip candidates that cannot pair, and the top bin only skips reading bins
      // that cannot change b_ij: the same sums, bit for bit, in the same order; with some particles not due, the
      // prefix and the list each skip some candidates.
      EXPECT_EQ(kicks[1], kicks[0]);
      EXPECT_EQ(kicks[2], kicks[0]);
      EXPECT_EQ(kicks[3], kicks[0]);
      EXPECT_EQ(rates[3], rates[0]);
      EXPECT_EQ(candidates[3], candidates[2]);
      if (active > 0) {
        EXPECT_LE(candidates[1], candidates[0]);
        // With a layer per level every particle of a due layer is due here (each level in its own bin): the list
        // has nothing more to skip. In one grid the runs mix the levels.
        if (layered) {
          EXPECT_EQ(candidates[2], candidates[1]);
        } else {
          EXPECT_LT(candidates[2], candidates[1]);
        }
      } else {
        EXPECT_EQ(candidates[2], candidates[0]);
      }
    }
  }
  // The last evaluation of a step whose bins change (Activity::rebin): some particles move one bin finer, some
  // one coarser (never coarser than their level, as Integrator::bin_for has it). kick must keep this step's
  // weights, a and drho take the next step's.
  std::size_t moved = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    if (i % 5 == 0) s.bin[i] = s.level[i] + 1;  // a particle that was finer than its level this step
    if (i % 7 == 0) s.next_bin[i] = s.level[i] + 1;
    moved += s.bin[i] != s.next_bin[i];
  }
  ASSERT_GT(moved, 50u);
  CellGrid<2> grid;
  sph::test::build_level_grid_in_order(s, grid);
  sph::Activity act{0, sph::Integrator::kMaxBin};
  act.rebin = true;
  const sph::SweepLimits lim = sweep->run(s.view(), grid, act);
  expect_rates_match_brute_force(s, lim, st, "rebin", act);
  EXPECT_EQ(lim.finest_bin, 3);
  // And without rebin the same store gives other rates: the test can tell the weights apart.
  const ParticleStore<2> with_rebin = s;
  sweep->run(s.view(), grid, sph::Activity{0, sph::Integrator::kMaxBin});
  std::size_t differ = 0;
  for (std::size_t i = 0; i < s.size(); ++i) differ += s.kind[i] == Kind::fluid && s.a[i] != with_rebin.a[i];
  EXPECT_GT(differ, 50u);
}

// The jerk (Integrator::drift's extrapolation): a due particle's change of its rates at full weight (full_a, full_drho)
// since its last evaluation over the time between them, dt0 2^-b (Activity::dt0); an evaluation that ends no step (dt0 = 0, Simulation::refresh)
// and a particle that is not due leave it as it was. Exact: the sweep forms the same difference and quotient.
TEST(Sweep, TheJerkIsTheRatesChangeOverTheTimeSinceTheLastEvaluation) {
  const SolverSettings st = twin_settings(true, true);
  ParticleStore<2> s = twin_cloud(st, 11u);
  for (std::size_t i = 0; i < s.size(); ++i) s.bin[i] = s.next_bin[i] = static_cast<std::int32_t>(i % 2);
  CellGrid<2> grid;
  build_grid(s, grid);
  const auto sweep = sph::make_sweep(st);
  const Vec<2> sentinel(1234.5, -6789.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.jerk[i] = sentinel;
    s.density_jerk[i] = 42.0;
  }
  sweep->run(s.view(), grid, sph::Activity{0, sph::Integrator::kMaxBin});  // dt0 = 0: no step ends here
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.jerk[i], sentinel) << i;
    EXPECT_EQ(s.density_jerk[i], 42.0) << i;
  }
  // The flow moves on: new velocities, so the rates change; then the evaluation at the end of a substep where only
  // bin 1 is due, and at the end of the step.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.kind[i] == Kind::fluid) s.v[i] += Vec<2>(u(rng), u(rng));
  const double dt0 = 0.01;
  for (const int active : {1, 0}) {
    SCOPED_TRACE(testing::Message() << "active bin " << active);
    const std::vector<Vec<2>> a_before = s.full_a.values(), jerk_before = s.jerk.values();
    const std::vector<double> drho_before = s.full_drho.values(), density_jerk_before = s.density_jerk.values();
    sph::Activity act{active, sph::Integrator::kMaxBin};
    act.dt0 = dt0;
    sweep->run(s.view(), grid, act);
    std::size_t changed = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.kind[i] != Kind::fluid) continue;
      if (s.bin[i] < active) {
        EXPECT_EQ(s.jerk[i], jerk_before[i]) << i;
        EXPECT_EQ(s.density_jerk[i], density_jerk_before[i]) << i;
        continue;
      }
      const double since = s.bin[i] == 0 ? dt0 : 0.5 * dt0;
      EXPECT_EQ(s.jerk[i], Vec<2>((s.full_a[i] - a_before[i]) / since)) << i;
      EXPECT_EQ(s.density_jerk[i], (s.full_drho[i] - drho_before[i]) / since) << i;
      changed += s.jerk[i] != Vec<2>::Zero();
    }
    EXPECT_GT(changed, 50u);
  }
}

// The sweep runs one of three loops, chosen per evaluation (PairSweep::operator()): single-rate, binned, and binned
// with the next step's sums (rebin). With every particle in bin 0 the binned loop evaluates the same pairs as the
// single-rate one, at weight 1 and in the same order, so it must give the same bits: rates, kicks, jerks, limits
// and counts. (The rebin loop sums each pair on its own before adding it, so it differs in rounding; its
// brute-force twin is TimeBinsEqualBruteForce.) Each loop has its brute-force twins above.
TEST(Sweep, SingleRateAndBinnedLoopsAgreeBitwiseWithEveryParticleInBinZero) {
  for (const bool viscosity : {false, true}) {
    SCOPED_TRACE(viscosity ? "viscosity and Lennard-Jones walls" : "Lennard-Jones walls");
    const SolverSettings st = twin_settings(viscosity, true);
    ParticleStore<2> s = twin_cloud(st, 13u);
    for (std::size_t i = 0; i < s.size(); ++i) s.bin[i] = s.next_bin[i] = 0;
    CellGrid<2> grid;
    build_grid(s, grid);
    const auto sweep = sph::make_sweep(st);
    const ParticleStore<2> start = s;
    std::vector<ParticleStore<2>> out;
    std::vector<sph::SweepLimits> lims;
    for (const int loop : {0, 1}) {
      s = start;
      sph::Activity act;  // loop 0: the single-rate default
      if (loop == 1) act.bin_cap = sph::Integrator::kMaxBin;
      act.dt0 = 1e-3;  // so that the jerks are set, and compared
      lims.push_back(sweep->run(s.view(), grid, act));
      out.push_back(s);
    }
    std::size_t fluid = 0;
    for (std::size_t i = 0; i < s.size(); ++i) fluid += s.kind[i] == Kind::fluid;
    ASSERT_GT(fluid, 400u);
    {
      const ParticleStore<2>& a = out[0];
      const ParticleStore<2>& b = out[1];
      EXPECT_EQ(a.a.values(), b.a.values());
      EXPECT_EQ(a.drho.values(), b.drho.values());
      EXPECT_EQ(a.kick.values(), b.kick.values());
      EXPECT_EQ(a.kick_rho.values(), b.kick_rho.values());
      EXPECT_EQ(a.jerk.values(), b.jerk.values());
      EXPECT_EQ(a.density_jerk.values(), b.density_jerk.values());
      EXPECT_EQ(a.dt_limit.values(), b.dt_limit.values());
      EXPECT_EQ(a.stiffness.values(), b.stiffness.values());
      const sph::SweepLimits& x = lims[0];
      const sph::SweepLimits& y = lims[1];
      EXPECT_EQ(x.dt_force, y.dt_force);
      EXPECT_EQ(x.dt_cfl, y.dt_cfl);
      EXPECT_EQ(x.pairs, y.pairs);
      EXPECT_EQ(x.candidates, y.candidates);
      EXPECT_EQ(x.finest_bin, y.finest_bin);
    }
    // Not vacuous: the sweep did work, and the jerk was set from a rate that changed.
    EXPECT_GT(lims[0].pairs, 5000u);
    std::size_t jerked = 0;
    for (std::size_t i = 0; i < s.size(); ++i) jerked += out[0].jerk[i] != Vec<2>::Zero();
    EXPECT_GT(jerked, 400u);
  }
}

}  // namespace
