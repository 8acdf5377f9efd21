// Ghost particles (section 2.4) built on a store: GhostBuilder::rebuild places each fluid particle's
// images right after it, copies every other field, drops old ghosts, leaves wall particles alone, and gives
// the same ghosts (positions, velocities, pressures, densities) as the solver's own step pipeline, for
// both slip conditions and both ghost-pressure modes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <map>
#include <tuple>
#include <vector>

#include "core/boundary/ghosts.hpp"
#include "core/simulation.hpp"
#include "tests/support/physics_helpers.hpp"

namespace {

using sph::GhostBuilder;
using sph::GhostPressure;
using sph::GhostSlip;
using sph::Kind;
using sph::ParticleStore;
using sph::SolverSettings;
using sph::Vec;
using namespace sph::test;

SolverSettings box_settings(GhostSlip slip, GhostPressure pressure) {
  SolverSettings st;
  st.eos.rho0 = 1000.0;
  st.eos.c0 = 30.0;
  st.gravity = Vec<2>(0.0, -9.81);
  st.ghosts = slip;
  st.ghost_pressure = pressure;
  st.geometry.container = {Vec<2>(0, 0), Vec<2>(10, 10)};
  st.geometry.open_top = true;
  return st;
}

/// Interior, bottom, left, right, two corners, an open-top particle near the top, and a wall particle.
void add_scene(ParticleStore<2>& s, const sph::TaitEquationOfState& eos) {
  const std::vector<Vec<2>> xs = {Vec<2>(5.0, 5.0), Vec<2>(5.0, 0.3),  Vec<2>(0.4, 6.0), Vec<2>(9.5, 2.0),
                                  Vec<2>(0.3, 0.6), Vec<2>(9.8, 0.2), Vec<2>(4.0, 9.9)};
  for (std::size_t k = 0; k < xs.size(); ++k) {
    ParticleInit p;
    p.x = xs[k];
    p.v = Vec<2>(0.5 + 0.1 * static_cast<double>(k), -0.3 + 0.05 * static_cast<double>(k));
    p.rho = 1000.0 + 2.0 * static_cast<double>(k);
    p.m = 0.36;
    p.h = 0.6;
    p.d = 0.6;
    p.level = static_cast<int>(k % 2);
    add_particle(s, p, eos);
  }
  ParticleInit w;
  w.x = Vec<2>(3.0, 0.0);
  w.m = 0.0;
  w.h = 0.0;
  w.d = 0.3;
  w.kind = Kind::wall;
  add_particle(s, w, eos);
}

/// The ghosts of a store keyed by source id, each as (x, y, vx, vy, p, rho), sorted.
using GhostKey = std::tuple<double, double, double, double, double, double>;
std::map<sph::ParticleId, std::vector<GhostKey>> ghosts_by_id(const ParticleStore<2>& s) {
  std::map<sph::ParticleId, std::vector<GhostKey>> out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::ghost) continue;
    out[s.id[i]].emplace_back(s.x[i][0], s.x[i][1], s.v[i][0], s.v[i][1], s.p[i], s.rho[i]);
  }
  for (auto& [id, g] : out) std::sort(g.begin(), g.end());
  return out;
}

TEST(Ghosts, RebuildPlacesImagesAfterTheirSourceAndCopiesTheirFields) {
  const SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::mirrored);
  ParticleStore<2> s;
  add_scene(s, st.eos);
  const ParticleStore<2> before = s;
  const GhostBuilder gb(st.geometry.walls(), GhostSlip::free_slip);
  gb.rebuild(s);
  // Expected counts: interior 0, bottom 1, left 1, right 1, corners 3 each, open top 0; wall particle kept.
  const std::vector<int> expected = {0, 1, 1, 1, 3, 3, 0};
  std::size_t k = 0;
  for (std::size_t src = 0; src < before.size(); ++src) {
    ASSERT_LT(k, s.size());
    EXPECT_EQ(s.id[k], before.id[src]);
    EXPECT_EQ(s.kind[k], before.kind[src]);
    EXPECT_EQ(s.x[k], before.x[src]);
    const std::size_t source = k++;
    if (before.kind[src] != Kind::fluid) continue;
    const int n = expected[src];
    EXPECT_EQ(gb.images(before.x[src], before.v[src], before.h[src]).count, n) << src;
    for (int g = 0; g < n; ++g, ++k) {
      ASSERT_LT(k, s.size());
      EXPECT_EQ(s.kind[k], Kind::ghost);
      EXPECT_EQ(s.id[k], s.id[source]);
      EXPECT_EQ(s.m[k], s.m[source]);
      EXPECT_EQ(s.h[k], s.h[source]);
      EXPECT_EQ(s.d[k], s.d[source]);
      EXPECT_EQ(s.level[k], s.level[source]);
      EXPECT_EQ(s.rho[k], s.rho[source]);  // mirrored pressure mode: density and pressure copied
      EXPECT_EQ(s.p[k], s.p[source]);
      EXPECT_EQ(s.a[k], Vec<2>::Zero());
      EXPECT_EQ(s.drho[k], 0.0);
      // A ghost is outside the fluid domain, at the source's image, with |v| kept (free-slip).
      EXPECT_FALSE(st.geometry.in_fluid_domain(s.x[k])) << s.x[k].transpose();
      const auto im = gb.images(before.x[src], before.v[src], before.h[src]);
      EXPECT_EQ(s.x[k], im.x[static_cast<std::size_t>(g)]);
      EXPECT_EQ(s.v[k], im.v[static_cast<std::size_t>(g)]);
      EXPECT_NEAR(s.v[k].norm(), s.v[source].norm(), 1e-12);
    }
  }
  EXPECT_EQ(k, s.size());
  // Rebuilding again drops the old ghosts first: the result is the same store.
  const ParticleStore<2> once = s;
  gb.rebuild(s);
  ASSERT_EQ(s.size(), once.size());
  EXPECT_EQ(s.x.values(), once.x.values());
  EXPECT_EQ(s.v.values(), once.v.values());
  EXPECT_EQ(s.kind.values(), once.kind.values());
  // And removing them gives back the original particles.
  GhostBuilder::remove(s);
  ASSERT_EQ(s.size(), before.size());
  EXPECT_EQ(s.x.values(), before.x.values());
  EXPECT_EQ(s.id.values(), before.id.values());
}

TEST(Ghosts, CornerImagesForFreeSlipAndNoSlip) {
  const SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::mirrored);
  const Vec<2> x(9.8, 0.2), v(0.7, -0.4);  // bottom-right corner
  const auto fs = GhostBuilder(st.geometry.walls(), GhostSlip::free_slip).images(x, v, 0.6);
  const auto ns = GhostBuilder(st.geometry.walls(), GhostSlip::no_slip).images(x, v, 0.6);
  ASSERT_EQ(fs.count, 3);
  ASSERT_EQ(ns.count, 3);
  // Walls in order bottom, right: the bottom image, the right image, then the doubly reflected one.
  EXPECT_NEAR((fs.x[0] - Vec<2>(9.8, -0.2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((fs.x[1] - Vec<2>(10.2, 0.2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((fs.x[2] - Vec<2>(10.2, -0.2)).norm(), 0.0, 1e-12);
  EXPECT_EQ(fs.v[0], Vec<2>(0.7, 0.4));    // normal (y) part reversed
  EXPECT_EQ(fs.v[1], Vec<2>(-0.7, -0.4));  // normal (x) part reversed
  EXPECT_EQ(fs.v[2], Vec<2>(-0.7, 0.4));   // both
  for (int g = 0; g < 3; ++g) {
    EXPECT_EQ(ns.x[static_cast<std::size_t>(g)], fs.x[static_cast<std::size_t>(g)]);
    EXPECT_EQ(ns.v[static_cast<std::size_t>(g)], -v);
  }
}

TEST(Ghosts, ReachIsTwiceTheSmoothingLengthAndTheTopIsOpenUnlessClosed) {
  SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::mirrored);
  const Vec<2> v(1.0, 0.0);
  const GhostBuilder open(st.geometry.walls(), GhostSlip::free_slip);
  EXPECT_EQ(open.images(Vec<2>(5.0, 1.2), v, 0.6).count, 0);       // distance == 2h: outside the support
  EXPECT_EQ(open.images(Vec<2>(5.0, 1.1999), v, 0.6).count, 1);
  EXPECT_EQ(open.images(Vec<2>(5.0, 9.9), v, 0.6).count, 0);       // open top: no wall there
  EXPECT_EQ(open.images(Vec<2>(0.2, 10.5), v, 0.6).count, 0);      // above the side wall's end
  EXPECT_EQ(open.images(Vec<2>(5.0, -0.1), v, 0.6).count, 0);      // behind the wall
  st.geometry.open_top = false;
  const GhostBuilder closed(st.geometry.walls(), GhostSlip::free_slip);
  const auto im = closed.images(Vec<2>(5.0, 9.9), v, 0.6);
  ASSERT_EQ(im.count, 1);
  EXPECT_NEAR((im.x[0] - Vec<2>(5.0, 10.1)).norm(), 0.0, 1e-12);
  // An obstacle: a particle above its top face gets a ghost inside it.
  st.geometry.obstacles.push_back({Vec<2>(4, 0), Vec<2>(6, 3)});
  const GhostBuilder obstacle(st.geometry.walls(), GhostSlip::free_slip);
  const auto ob = obstacle.images(Vec<2>(5.0, 3.4), Vec<2>(0.5, -1.0), 0.6);
  ASSERT_EQ(ob.count, 1);
  EXPECT_NEAR((ob.x[0] - Vec<2>(5.0, 2.6)).norm(), 0.0, 1e-12);
  EXPECT_EQ(ob.v[0], Vec<2>(0.5, 1.0));
}

// The store-level rebuild and the solver's step pipeline (which composes the ghost expansion with the
// cell sort) must produce the same ghosts, whatever the slip condition and the ghost-pressure mode.
TEST(Ghosts, RebuildGivesTheSolversGhosts) {
  for (GhostSlip slip : {GhostSlip::free_slip, GhostSlip::no_slip}) {
    for (GhostPressure pressure : {GhostPressure::mirrored, GhostPressure::hydrostatic}) {
      const SolverSettings st = box_settings(slip, pressure);
      sph::Simulation sim(st);
      add_scene(sim.store(), st.eos);
      ParticleStore<2> store = sim.store();
      sim.refresh();
      ASSERT_NE(sim.ghosts(), nullptr);
      sim.ghosts()->rebuild(store);
      const auto expected = ghosts_by_id(sim.store());
      const auto got = ghosts_by_id(store);
      EXPECT_EQ(got.size(), 5u);
      EXPECT_EQ(got, expected) << "slip " << static_cast<int>(slip) << ", pressure " << static_cast<int>(pressure);
    }
  }
}

TEST(Ghosts, HydrostaticGhostPressureAddsTheWeightOfTheGapBelowTheWall) {
  const SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::hydrostatic);
  ParticleStore<2> s;
  add_scene(s, st.eos);
  const ParticleStore<2> before = s;
  const GhostBuilder gb(st.geometry.walls(), GhostSlip::free_slip, GhostPressure::hydrostatic, *st.gravity, st.eos);
  gb.rebuild(s);
  std::size_t checked = 0;
  for (std::size_t k = 1; k < s.size(); ++k) {
    if (s.kind[k] != Kind::ghost) continue;
    std::size_t src = k;
    while (s.kind[src] == Kind::ghost) --src;  // the source precedes its ghosts
    const double dy = s.x[k][1] - s.x[src][1];  // g . (x_ghost - x_i) = -9.81 dy
    EXPECT_NEAR(s.p[k], s.p[src] - s.rho[src] * 9.81 * dy, 1e-9 * std::abs(s.p[src]) + 1e-9);
    EXPECT_NEAR(s.rho[k], st.eos.density(s.p[k]), 1e-9);
    if (dy == 0.0) {
      EXPECT_EQ(s.p[k], s.p[src]);  // side walls: gravity along the wall, pressure mirrored
    }
    ++checked;
  }
  EXPECT_EQ(checked, 9u);
}

}  // namespace
