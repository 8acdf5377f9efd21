#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <random>

#include "core/case_builder.hpp"
#include "core/refinement/criteria.hpp"
#include "core/refinement/family.hpp"
#include "core/refinement/patterns.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/refinement/split_pass.hpp"
#include "core/setup.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;
using refine::Pattern;

struct Totals {
  double mass = 0, ke = 0, L0 = 0, Lfar = 0;
  Vec<2> P = Vec<2>::Zero();
};

Totals totals(const ParticleStore<2>& s) {
  Totals t;
  const Vec<2> far(1.0e3, -2.0e3);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    t.mass += s.m[i];
    t.ke += 0.5 * s.m[i] * s.v[i].squaredNorm();
    t.P += s.m[i] * s.v[i];
    t.L0 += s.m[i] * (s.x[i][0] * s.v[i][1] - s.x[i][1] * s.v[i][0]);
    const Vec<2> r = s.x[i] - far;
    t.Lfar += s.m[i] * (r[0] * s.v[i][1] - r[1] * s.v[i][0]);
  }
  return t;
}

// A disordered cloud of fluid particles (two levels) with random velocities, inside a 10 x 10 box.
ParticleStore<2> random_cloud(std::size_t n, unsigned seed) {
  ParticleStore<2> s;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  s.append(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.x[i] = Vec<2>(1.0 + 8.0 * U(rng), 1.0 + 8.0 * U(rng));
    s.v[i] = Vec<2>(U(rng) - 0.5, U(rng) - 0.5) * 10.0;
    s.level[i] = U(rng) < 0.3 ? 1 : 0;
    s.d[i] = 0.5 / std::pow(2.0, s.level[i]);
    s.h[i] = 1.2 * s.d[i];
    s.m[i] = 1000.0 * s.d[i] * s.d[i];
    s.rho[i] = 1000.0 * (1.0 + 0.01 * (U(rng) - 0.5));
    s.kind[i] = Kind::fluid;
  }
  return s;
}

void expect_rel(double a, double b, double tol, const char* what) {
  EXPECT_LE(std::abs(a - b), tol * std::max(std::abs(a), std::abs(b)) + 1e-300) << what << ": " << a << " vs " << b;
}

void expect_conserved(const Totals& a, const Totals& b, double scale_P, double scale_L) {
  expect_rel(a.mass, b.mass, 1e-12, "mass");
  expect_rel(a.ke, b.ke, 1e-12, "kinetic energy");
  EXPECT_LE((a.P - b.P).norm(), 1e-12 * scale_P) << "linear momentum";
  EXPECT_LE(std::abs(a.L0 - b.L0), 1e-12 * scale_L) << "angular momentum about the origin";
  EXPECT_LE(std::abs(a.Lfar - b.Lfar), 1e-12 * scale_L * 300.0) << "angular momentum about a far point";
}

// Scales for relative momentum checks: sum m|v| and sum m |x||v|.
std::pair<double, double> scales(const ParticleStore<2>& s) {
  double P = 0, L = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    P += s.m[i] * s.v[i].norm();
    L += s.m[i] * s.x[i].norm() * s.v[i].norm();
  }
  return {P, L};
}

class SplitConservation : public ::testing::TestWithParam<std::tuple<Pattern, double>> {};

TEST_P(SplitConservation, EachSplitConservesMassMomentumAngularMomentumAndKineticEnergy) {
  const auto [pattern, k] = GetParam();
  ParticleStore<2> s = random_cloud(2000, 7);
  const Totals before = totals(s);
  const auto [sP, sL] = scales(s);
  std::vector<std::uint8_t> marks(s.size(), 0);
  for (std::size_t i = 0; i < s.size(); i += 3) marks[i] = 1;
  const auto r = refine::split_marked(s, marks, pattern, k, 5, {});
  EXPECT_GT(r.refined, 600u);
  EXPECT_EQ(s.size(), 2000u + 3 * r.refined);
  expect_conserved(before, totals(s), sP, sL);
}

INSTANTIATE_TEST_SUITE_P(Patterns, SplitConservation,
                         ::testing::Values(std::make_tuple(Pattern::aap, 1.0), std::make_tuple(Pattern::rsp, 1.0),
                                           std::make_tuple(Pattern::rsp, 0.5)));

TEST(Refinement, DaughtersGetQuarterMassHalfSmoothingLengthParentVelocityAndDensity) {
  ParticleStore<2> s = random_cloud(50, 3);
  const ParticleStore<2> old = s;
  std::vector<std::uint8_t> marks(s.size(), 0);
  marks.at(10) = 1;
  refine::split_marked(s, marks, Pattern::aap, 1.0, 5, {});
  ASSERT_EQ(s.size(), 53u);
  for (std::size_t a = 10; a < 14; ++a) {
    EXPECT_EQ(s.m[a], old.m[10] / 4);
    EXPECT_EQ(s.h[a], old.h[10] / 2);
    EXPECT_EQ(s.d[a], old.d[10] / 2);
    EXPECT_EQ(s.level[a], old.level[10] + 1);
    EXPECT_EQ(s.v[a], old.v[10]);
    EXPECT_EQ(s.rho[a], old.rho[10]);
    EXPECT_NEAR(std::abs((s.x[a] - old.x[10])[0]), old.d[10] / 4, 1e-15);
    EXPECT_NEAR(std::abs((s.x[a] - old.x[10])[1]), old.d[10] / 4, 1e-15);
  }
  // New ids are fresh and distinct; the others keep theirs and their order.
  std::vector<ParticleId> ids(s.id.values());
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());
  EXPECT_EQ(s.id[9], old.id[9]);
  EXPECT_EQ(s.id[14], old.id[11]);
}

// effects.refinement.daughter_density = "pressure_gradient" (core/refinement/split_pass.hpp). At rest (a = 0) the
// daughters' pressures differ as the hydrostatic field does between their heights, rho g . (x_a - x_b): the density is
// carried along grad rho = rho g / c^2, so the difference is exact but for the equation of state's curvature: the
// Taylor terms p2 (delta_a^2 - delta_b^2) / 2 + p3 (delta_a^3 - delta_b^3) / 6, delta being the change of density and
// p2 = (gamma - 1) c^2 / rho, p3 = (gamma - 1)(gamma - 2) c^2 / rho^2 the second and third derivatives of p(rho). The
// bound is their sum with a tenth more for the next terms (each smaller by |delta| gamma / rho < 1e-3), plus rounding. The family's mean density is the parent's (the offsets sum to zero), and a parent in free fall (a = g:
// no pressure gradient) gives every daughter its own density.
TEST(Refinement, PressureGradientDaughtersCarryTheParentsDensityAlongItsPressureGradient) {
  const TaitEquationOfState eos{1000.0, 99.0, 7.0};
  const Vec<2> g(0.0, -9.81);
  const refine::DaughterDensityIn<2> rule{refine::DaughterDensity::pressure_gradient, g, eos};
  for (const Pattern pattern : {Pattern::aap, Pattern::rsp}) {
    ParticleStore<2> s = random_cloud(50, 3);
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.a[i] = Vec<2>::Zero();
      s.p[i] = eos.pressure(s.rho[i]);
    }
    s.a[20] = g;  // in free fall
    const ParticleStore<2> old = s;
    std::vector<std::uint8_t> marks(s.size(), 0);
    marks[10] = marks[20] = 1;
    refine::split_marked(s, marks, pattern, 1.0, 5, {}, 0.0, false, rule);
    ASSERT_EQ(s.size(), 56u);
    const double rho = old.rho[10];
    double mean = 0.0, highest = 0.0;
    for (std::size_t a = 10; a < 14; ++a) {
      mean += 0.25 * s.rho[a];
      EXPECT_EQ(s.p[a], eos.pressure(s.rho[a]));
      for (std::size_t b = 10; b < 14; ++b) {
        const double da = s.rho[a] - rho, db = s.rho[b] - rho;
        const double c2 = eos.sound_speed_squared(rho), n = eos.gamma - 1.0;
        const double curvature = 0.5 * n * c2 / rho * std::abs(da * da - db * db) +
                                 n * (n - 1.0) * c2 / (6.0 * rho * rho) * std::abs(da * da * da - db * db * db);
        const double hydrostatic = rho * g.dot(s.x[a] - s.x[b]);
        highest = std::max(highest, s.x[a][1] - s.x[b][1]);
        EXPECT_NEAR(s.p[a] - s.p[b], hydrostatic, 1.1 * curvature + 1e-12 * eos.B()) << a << " " << b;
      }
    }
    EXPECT_GT(highest, old.d[10] / 8) << "the pattern spans heights, so the pressures must differ";
    EXPECT_NEAR(mean, rho, 1e-12 * rho);
    for (std::size_t a = 23; a < 27; ++a) {  // the free-falling parent, after the 3 daughters of 10 moved it on
      ASSERT_EQ(refine::parent_id(s.id[a]), old.id[20]);
      EXPECT_EQ(s.rho[a], old.rho[20]);
      EXPECT_EQ(s.rhoh[a], old.rhoh[20]);
    }
  }
}

std::vector<Vec<2>> sorted_positions(const ParticleStore<2>& s) {
  std::vector<Vec<2>> p;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.kind[i] == Kind::fluid) p.push_back(s.x[i]);
  std::sort(p.begin(), p.end(), [](const Vec<2>& a, const Vec<2>& b) {
    const double ya = std::round(a[1] * 1e9), yb = std::round(b[1] * 1e9);
    return ya != yb ? ya < yb : a[0] < b[0];
  });
  return p;
}

ParticleStore<2> lattice_store(double d, int level) {
  ParticleStore<2> s;
  FluidBlockSpec spec;
  spec.spacing = d;
  spec.level = level;
  add_fluid(s, lattice_rectangle(Vec<2>(0, 0), Vec<2>(6.0, 4.0), d), spec, 1000.0);
  return s;
}

TEST(Refinement, AxisAlignedPatternOnALatticeGivesTheNextLattice) {
  for (int level = 0; level < 3; ++level) {
    const double d = 0.5 / std::pow(2.0, level);
    ParticleStore<2> s = lattice_store(d, level);
    std::vector<std::uint8_t> all(s.size(), 1);
    refine::split_marked(s, all, Pattern::aap, 1.0, 10, {});
    const ParticleStore<2> fine = lattice_store(d / 2, level + 1);
    const auto a = sorted_positions(s), b = sorted_positions(fine);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_LE((a[i] - b[i]).norm(), 1e-12) << i;
  }
}

TEST(Refinement, RotatedPatternPicksLargestFAlignsWithItAndScalesWithOneOverF) {
  ParticleStore<2> s;
  s.append(4);
  const double d = 1.0;
  const Vec<2> xi(5.0, 5.0);
  const Vec<2> dirs[3] = {Vec<2>(1, 0), Vec<2>(std::cos(0.4), std::sin(0.4)), Vec<2>(0, -1)};
  const double dist[3] = {1.1, 0.8, 0.95};  // the second is closest: largest F = d / 0.8
  for (std::size_t i = 0; i < 4; ++i) {
    s.x[i] = i == 0 ? xi : Vec<2>(xi + dist[i - 1] * dirs[i - 1]);
    s.d[i] = d;
    s.h[i] = 1.2 * d;
    s.m[i] = 1.0;
    s.rho[i] = 1000;
    s.kind[i] = Kind::fluid;
  }
  const refine::NeighbourQuery q(s);
  const refine::Reference ref = refine::find_reference(s, q, 0);
  ASSERT_TRUE(ref.found);
  EXPECT_NEAR(ref.F, d / 0.8, 1e-14);
  EXPECT_NEAR((ref.direction - dirs[1]).norm(), 0.0, 1e-14);
  for (double k : {0.5, 1.0}) {
    const refine::Offsets o = refine::rotated_scaled_pattern(d, ref, k);
    const double side = k * d / ref.F;
    for (const Vec<2>& a : o) {
      // Each daughter sits s/4 along the reference direction and s/4 across it.
      EXPECT_NEAR(std::abs(a.dot(dirs[1])), side / 4, 1e-14);
      EXPECT_NEAR(std::abs(a.dot(Vec<2>(-dirs[1][1], dirs[1][0]))), side / 4, 1e-14);
    }
  }
}

TEST(Refinement, RotatedPatternWithKOneOnAnUndisturbedLatticeEqualsAxisAligned) {
  const double d = 0.25;
  ParticleStore<2> aap = lattice_store(d, 0);
  ParticleStore<2> rsp = aap;
  // Refine interior particles only (every particle has its four lattice neighbours at distance d).
  std::vector<std::uint8_t> marks(aap.size(), 0);
  for (std::size_t i = 0; i < aap.size(); ++i) {
    const Vec<2>& x = aap.x[i];
    marks[i] = (x[0] > 1.0 && x[0] < 5.0 && x[1] > 1.0 && x[1] < 3.0) ? 1 : 0;
  }
  refine::split_marked(aap, marks, Pattern::aap, 1.0, 1, {});
  refine::split_marked(rsp, marks, Pattern::rsp, 1.0, 1, {});
  const auto a = sorted_positions(aap), b = sorted_positions(rsp);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_LE((a[i] - b[i]).norm(), 1e-12) << i;
}

bool same_state(const ParticleStore<2>& a, const ParticleStore<2>& b) {
  if (a.size() != b.size()) return false;
  bool same = true;
  const_cast<ParticleStore<2>&>(a).for_each_field([&](auto& fa) {
    using F = std::decay_t<decltype(fa)>;
    const_cast<ParticleStore<2>&>(b).for_each_field([&](auto& fb) {
      if constexpr (std::is_same_v<F, std::decay_t<decltype(fb)>>) {
        if (fa.name() == fb.name()) {
          for (std::size_t i = 0; i < fa.size(); ++i)
            if (!(fa[i] == fb[i])) same = false;
        }
      }
    });
  });
  return same;
}

TEST(Refinement, ResultIsBitwiseIndependentOfThreadCountAndOfTheCriterion) {
  const int threads = omp_get_max_threads();
  ParticleStore<2> base = random_cloud(30000, 11);
  // The velocity criterion and the zone criterion, each through make_criterion as the refinement stage builds
  // them, marking exactly the same particles: the velocities are set so that a particle is faster than the
  // threshold exactly when it lies inside the zone (speeds 1..2.5 m/s outside, 3.5..5 m/s inside).
  const Box2 zone{Vec<2>(2.5, 3.0), Vec<2>(6.0, 7.5)};
  for (std::size_t i = 0; i < base.size(); ++i) {
    const double speed = base.v[i].norm();  // 0 .. 5 sqrt(2)
    const double fraction = speed / (5.0 * std::sqrt(2.0));
    const double target = zone.contains(base.x[i]) ? 3.5 + 1.5 * fraction : 1.0 + 1.5 * fraction;
    base.v[i] = speed > 0.0 ? Vec<2>(base.v[i] * (target / speed)) : Vec<2>(target, 0.0);
  }
  refine::RefinementSettings by_speed;
  by_speed.criterion = refine::CriterionKind::velocity;
  by_speed.v_threshold = 3.0;
  refine::RefinementSettings by_zone;
  by_zone.criterion = refine::CriterionKind::zone;
  by_zone.zone = zone;
  std::vector<std::uint8_t> m_speed(base.size(), 0), m_zone(base.size(), 0);
  const auto speed_criterion = refine::make_criterion(by_speed);
  const auto zone_criterion = refine::make_criterion(by_zone);
  ASSERT_STREQ(speed_criterion->name(), "velocity");
  ASSERT_STREQ(zone_criterion->name(), "zone");
  speed_criterion->mark(base, m_speed);
  zone_criterion->mark(base, m_zone);
  const auto marked = static_cast<std::size_t>(std::count(m_zone.begin(), m_zone.end(), 1));
  ASSERT_GT(marked, base.size() / 10);  // the zone holds about a fifth of the cloud
  ASSERT_LT(marked, base.size() / 2);
  ASSERT_EQ(m_speed, m_zone);
  for (Pattern p : {Pattern::aap, Pattern::rsp}) {
    ParticleStore<2> one = base, two = base, other = base;
    omp_set_num_threads(1);
    refine::split_marked(one, m_speed, p, 1.0, 3, {});
    omp_set_num_threads(2);
    refine::split_marked(two, m_speed, p, 1.0, 3, {});
    omp_set_num_threads(4);
    refine::split_marked(other, m_zone, p, 1.0, 3, {});
    EXPECT_TRUE(same_state(one, two));
    EXPECT_TRUE(same_state(one, other));
  }
  omp_set_num_threads(threads);
}

TEST(Refinement, DaughtersNeverLandInsideAWallOrOutsideTheDomain) {
  Geometry2 g;
  g.container = {Vec<2>(0, 0), Vec<2>(10, 10)};
  g.obstacles.push_back({Vec<2>(6, 0), Vec<2>(7, 3)});
  const auto walls = g.walls();
  const double d = 0.5;
  // Parents at the lattice distance (d/2), closer (d/8), very close (d/100), in a corner and at the obstacle.
  const std::vector<Vec<2>> parents = {Vec<2>(5, d / 2),     Vec<2>(5, d / 8),       Vec<2>(5, d / 100),
                                       Vec<2>(d / 8, d / 8), Vec<2>(d / 2, d / 2),  Vec<2>(10 - d / 10, 10 - 0.3),
                                       Vec<2>(6 - d / 8, 1), Vec<2>(6.5, 3 + d / 8), Vec<2>(7 + 0.01, 3 + 0.01)};
  for (const Vec<2>& xi : parents) {
    refine::Offsets o = refine::axis_aligned_pattern(d);
    const double margin = refine::daughter_wall_margin(d);
    ASSERT_EQ(margin, 0.5 * (d / 2)) << "half the daughters' spacing: where their Lennard-Jones wall force begins";
    const bool shifted = refine::keep_inside_walls(xi, o, walls, margin);
    Vec<2> centroid = Vec<2>::Zero();
    for (const Vec<2>& a : o) {
      const Vec<2> x = xi + a;
      EXPECT_TRUE(g.in_fluid_domain(x)) << "parent " << xi.transpose() << " daughter " << x.transpose();
      EXPECT_GE(g.distance_to_walls(x), margin - 1e-12) << "parent " << xi.transpose();
      centroid += a / 4;
    }
    // The centroid stays at x_i unless the parent itself is closer to a wall than the margin.
    if (!shifted) {
      EXPECT_LE(centroid.norm(), 1e-15) << "parent " << xi.transpose();
    }
    // No two daughters collapse onto each other.
    for (std::size_t a = 0; a < 4; ++a)
      for (std::size_t b = a + 1; b < 4; ++b) EXPECT_GT((o[a] - o[b]).norm(), 0.2 * d / 4);
  }
  // At the lattice distance the pattern is untouched.
  refine::Offsets o = refine::axis_aligned_pattern(d);
  EXPECT_FALSE(refine::keep_inside_walls(Vec<2>(5, d / 2), o, walls, 0.25 * d / 2));
  EXPECT_EQ(o, refine::axis_aligned_pattern(d));
}

std::string scientific(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", x);
  return buf;
}

double scaled_end() { return test::short_runs() ? 0.5 : 2.0; }

class DynamicDamBreak : public ::testing::TestWithParam<Pattern> {};

TEST_P(DynamicDamBreak, RunsWithoutNaNRefinesFastParticlesNeverRefinesDaughtersAndConserves) {
  DamBreakSpec spec;
  refine::RefinementSettings r;
  r.pattern = GetParam();
  r.v_threshold = 10.0;
  r.check_interval = 100;
  r.max_level = 1;
  spec.refinement = r;
  Simulation sim = make_dam_break(spec);
  const double T = std::sqrt(spec.column_height / 9.81);
  const Diagnostics start = sim.diagnostics();
  std::size_t last_level1 = 0;
  int passes = 0;
  double largest_pass_change = 0.0;
  while (sim.time() < scaled_end() * T) {
    sim.step();
    const bool check = sim.step_count() % 100 == 0;
    const Diagnostics before = check ? sim.diagnostics() : Diagnostics{};
    sim.run_stages();
    if (!check) continue;
    const Diagnostics after = sim.diagnostics();
    if (after.fluid != before.fluid) {
      ++passes;
      // Diagnostics just before and just after the pass agree to rounding.
      EXPECT_EQ(after.mass, before.mass);
      EXPECT_NEAR(after.kinetic, before.kinetic, 1e-12 * before.kinetic);
      EXPECT_LE((after.momentum - before.momentum).norm(), 1e-12 * start.mass * after.max_speed);
      EXPECT_NEAR(after.angular_momentum, before.angular_momentum, 1e-12 * start.mass * after.max_speed * 60.0);
      // Issue target: a pass changes the total energy (kinetic, potential, elastic) by at most 1e-6 of E(0).
      // Daughters keep v and rho and their centroid is the parent's, so only the wall rule's shift (the
      // centroid moved inward by less than d/8) changes it; that stays far below 1e-6 E(0) unless many
      // parents sit within 3 d / 16 of the floor.
      EXPECT_LE(std::abs(after.total_energy() - before.total_energy()), 1e-6 * start.total_energy())
          << "pass at t = " << sim.time();
      largest_pass_change = std::max(largest_pass_change, std::abs(after.total_energy() - before.total_energy()));
      const std::size_t level1 = after.per_level.size() > 1 ? after.per_level[1] : 0;
      EXPECT_GT(level1, last_level1);
      last_level1 = level1;
    }
  }
  const Diagnostics end = sim.diagnostics();
  RecordProperty("largest_pass_energy_change_over_E0", scientific(largest_pass_change / start.total_energy()));
  EXPECT_GT(passes, 0);
  EXPECT_GT(last_level1, 0u);
  EXPECT_EQ(end.mass, start.mass);
  ASSERT_LE(end.per_level.size(), 2u) << "a daughter was refined with max_level = 1";
  EXPECT_EQ(end.per_level[1] % 4, 0u);
  EXPECT_EQ(end.per_level[0] + end.per_level[1] / 4, 900u);
  const auto& s = sim.store();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    ASSERT_TRUE(std::isfinite(s.x[i][0]) && std::isfinite(s.x[i][1]) && std::isfinite(s.v[i].norm()) &&
                std::isfinite(s.rho[i]))
        << "particle " << s.id[i];
    // No particle left the container or entered a wall.
    EXPECT_TRUE(sim.settings().geometry.in_fluid_domain(s.x[i])) << s.x[i].transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(Patterns, DynamicDamBreak, ::testing::Values(Pattern::aap, Pattern::rsp));

// The case: the dam break with a zone covering only the right-hand corner, where the surge arrives at
// a wall and the wall rule compresses and shifts patterns. Each pass changes the total energy (kinetic,
// potential, elastic) by at most 1e-6 of E(0), measured just before and just after it.
class CornerZoneDamBreak : public ::testing::TestWithParam<Pattern> {};

TEST_P(CornerZoneDamBreak, EachPassChangesTheTotalEnergyByAtMostAMillionthOfItsStart) {
  DamBreakSpec spec;
  refine::RefinementSettings r;
  r.criterion = refine::CriterionKind::zone;
  r.zone = Box2{Vec<2>(44, 0), Vec<2>(50, 6)};
  r.pattern = GetParam();
  r.check_interval = 100;
  spec.refinement = r;
  if (test::short_runs()) spec.spacing = 25.0 / 20.0;  // the sanitizer preset: 400 particles instead of 900
  Simulation sim = make_dam_break(spec);
  const double E0 = sim.diagnostics().total_energy();
  const double end = (test::short_runs() ? 1.6 : 2.5) * std::sqrt(spec.column_height / 9.81);  // past the impact
  int passes = 0;
  double largest = 0.0;
  while (sim.time() < end) {
    sim.step();
    if (sim.step_count() % 100 != 0) {  // passes happen at checks only
      sim.run_stages();
      continue;
    }
    const Diagnostics before = sim.diagnostics();
    sim.run_stages();
    const Diagnostics after = sim.diagnostics();
    if (after.fluid == before.fluid) continue;
    ++passes;
    largest = std::max(largest, std::abs(after.total_energy() - before.total_energy()));
  }
  RecordProperty("largest_pass_energy_change_over_E0", scientific(largest / E0));
  EXPECT_GT(passes, 1);
  EXPECT_LE(largest, 1e-6 * E0);
}

INSTANTIATE_TEST_SUITE_P(Patterns, CornerZoneDamBreak, ::testing::Values(Pattern::aap, Pattern::rsp));

// A particle whose daughters' ids would not fit (the generations of core/refinement/family.hpp used up, as split-merge
// cycles in cell groups can do) is left whole by the stage and counted, while the others split; a split asked for
// directly (split_marked) still refuses with an error.
TEST(Refinement, AParticleWithoutRoomForItsDaughtersIdsStaysWholeAndIsCounted) {
  refine::RefinementSettings rs;
  rs.criterion = refine::CriterionKind::velocity;
  rs.v_threshold = 1.0;
  rs.check_interval = 1;
  rs.max_level = 1;
  TankSpec spec;
  Simulation sim = make_still_tank(spec);
  refine::RefinementStage& stage = refine::add_refinement_stage(sim, rs);
  auto& s = sim.store();
  std::size_t fluid = 0, full = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    s.v[i] = Vec<2>(2.0, 0.0);  // every fluid particle is marked
    // Every fifth: the last generation an id holds (a unique path: the set-up id's, below kMaxRootId).
    if (fluid++ % 5 == 0) {
      s.id[i] = (static_cast<ParticleId>(refine::kMaxGenerations) << refine::kGenerationShift) | s.id[i];
      ++full;
    }
  }
  ASSERT_GT(full, 10u);
  sim.set_clock(0.0, 0, sim.dt());
  sim.run_stages();
  EXPECT_EQ(stage.total_refused(), full);
  EXPECT_EQ(stage.total_refined(), fluid - full);
  ASSERT_EQ(stage.log().size(), 1u);
  EXPECT_EQ(stage.log()[0].refused, full);
  std::size_t whole = 0, daughters = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    if (s.level[i] == 0) {
      ++whole;
      EXPECT_EQ(refine::generation(s.id[i]), refine::kMaxGenerations) << "only the full ids stay whole";
    } else {
      ++daughters;
    }
  }
  EXPECT_EQ(whole, full);
  EXPECT_EQ(daughters, 4 * (fluid - full));
  // At the next check only the full ids are marked (the daughters are at max_level): the pass is logged, but the
  // particles did not change, so the stage asks for no refresh.
  const std::size_t n = s.size();
  sim.set_clock(0.1, 1, sim.dt());
  EXPECT_FALSE(stage.after_step(sim));
  EXPECT_EQ(s.size(), n);
  EXPECT_EQ(stage.total_refused(), 2 * full);
  ASSERT_EQ(stage.log().size(), 2u);
  EXPECT_EQ(stage.log()[1].refined, 0u);
  std::vector<std::uint8_t> marks(s.size(), 0);
  for (std::size_t i = 0; i < s.size(); ++i) marks[i] = s.kind[i] == Kind::fluid && s.level[i] == 0;
  EXPECT_THROW(refine::split_marked(s, marks, Pattern::aap, 1.0, 2, sim.settings().geometry.walls()),
               std::length_error);
}

TEST(Refinement, AnyNumberOfLevelsWorks) {
  ParticleStore<2> s = lattice_store(0.5, 0);
  const std::size_t n0 = s.size();
  for (int level = 0; level < 3; ++level) {
    std::vector<std::uint8_t> all(s.size(), 1);
    const auto r = refine::split_marked(s, all, Pattern::aap, 1.0, 3, {});
    EXPECT_EQ(r.refined, n0 * static_cast<std::size_t>(std::pow(4, level)));
  }
  // max_level = 3 stops a fourth split.
  std::vector<std::uint8_t> all(s.size(), 1);
  EXPECT_EQ(refine::split_marked(s, all, Pattern::aap, 1.0, 3, {}).refined, 0u);
  EXPECT_EQ(s.size(), n0 * 64);
}

}  // namespace
