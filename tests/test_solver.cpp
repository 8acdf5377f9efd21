// Solver invariants over whole runs: conservation in an isolated cloud, the sign of the viscosity, ghost
// velocities at a wall and in a corner, thread-count independence, and the paper's 900-particle dam break.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "core/case_builder.hpp"
#include "core/effects/artificial_viscosity.hpp"
#include "core/setup.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;

TEST(Solver, IsolatedCloudConservesMomentumAndAngularMomentumOver1000Steps) {
  SolverSettings st = test::isolated_settings(20.0, true);
  st.geometry.container = {Vec<2>(-100, -100), Vec<2>(100, 100)};  // no walls: only the watchdog sees it
  Simulation sim(st);
  FluidBlockSpec spec;
  spec.spacing = 0.1;
  add_fluid(sim.store(), lattice_circle(Vec<2>(1.0, 2.0), 1.0, 0.1), spec, 1000.0);
  // A rotation, a drift and a random perturbation, and densities 1 % off rest, so every force is non-trivial.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto& s = sim.store();
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec<2> r = s.x[i] - Vec<2>(1.0, 2.0);
    s.v[i] = Vec<2>(-r[1], r[0]) * 2.0 + Vec<2>(0.3, -0.2) + 0.2 * Vec<2>(u(rng), u(rng));
    s.rho[i] = 1000.0 * (1.0 + 0.01 * u(rng));
  }
  sim.refresh();
  const double mass0 = test::mass_by_id(s);
  const test::Momenta m0 = test::momenta_by_id(s);
  const test::MomentumScales sc = test::momentum_scales(s);
  for (int k = 0; k < 1000; ++k) sim.step();
  sim.remove_ghosts();
  const test::Momenta m1 = test::momenta_by_id(sim.store());
  EXPECT_EQ(test::mass_by_id(sim.store()), mass0);
  EXPECT_LE((m1.P - m0.P).norm(), 1e-12 * sc.linear);
  EXPECT_LE(std::abs(m1.L - m0.L), 1e-10 * sc.angular);
  EXPECT_TRUE(test::all_finite(sim.store()));
}

TEST(Solver, ViscositySlowsAnApproachingPairAndLeavesARecedingPairAlone) {
  const TaitEquationOfState eos{1000.0, 10.0, 7.0};
  const ArtificialViscosity av{0.5, 0.5, eos.c0};
  for (double sign : {-1.0, 1.0}) {  // -1: approaching, +1: receding
    ParticleStore<2> s;
    test::add_particle(s, {Vec<2>(0, 0), Vec<2>(-sign, 0), 1000.0, 1.0, 1.0, 1.0}, eos);
    test::add_particle(s, {Vec<2>(1, 0), Vec<2>(sign, 0), 1000.0, 1.0, 1.0, 1.0}, eos);
    Pair<2> pr;
    pr.i = 0;
    pr.j = 1;
    pr.xij = s.x[0] - s.x[1];
    pr.r2 = pr.xij.squaredNorm();
    pr.r = std::sqrt(pr.r2);
    pr.hij = 1.0;
    pr.vij = s.v[0] - s.v[1];
    pr.vx = pr.vij.dot(pr.xij);
    pr.mu = pr.hij * pr.vx / (pr.r2 + 0.01);
    pr.gradW = CubicSpline<2>::gradient_factor(pr.r, pr.hij) * pr.xij;
    PairSums<2> acc;
    av(s.view(), pr, acc);
    if (sign < 0) {
      // Particle 0 moves right towards 1: the viscous acceleration points left, against the approach.
      EXPECT_LT(acc.a[0], 0.0);
      EXPECT_LT(acc.a.dot(pr.vij), 0.0);
    } else {
      EXPECT_EQ(acc.a, Vec<2>::Zero());
    }
  }
}

TEST(Solver, GhostVelocitiesAtAWallAndInACorner) {
  const std::vector<Wall2> walls = Geometry2{Box2{Vec<2>(0, 0), Vec<2>(10, 10)}, true, {}}.walls();
  const Vec<2> v(1.0, 2.0);
  const GhostBuilder free_slip(walls, GhostSlip::free_slip), no_slip(walls, GhostSlip::no_slip);
  // Near the bottom only: one ghost, mirrored in y; free-slip keeps vx and reverses vy.
  auto g = free_slip.images(Vec<2>(5, 0.4), v, 1.0);
  ASSERT_EQ(g.count, 1);
  EXPECT_EQ(g.x[0], Vec<2>(5, -0.4));
  EXPECT_EQ(g.v[0], Vec<2>(1.0, -2.0));
  EXPECT_EQ(no_slip.images(Vec<2>(5, 0.4), v, 1.0).v[0], Vec<2>(-1.0, -2.0));
  // In the bottom-left corner: two single ghosts and the doubly reflected one.
  g = free_slip.images(Vec<2>(0.3, 0.4), v, 1.0);
  ASSERT_EQ(g.count, 3);
  EXPECT_EQ(g.x[0], Vec<2>(0.3, -0.4));
  EXPECT_EQ(g.v[0], Vec<2>(1.0, -2.0));
  EXPECT_EQ(g.x[1], Vec<2>(-0.3, 0.4));
  EXPECT_EQ(g.v[1], Vec<2>(-1.0, 2.0));
  EXPECT_EQ(g.x[2], Vec<2>(-0.3, -0.4));
  EXPECT_EQ(g.v[2], Vec<2>(-1.0, -2.0));
  const auto n = no_slip.images(Vec<2>(0.3, 0.4), v, 1.0);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(n.v[static_cast<std::size_t>(k)], -v);
  // Farther than 2h from every wall: no ghost.
  EXPECT_EQ(free_slip.images(Vec<2>(5, 5), v, 1.0).count, 0);
  // The hydrostatic ghost pressure adds rho g times the depth difference.
  TaitEquationOfState eos{1000.0, 20.0, 7.0};
  const GhostBuilder hydro(walls, GhostSlip::free_slip, GhostPressure::hydrostatic, Vec<2>(0, -9.81), eos);
  ParticleStore<2> s;
  test::add_particle(s, {Vec<2>(5, 0.4), v, 1001.0, 1.0, 1.0, 1.0}, eos);
  const double p = s.p[0];
  s.append(1);
  s.gather({0, 0});
  auto view = s.view();
  hydro.make_ghost(view, 1, 0);
  EXPECT_NEAR(s.p[1], p + 1001.0 * 9.81 * 0.8, 1e-9 * p);
  EXPECT_NEAR(s.rho[1], eos.density(s.p[1]), 1e-12);
  EXPECT_EQ(s.kind[1], Kind::ghost);
}

ParticleStore<2> fluid_by_id(Simulation& sim) {
  sim.remove_ghosts();
  ParticleStore<2> out = sim.store();
  std::vector<std::uint32_t> order;
  for (std::size_t i : test::index_by_id(out))
    if (i != static_cast<std::size_t>(-1)) order.push_back(static_cast<std::uint32_t>(i));
  out.gather(order);
  return out;
}

TEST(Solver, SmallDamBreakIsBitwiseIdenticalAtOneAndTwoThreads) {
  const int threads = omp_get_max_threads();
  DamBreakSpec spec;
  spec.column_width = spec.column_height = 10.0;
  spec.tank_width = 20.0;
  spec.spacing = 10.0 / 24.0;
  ParticleStore<2> result[2];
  for (int t = 1; t <= 2; ++t) {
    omp_set_num_threads(t);
    Simulation sim = make_dam_break(spec);
    for (int k = 0; k < 200; ++k) sim.step();
    result[t - 1] = fluid_by_id(sim);
  }
  omp_set_num_threads(threads);
  ASSERT_EQ(result[0].size(), result[1].size());
  std::size_t differing = 0;
  result[0].for_each_field([&](auto& f0) {
    result[1].for_each_field([&](auto& f1) {
      if constexpr (std::is_same_v<std::decay_t<decltype(f0)>, std::decay_t<decltype(f1)>>) {
        if (f0.name() != f1.name()) return;
        for (std::size_t i = 0; i < f0.size(); ++i) differing += (f0[i] == f1[i]) ? 0 : 1;
      }
    });
  });
  EXPECT_EQ(differing, 0u);
}

TEST(Solver, PaperDamBreakRunsOneSecondFrontMovesRightMassExact) {
  Simulation sim = make_dam_break(DamBreakSpec{});
  const double mass0 = test::mass_by_id(sim.store());
  auto front = [&] {
    double f = 0.0;
    for (std::size_t i = 0; i < sim.store().size(); ++i)
      if (sim.store().kind[i] == Kind::fluid) f = std::max(f, sim.store().x[i][0]);
    return f;
  };
  const double front0 = front();
  sim.run_until(1.0);
  EXPECT_EQ(sim.diagnostics().fluid, 900u);
  EXPECT_EQ(test::mass_by_id(sim.store()), mass0);
  EXPECT_TRUE(test::all_finite(sim.store()));
  EXPECT_GT(front(), front0 + 5.0);  // the surge has moved well to the right after 1 s
}

}  // namespace
