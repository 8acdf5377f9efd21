// Buffered levels (effects.refinement.coupling = "buffered", core/refinement/buffer.hpp): the sweep's own-level
// pairs against the brute force, the band, the buffer particles' ties, flips and walls, and issue #15's still tank
// with a refined zone. The passive particles' fit is in test_passive_fit.cpp, the dam-break flows in
// test_buffered_flow.cpp.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <set>
#include <vector>

#include "core/case_builder.hpp"
#include "core/integrator.hpp"
#include "core/refinement/buffer.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/scene/runner.hpp"
#include "core/scene/scene_parser.hpp"
#include "tests/support/brute_force_sweep.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/still_tank_run.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;
using sph::test::brute_force;
using sph::test::make_some_passive;
using sph::test::twin_cloud;
using sph::test::twin_settings;

TEST(BufferedLevels, SweepPairsOnlyWithinALevelAsTheBruteForceDoes) {
  const SolverSettings st = twin_settings(true, true);
  ParticleStore<2> s = twin_cloud(st, 41);
  ASSERT_GT(make_some_passive(s), 100u);
  CellGrid<2> grid;
  sph::test::build_grid(s, grid);
  Activity act;
  act.own_level_only = true;
  const SweepLimits lim = make_sweep(st)->run(s.view(), grid, act);
  sph::test::expect_rates_match_brute_force(s, lim, st, "own level only", act);
  // The twin is sharp: dropping the other level's pairs changes most rates beyond the comparison's tolerance.
  EXPECT_GT(sph::test::changed_accelerations(brute_force(s, st, act), brute_force(s, st, Activity{})), 100u);
  // Per-level steps (each level in its own bin): the binned loop at each active bin, and the rebin evaluation of a
  // step after which some particles change bin, against the same twin.
  for (std::size_t i = 0; i < s.size(); ++i) s.bin[i] = s.next_bin[i] = s.level[i];
  for (const int active : {1, 0}) {
    SCOPED_TRACE(testing::Message() << "active bin " << active);
    Activity binned{active, Integrator::kMaxBin};
    binned.own_level_only = true;
    const SweepLimits b = make_sweep(st)->run(s.view(), grid, binned);
    sph::test::expect_rates_match_brute_force(s, b, st, "own level only, bins", binned);
  }
  std::size_t moved = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || i % 5 != 0) continue;
    s.next_bin[i] = s.level[i] + 1;
    ++moved;
  }
  ASSERT_GT(moved, 20u);
  Activity rebin{0, Integrator::kMaxBin};
  rebin.own_level_only = true;
  rebin.rebin = true;
  const SweepLimits r = make_sweep(st)->run(s.view(), grid, rebin);
  sph::test::expect_rates_match_brute_force(s, r, st, "own level only, rebin", rebin);
}

/// prepare_buffered_marks' band written out directly: every pair of particles, no cells.
std::vector<std::uint8_t> brute_band(const ParticleStore<2>& s, std::vector<std::uint8_t> marks, int max_level) {
  // Mixed fluid: an active particle with an active one of the next level within kIntermixReach of its spacing.
  std::vector<std::uint8_t> mixed(s.size(), 0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || is_passive(s.role[i]) || s.level[i] >= max_level) continue;
    for (std::size_t j = 0; j < s.size(); ++j) {
      if (s.kind[j] == Kind::fluid && !is_passive(s.role[j]) && s.level[j] == s.level[i] + 1 &&
          (s.x[i] - s.x[j]).norm() < refine::kIntermixReach * s.d[i]) {
        mixed[i] = 1;
      }
    }
  }
  for (std::size_t i = 0; i < s.size(); ++i) marks[i] = marks[i] || mixed[i];
  // Marks kept only on active particles (no particle of the cloud has daughters: every id is of generation 0).
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (marks[i] && (s.kind[i] != Kind::fluid || s.role[i] != Role::active)) marks[i] = 0;
  }
  std::vector<std::uint8_t> out = marks;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || marks[i] != 0 || s.level[i] >= max_level) continue;
    if (s.role[i] != Role::active && s.role[i] != Role::buffer) continue;
    const double to_daughters = s.h[i] + s.d[i];
    for (std::size_t j = 0; j < s.size() && out[i] == 0; ++j) {
      if (s.kind[j] != Kind::fluid) continue;
      const double r = (s.x[i] - s.x[j]).norm();
      if (s.level[j] == s.level[i] + 1 && !is_passive(s.role[j]) && r < to_daughters) out[i] = 2;
      if (s.level[j] == s.level[i] && marks[j] == 1 && r < to_daughters + 0.5 * std::sqrt(2.0) * s.d[i]) out[i] = 2;
    }
  }
  return out;
}

TEST(BufferedLevels, BandMarksEqualTheBruteForce) {
  const SolverSettings st = twin_settings(false, false);
  ParticleStore<2> s = twin_cloud(st, 23);  // levels 0 and 1, some ghost-kind particles, walls
  make_some_passive(s);
  // Level 1 active only where x < 3, so that the band from level 1's particles and the band from this pass's marks
  // (x > 6, y > 5) are apart, and each reach is seen at its own edge.
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && s.level[i] == 1 && s.x[i][0] >= 3.0) s.role[i] = Role::buffer;
  }
  std::vector<std::uint8_t> marks(s.size(), 0);
  for (std::size_t i = 0; i < s.size(); ++i) {  // a zone of marks at each level, on active and passive particles
    if (s.x[i][0] > 6.0 && s.x[i][1] > 5.0) marks[i] = 1;
  }
  const std::vector<std::uint8_t> zone = marks;
  const std::vector<std::uint8_t> expected = brute_band(s, marks, 2);
  ASSERT_EQ(refine::prepare_buffered_marks(s, marks, 2, refine::DaughterDensityIn<2>{}), 0u);  // no hosts in the cloud: nothing flips
  std::size_t band = 0, mixed = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(marks[i], expected[i]) << i << " at " << s.x[i].transpose() << ", level " << s.level[i];
    band += marks[i] == 2 ? 1 : 0;
    mixed += marks[i] == 1 && zone[i] == 0 ? 1 : 0;
  }
  EXPECT_GT(band, 50u);  // the band is there at both levels, so the comparison sees it
  EXPECT_GT(mixed, 10u);  // and the levels mixed where x < 3
}

using test::TankRun;

TankRun run_tank(const refine::RefinementSettings* r, double end, TimeStepping stepping) {
  TankSpec spec;
  spec.stepping = stepping;
  Simulation sim = make_still_tank(spec);
  if (r != nullptr) refine::add_refinement_stage(sim, *r);
  TankRun out = test::measure_still_tank(sim, end);
  const auto& s = sim.store();
  const int finest = r != nullptr ? r->max_level : 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || is_passive(s.role[i])) continue;
    if (s.level[i] == 0) out.coarse_bin = std::max(out.coarse_bin, s.bin[i]);
    if (s.level[i] == finest) out.fine_bin = out.fine_bin < 0 ? s.bin[i] : std::min(out.fine_bin, s.bin[i]);
  }
  return out;
}

struct TankCase {
  const char* name;
  Vec<2> lo, hi;
  refine::Pattern pattern;
  int levels;
  TimeStepping stepping = TimeStepping::global;
};

class BufferedStillTank : public ::testing::TestWithParam<TankCase> {};

// Issue #15's first target, with buffered levels: the still tank with a refined zone stays within twice the unrefined
// tank's largest speed (the bound; the largest speed oscillates with the tank's compression mode, so each run's
// is averaged over the last two thirds of the run, as tools/still_water_report.py does), takes exactly one pass per
// level and no pass after (no creep), loses no particle, and each pass changes the total energy by at most 1e-6 of
// E(0) (the pass target). 10 s is 14 periods of the compression mode and four times the time in which every refined
// tank of the paper's coupling failed at a wall or a corner (docs/METHOD.md); the report runs 30 s.
TEST_P(BufferedStillTank, StaysAsStillAsTheUnrefinedTank) {
  const TankCase& c = GetParam();
  const double end = test::short_runs() ? 4.0 : 10.0;
  const refine::RefinementSettings r = test::buffered_zone(Box2{c.lo, c.hi}, c.pattern, c.levels);
  const TankRun plain = run_tank(nullptr, end, c.stepping);
  const TankRun refined = run_tank(&r, end, c.stepping);
  RecordProperty("window_speed_over_unrefined", std::to_string(refined.window_speed / plain.window_speed));
  EXPECT_EQ(refined.passes, static_cast<std::size_t>(c.levels));
  EXPECT_LE(refined.window_speed, 2.0 * plain.window_speed) << "unrefined " << plain.window_speed;
  EXPECT_EQ(refined.fluid_end, refined.fluid_after_last);
  EXPECT_GT(refined.fluid_after_last, plain.fluid_end);
  EXPECT_EQ(refined.outside, 0u);
  EXPECT_LE(refined.largest_pass_change, 1e-6 * refined.e0);
  if (c.stepping == TimeStepping::per_level) {  // the levels did step in bins of their own, the finest the finer
    EXPECT_GE(refined.coarse_bin, 0);
    EXPECT_LT(refined.coarse_bin, refined.fine_bin);
  }
}

INSTANTIATE_TEST_SUITE_P(Zones, BufferedStillTank,
                         ::testing::Values(TankCase{"bulk_aap_1", Vec<2>(10, 3), Vec<2>(15, 7), refine::Pattern::aap, 1},
                                           TankCase{"wall_rsp_1", Vec<2>(0, 3), Vec<2>(4, 7), refine::Pattern::rsp, 1},
                                           TankCase{"wall_rsp_2", Vec<2>(0, 3), Vec<2>(4, 7), refine::Pattern::rsp, 2},
                                           TankCase{"corner_rsp_2", Vec<2>(0, 0), Vec<2>(5, 4), refine::Pattern::rsp, 2},
                                           // Issue #16's "two levels in their own bins stay at rest": each level
                                           // steps in its own bin (buffered levels pair within a level only, so
                                           // the limiter and the neighbourhood limit look at the own level).
                                           TankCase{"bulk_aap_2_per_level", Vec<2>(10, 3), Vec<2>(15, 7),
                                                    refine::Pattern::aap, 2, TimeStepping::per_level},
                                           TankCase{"corner_rsp_2_per_level", Vec<2>(0, 0), Vec<2>(5, 4),
                                                    refine::Pattern::rsp, 2, TimeStepping::per_level}),
                         [](const auto& p) { return std::string(p.param.name); });

/// tie_buffers against the brute force: after the hosts move (each by its own displacement), every buffer particle
/// sits at its host's place plus its tie, the host found by a scan of the whole store, level by level, so that a
/// buffer particle whose host is a buffer particle follows it.
/// The still tank with the AAP zone `zone` at max_level levels, buffered, checked every 50 steps, after `steps` steps:
/// a pass at step 50 (and 100), so hosts and their buffer particles are in the store.
Simulation refined_still_tank(const Box2& zone, int max_level, int steps) {
  refine::RefinementSettings r;
  r.criterion = refine::CriterionKind::zone;
  r.zone = zone;
  r.check_interval = 50;
  r.max_level = max_level;
  r.coupling = LevelCoupling::buffered;
  Simulation sim = make_still_tank(TankSpec{});
  refine::add_refinement_stage(sim, r);
  for (int k = 0; k < steps; ++k) {
    sim.step();
    sim.run_stages();
  }
  return sim;
}

TEST(BufferedLevels, BufferParticlesFollowTheirHostsAsTheBruteForcePlacesThem) {
  Simulation sim = refined_still_tank(Box2{Vec<2>(0, 3), Vec<2>(4, 7)}, 2, 120);
  ParticleStore<2> s = sim.store();
  std::size_t nested = 0, buffers = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    if (s.role[i] == Role::host || s.role[i] == Role::buffer) {  // displaced: none is where its buffers were put
      s.x[i] += Vec<2>(1e-3 * static_cast<double>(1 + i % 7), -2e-3 * static_cast<double>(1 + i % 5));
    }
    if (s.role[i] == Role::buffer) ++buffers;
    if (s.role[i] == Role::buffer && s.level[i] == 2) ++nested;
  }
  ASSERT_GT(nested, 20u) << "level-2 buffer particles, hosted by level-1 buffer particles";
  ParticleStore<2> expected = s;
  for (int l = 1; l <= 2; ++l) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (expected.kind[i] != Kind::fluid || expected.role[i] != Role::buffer || expected.level[i] != l) continue;
      for (std::size_t j = 0; j < s.size(); ++j) {
        if (expected.kind[j] == Kind::fluid && expected.id[j] == refine::parent_id(expected.id[i])) {
          expected.x[i] = expected.x[j] + expected.tie[i];
        }
      }
    }
  }
  refine::tie_buffers(s);
  std::size_t moved = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.x[i], expected.x[i]) << i;
    moved += s.role[i] == Role::buffer && s.x[i] != sim.store().x[i] ? 1 : 0;
  }
  EXPECT_EQ(moved, buffers);
}

/// A passive particle is kept a quarter of its spacing inside every wall it is near (keep_passive_inside_walls): one
/// that drifted within the margin or through the wall by less than its spacing goes back along the wall's normal to
/// the margin, at a corner along both; one where the set-up puts it (half a spacing in) stays, as does an active
/// particle within the margin, a passive one beyond the face's end (the open top's side) and one a spacing or more
/// behind a wall (on an obstacle's far side).
TEST(BufferedLevels, PassiveParticlesStayInsideTheWalls) {
  Geometry2 g;
  g.container = Box2{Vec<2>(0, 0), Vec<2>(10, 5)};
  g.open_top = true;
  const double d = 0.4, margin = refine::passive_wall_margin(d);
  ASSERT_DOUBLE_EQ(margin, 0.1);
  struct Case {
    Vec<2> x;
    Role role;
    Vec<2> expected;
  };
  const std::vector<Case> cases{
      {Vec<2>(9.95, 2.0), Role::shadow, Vec<2>(10.0 - margin, 2.0)},   // within the margin of the right wall
      {Vec<2>(10.02, 2.0), Role::shadow, Vec<2>(10.0 - margin, 2.0)},  // just through it
      {Vec<2>(3.0, -0.05), Role::buffer, Vec<2>(3.0, margin)},         // through the floor
      {Vec<2>(0.03, 0.02), Role::shadow, Vec<2>(margin, margin)},      // into the corner
      {Vec<2>(9.8, 0.2), Role::shadow, Vec<2>(9.8, 0.2)},              // half a spacing in: the set-up's place
      {Vec<2>(9.95, 2.0), Role::active, Vec<2>(9.95, 2.0)},            // active particles are the walls' to hold
      {Vec<2>(9.95, 5.3), Role::shadow, Vec<2>(9.95, 5.3)},            // above the rim: no wall beside it
      {Vec<2>(3.0, -0.5), Role::shadow, Vec<2>(3.0, -0.5)},            // a spacing or more behind the floor
  };
  ParticleStore<2> s;
  s.append(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    s.kind[i] = Kind::fluid;
    s.role[i] = cases[i].role;
    s.d[i] = d;
    s.x[i] = cases[i].x;
  }
  EXPECT_EQ(refine::keep_passive_inside_walls(s, g.walls()), 4u);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_NEAR(s.x[i][0], cases[i].expected[0], 1e-15) << i;
    EXPECT_NEAR(s.x[i][1], cases[i].expected[1], 1e-15) << i;
  }
}

/// A host's flip (prepare_buffered_marks, flip_daughter): its buffer daughters turn active with the host's velocity
/// and the host's density carried along the hydrostatic gradient to each one's tie offset, whatever state their fit
/// had given them; the host turns into a shadow. Mass, momentum and kinetic energy stay exact, and the total energy
/// within issue #15's 1e-6 of E(0) (the gradient's second-order change: per family about m c^2 (g d / 4 c^2)^2, some
/// 1e-10 of E(0) here).
TEST(BufferedLevels, AFlipGivesTheDaughtersTheirHostsStateAndKeepsTheEnergy) {
  Simulation sim = refined_still_tank(Box2{Vec<2>(10, 3), Vec<2>(15, 7)}, 1, 60);
  ParticleStore<2>& s = sim.store();
  // The buffer particles' fitted state, made unlike their hosts' (as in a shearing flow).
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && s.role[i] == Role::buffer) {
      s.v[i] = Vec<2>(0.3 * static_cast<double>(i % 5), -0.2 * static_cast<double>(i % 3));
      s.rho[i] += 2.0 * static_cast<double>(i % 4);
    }
  }
  std::vector<std::uint8_t> marks(s.size(), 0);
  std::vector<std::size_t> hosts;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && s.role[i] == Role::host && s.x[i][0] > 15.0) {  // the band's right-hand side
      marks[i] = 1;
      hosts.push_back(i);
    }
  }
  ASSERT_GT(hosts.size(), 3u);
  const ParticleStore<2> before_store = s;
  const Diagnostics before = sim.diagnostics();
  const refine::DaughterDensityIn<2> density{refine::DaughterDensity::pressure_gradient, Vec<2>(0, -9.81),
                                             sim.settings().eos};
  EXPECT_EQ(refine::prepare_buffered_marks(s, marks, 1, density), hosts.size());
  const Diagnostics after = sim.diagnostics();
  std::size_t daughters = 0;
  for (const std::size_t h : hosts) {
    EXPECT_EQ(s.role[h], Role::shadow);
    const double rho = before_store.rho[h];
    const double c2 = sim.settings().eos.sound_speed_squared(rho);
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (s.kind[k] != Kind::fluid || !refine::has_parent(s.id[k]) || refine::parent_id(s.id[k]) != s.id[h]) continue;
      ++daughters;
      EXPECT_EQ(s.role[k], Role::active);
      EXPECT_EQ(s.v[k], before_store.v[h]);
      EXPECT_EQ(s.x[k], before_store.x[k]);  // in place
      EXPECT_NEAR(s.rho[k], rho - rho * 9.81 * s.tie[k][1] / c2, 1e-12 * rho);
    }
  }
  EXPECT_EQ(daughters, 4 * hosts.size());
  EXPECT_EQ(after.mass, before.mass);
  EXPECT_LE((after.momentum - before.momentum).norm(), 1e-12 * before.mass * 1e-2);  // speeds of mm/s at rest
  EXPECT_NEAR(after.kinetic, before.kinetic, 1e-12 * before.kinetic);
  EXPECT_LE(std::abs(after.total_energy() - before.total_energy()), 1e-6 * std::abs(before.total_energy()));
  EXPECT_GT(std::abs(after.total_energy() - before.total_energy()), 0.0);  // the gradient did change the densities
}

/// A flip two levels deep: a level-0 host whose level-1 buffer daughters host level-2 buffer particles. When the host
/// flips, a daughter with buffer daughters of its own becomes their host (so tie_buffers keeps them beside it, and a
/// later flip of its own can hand them its place), the others active. (Until 2026-12-06 all turned active, and the
/// level-2 buffer particles of an active parent were neither tied nor ever flipped.)
TEST(BufferedLevels, AFlippedDaughterWithBufferDaughtersBecomesTheirHost) {
  Simulation sim = refined_still_tank(Box2{Vec<2>(0, 3), Vec<2>(4, 7)}, 2, 120);
  ParticleStore<2>& s = sim.store();
  std::set<ParticleId> hosting;  // level-1 buffer particles with daughters
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && s.level[i] == 2 && s.role[i] == Role::buffer) hosting.insert(refine::parent_id(s.id[i]));
  }
  std::vector<std::uint8_t> marks(s.size(), 0);
  std::set<ParticleId> flipped;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && s.level[i] == 0 && s.role[i] == Role::host) {
      marks[i] = 1;
      flipped.insert(s.id[i]);
    }
  }
  const refine::DaughterDensityIn<2> density{refine::DaughterDensity::pressure_gradient, Vec<2>(0, -9.81),
                                             sim.settings().eos};
  ASSERT_EQ(refine::prepare_buffered_marks(s, marks, 2, density), flipped.size());
  std::size_t hosts = 0, active = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || s.level[i] != 1 || !flipped.count(refine::parent_id(s.id[i]))) continue;
    if (hosting.count(s.id[i]) != 0) {
      EXPECT_EQ(s.role[i], Role::host) << s.id[i];
      ++hosts;
    } else {
      EXPECT_EQ(s.role[i], Role::active) << s.id[i];
      ++active;
    }
  }
  EXPECT_GT(hosts, 10u);  // the case is there
  EXPECT_GT(active, 10u);
}

/// The same bits at one and two threads, with one global step and per level: the flips, the band, the fit and the
/// bins do not depend on the threads' shares.
class BufferedThreads : public ::testing::TestWithParam<TimeStepping> {};

TEST_P(BufferedThreads, StillTankIsBitwiseTheSameAtOneAndTwoThreads) {
  refine::RefinementSettings r;
  r.criterion = refine::CriterionKind::zone;
  r.zone = Box2{Vec<2>(0, 0), Vec<2>(5, 4)};
  r.pattern = refine::Pattern::rsp;
  r.check_interval = 50;
  r.max_level = 2;
  r.coupling = LevelCoupling::buffered;
  const int threads = omp_get_max_threads();
  std::vector<ParticleStore<2>> ends;
  for (const int t : {1, 2}) {
    omp_set_num_threads(t);
    TankSpec spec;
    spec.stepping = GetParam();
    Simulation sim = make_still_tank(spec);
    refine::add_refinement_stage(sim, r);
    for (int k = 0; k < 220; ++k) {
      sim.step();
      sim.run_stages();
    }
    ends.push_back(sim.store());
  }
  omp_set_num_threads(threads);
  ASSERT_EQ(ends[0].size(), ends[1].size());
  std::size_t passive = 0;
  for (std::size_t i = 0; i < ends[0].size(); ++i) {
    ASSERT_EQ(ends[0].id[i], ends[1].id[i]);
    EXPECT_EQ(ends[0].x[i], ends[1].x[i]) << i;
    EXPECT_EQ(ends[0].v[i], ends[1].v[i]) << i;
    EXPECT_EQ(ends[0].rho[i], ends[1].rho[i]) << i;
    EXPECT_EQ(ends[0].role[i], ends[1].role[i]) << i;
    passive += is_passive(ends[0].role[i]) ? 1 : 0;
  }
  EXPECT_GT(passive, 50u);
}

INSTANTIATE_TEST_SUITE_P(Stepping, BufferedThreads, ::testing::Values(TimeStepping::global, TimeStepping::per_level),
                         [](const auto& p) { return std::string(p.param == TimeStepping::global ? "global" : "per_level"); });

}  // namespace
