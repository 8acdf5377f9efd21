// Buffered levels (effects.refinement.coupling = "buffered", core/refinement/buffer.hpp): the sweep's own-level
// pairs against the brute force, the passive particles' fit against a brute-force fit, and issue #15's still tank
// with a refined zone.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "core/case_builder.hpp"
#include "core/refinement/buffer.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "tests/support/brute_force_sweep.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;
using sph::test::brute_force;
using sph::test::twin_cloud;
using sph::test::twin_settings;

/// Every third fluid particle of the cloud passive (alternately a shadow and a buffer particle).
template <int D>
std::size_t make_some_passive(ParticleStore<D>& s) {
  std::size_t passive = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || i % 3 != 1) continue;
    s.role[i] = (i / 3) % 2 == 0 ? Role::shadow : Role::buffer;
    ++passive;
  }
  return passive;
}

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
}

/// The fit of core/refinement/buffer.hpp written out directly: every particle of the store, the weighted least-squares
/// problem solved by a QR factorisation of the weighted design matrix (not the normal equations the solver forms).
struct BruteFit {
  bool well_posed = false;  // full rank and not near the solver's conditioning threshold
  double rho = 0.0;
  Vec<2> v = Vec<2>::Zero();
};

BruteFit brute_fit(const ParticleStore<2>& s, std::size_t i) {
  std::vector<std::size_t> src;
  for (std::size_t j = 0; j < s.size(); ++j) {
    if (j == i || (s.kind[j] != Kind::fluid && s.kind[j] != Kind::ghost)) continue;
    if (is_passive(s.role[j]) || s.level[j] == s.level[i]) continue;
    if ((s.x[i] - s.x[j]).norm() < s.h[i] + s.h[j]) src.push_back(j);
  }
  BruteFit f;
  if (src.size() < 3) return f;
  Eigen::MatrixXd A(src.size(), 3);
  Eigen::MatrixXd b(src.size(), 3);
  for (std::size_t k = 0; k < src.size(); ++k) {
    const std::size_t j = src[k];
    const double r = (s.x[i] - s.x[j]).norm();
    const double w = CubicSpline<2>::value(r, 0.5 * (s.h[i] + s.h[j])) * s.m[j] / s.rho[j];
    const double sw = std::sqrt(w);
    const Vec<2> dx = (s.x[j] - s.x[i]) / s.h[i];
    const auto row = static_cast<Eigen::Index>(k);
    A(row, 0) = sw;
    A(row, 1) = sw * dx[0];
    A(row, 2) = sw * dx[1];
    b(row, 0) = sw * s.rho[j];
    b(row, 1) = sw * s.v[j][0];
    b(row, 2) = sw * s.v[j][1];
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  const auto sv = svd.singularValues();
  // The solver's threshold is on the normal matrix A^T A, whose condition is the square of A's: 1e-6 there is 1e-3
  // here. Ten times that keeps the particles whose path (fit or Shepard) the rounding could change out of the check.
  f.well_posed = sv(2) > 1e-2 * sv(0);
  const Eigen::MatrixXd c = A.colPivHouseholderQr().solve(b);
  f.rho = c(0, 0);
  f.v = Vec<2>(c(0, 1), c(0, 2));
  return f;
}

TEST(BufferedLevels, PassiveFitEqualsTheBruteForceFitAndIsExactForLinearFields) {
  const SolverSettings st = twin_settings(true, false);
  ParticleStore<2> s = twin_cloud(st, 7);
  make_some_passive(s);
  // Linear fields on the active particles: the fit must give them back at every passive particle's place.
  const auto rho_at = [](const Vec<2>& x) { return 1000.0 + 0.7 * x[0] - 1.3 * x[1]; };
  const auto v_at = [](const Vec<2>& x) { return Vec<2>(0.2 - 0.05 * x[1], -0.1 + 0.03 * x[0] + 0.02 * x[1]); };
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.rho[i] = rho_at(s.x[i]);
    s.v[i] = v_at(s.x[i]);
  }
  CellGrid<2> grid;
  sph::test::build_grid(s, grid);
  std::vector<BruteFit> expected(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && is_passive(s.role[i])) expected[i] = brute_fit(s, i);
  }
  refine::interpolate_passive(s.view(), grid, st.eos);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    if (!is_passive(s.role[i])) {  // active particles keep their values
      EXPECT_EQ(s.rho[i], rho_at(s.x[i]));
      continue;
    }
    if (!expected[i].well_posed) continue;
    ++checked;
    // Both solve the same least-squares problem (conditioned to better than 1e4 here) in double precision: they
    // agree, and reproduce a linear field, to rounding times the condition, ~1e-12 of the values; 1e-9 of the
    // field's spread over the cloud (13 kg/m^3, 0.5 m/s) leaves a factor ~1000 and still fails on a missing source.
    EXPECT_NEAR(s.rho[i], expected[i].rho, 1e-9 * 13.0) << i;
    EXPECT_NEAR(s.rho[i], rho_at(s.x[i]), 1e-9 * 13.0) << i;
    EXPECT_LE((s.v[i] - expected[i].v).norm(), 1e-9 * 0.5) << i;
    EXPECT_LE((s.v[i] - v_at(s.x[i])).norm(), 1e-9 * 0.5) << i;
    EXPECT_EQ(s.p[i], st.eos.pressure(s.rho[i])) << i;
  }
  EXPECT_GT(checked, 100u);
}

/// prepare_buffered_marks' band written out directly: every pair of particles, no cells.
std::vector<std::uint8_t> brute_band(const ParticleStore<2>& s, std::vector<std::uint8_t> marks, int max_level) {
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
  const std::vector<std::uint8_t> expected = brute_band(s, marks, 2);
  ASSERT_EQ(refine::prepare_buffered_marks(s, marks, 2), 0u);  // no hosts in the cloud: nothing flips
  std::size_t band = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(marks[i], expected[i]) << i << " at " << s.x[i].transpose() << ", level " << s.level[i];
    band += marks[i] == 2 ? 1 : 0;
  }
  EXPECT_GT(band, 50u);  // the band is there at both levels, so the comparison sees it
}

struct TankRun {
  double window_speed = 0.0;       // the largest speed of each step, averaged over the steps in [end / 3, end]
  std::size_t fluid_after_last = 0, fluid_end = 0;  // active fluid after the last pass and at the end
  double largest_pass_change = 0.0;  // |E after - E before| of any pass
  double e0 = 0.0;
  std::size_t outside = 0;
  std::size_t passes = 0;
};

TankRun run_tank(const refine::RefinementSettings* r, double end) {
  Simulation sim = make_still_tank(TankSpec{});
  if (r != nullptr) refine::add_refinement_stage(sim, *r);
  TankRun out;
  out.e0 = sim.diagnostics().total_energy();
  double speed_sum = 0.0;
  std::size_t speed_steps = 0;
  while (sim.time() < end) {
    sim.step();
    const Diagnostics before = sim.diagnostics();
    if (sim.time() >= end / 3.0) {
      speed_sum += before.max_speed;
      ++speed_steps;
    }
    const std::size_t stored = sim.store().size();
    sim.run_stages();
    if (sim.store().size() != stored) {
      const Diagnostics after = sim.diagnostics();
      out.largest_pass_change = std::max(out.largest_pass_change, std::abs(after.total_energy() - before.total_energy()));
      out.fluid_after_last = after.fluid;
      ++out.passes;
    }
  }
  out.window_speed = speed_sum / static_cast<double>(std::max<std::size_t>(speed_steps, 1));
  out.fluid_end = sim.diagnostics().fluid;
  const auto& s = sim.store();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && !sim.settings().geometry.in_fluid_domain(s.x[i])) ++out.outside;
  }
  return out;
}

struct TankCase {
  const char* name;
  Vec<2> lo, hi;
  refine::Pattern pattern;
  int levels;
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
  refine::RefinementSettings r;
  r.criterion = refine::CriterionKind::zone;
  r.zone = Box2{c.lo, c.hi};
  r.pattern = c.pattern;
  r.check_interval = 100;
  r.max_level = c.levels;
  r.coupling = LevelCoupling::buffered;
  const TankRun plain = run_tank(nullptr, end);
  const TankRun refined = run_tank(&r, end);
  RecordProperty("window_speed_over_unrefined", std::to_string(refined.window_speed / plain.window_speed));
  EXPECT_EQ(refined.passes, static_cast<std::size_t>(c.levels));
  EXPECT_LE(refined.window_speed, 2.0 * plain.window_speed) << "unrefined " << plain.window_speed;
  EXPECT_EQ(refined.fluid_end, refined.fluid_after_last);
  EXPECT_GT(refined.fluid_after_last, plain.fluid_end);
  EXPECT_EQ(refined.outside, 0u);
  EXPECT_LE(refined.largest_pass_change, 1e-6 * refined.e0);
}

INSTANTIATE_TEST_SUITE_P(Zones, BufferedStillTank,
                         ::testing::Values(TankCase{"bulk_aap_1", Vec<2>(10, 3), Vec<2>(15, 7), refine::Pattern::aap, 1},
                                           TankCase{"wall_rsp_1", Vec<2>(0, 3), Vec<2>(4, 7), refine::Pattern::rsp, 1},
                                           TankCase{"wall_rsp_2", Vec<2>(0, 3), Vec<2>(4, 7), refine::Pattern::rsp, 2},
                                           TankCase{"corner_rsp_2", Vec<2>(0, 0), Vec<2>(5, 4), refine::Pattern::rsp, 2}),
                         [](const auto& p) { return std::string(p.param.name); });

/// tie_buffers against the brute force: after the hosts move (each by its own displacement), every buffer particle
/// sits at its host's place plus its tie, the host found by a scan of the whole store, level by level, so that a
/// buffer particle whose host is a buffer particle follows it.
TEST(BufferedLevels, BufferParticlesFollowTheirHostsAsTheBruteForcePlacesThem) {
  refine::RefinementSettings r;
  r.criterion = refine::CriterionKind::zone;
  r.zone = Box2{Vec<2>(0, 3), Vec<2>(4, 7)};
  r.check_interval = 50;
  r.max_level = 2;
  r.coupling = LevelCoupling::buffered;
  Simulation sim = make_still_tank(TankSpec{});
  refine::add_refinement_stage(sim, r);
  for (int k = 0; k < 120; ++k) {
    sim.step();
    sim.run_stages();
  }
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

/// The same bits at one and two threads: the flips, the band and the fit do not depend on the threads' shares.
TEST(BufferedLevels, StillTankIsBitwiseTheSameAtOneAndTwoThreads) {
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
    Simulation sim = make_still_tank(TankSpec{});
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

}  // namespace
