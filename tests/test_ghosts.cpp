// Ghost particles (section 2.4) as the solver builds them (Simulation::prepare_neighbours, the step's one
// expansion composed with the cell sort): each fluid particle gets exactly its images (GhostBuilder::images)
// carrying its id, every other field copied; old ghosts are dropped, wall particles left alone, for both slip
// conditions and both ghost-pressure modes. Which images a particle gets: one per wall in reach, one per
// perpendicular pair of those walls that meets at a corner, at most four walls (the nearest).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "core/boundary/ghosts.hpp"
#include "core/setup.hpp"
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

/// Index of each non-ghost particle by id.
std::map<sph::ParticleId, std::size_t> sources_by_id(const ParticleStore<2>& s) {
  std::map<sph::ParticleId, std::size_t> out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::ghost) out[s.id[i]] = i;
  }
  return out;
}

/// The non-ghost particles keyed by id, each as (kind, x, y, vx, vy, rho): the store's particles whatever
/// their order.
using SourceKey = std::tuple<int, double, double, double, double, double>;
std::map<sph::ParticleId, SourceKey> particles_by_id(const ParticleStore<2>& s) {
  std::map<sph::ParticleId, SourceKey> out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::ghost) continue;
    out[s.id[i]] = {static_cast<int>(s.kind[i]), s.x[i][0], s.x[i][1], s.v[i][0], s.v[i][1], s.rho[i]};
  }
  return out;
}

TEST(Ghosts, TheSolverGivesEachFluidParticleItsImagesWithItsFieldsCopied) {
  for (GhostSlip slip : {GhostSlip::free_slip, GhostSlip::no_slip}) {
    SCOPED_TRACE(slip == GhostSlip::free_slip ? "free-slip" : "no-slip");
    const SolverSettings st = box_settings(slip, GhostPressure::mirrored);
    sph::Simulation sim(st);
    add_scene(sim.store(), st.eos);
    const ParticleStore<2> before = sim.store();
    ASSERT_NE(sim.ghosts(), nullptr);
    const GhostBuilder& gb = *sim.ghosts();
    sim.prepare_neighbours();
    const ParticleStore<2>& s = sim.store();
    // Expected counts: interior 0, bottom 1, left 1, right 1, corners 3 each, open top 0; wall particle kept.
    const std::vector<int> expected = {0, 1, 1, 1, 3, 3, 0};
    EXPECT_EQ(particles_by_id(s), particles_by_id(before)) << "the sources are kept as they were";
    const auto source = sources_by_id(s);
    std::size_t ghosts = 0;
    std::map<sph::ParticleId, std::vector<int>> matched;  // per source: how often each image was found
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (s.kind[k] != Kind::ghost) continue;
      ++ghosts;
      ASSERT_TRUE(source.count(s.id[k])) << "a ghost carries its source's id";
      const std::size_t i = source.at(s.id[k]);
      ASSERT_EQ(s.kind[i], Kind::fluid) << "only fluid particles have ghosts";
      EXPECT_EQ(s.m[k], s.m[i]);
      EXPECT_EQ(s.h[k], s.h[i]);
      EXPECT_EQ(s.d[k], s.d[i]);
      EXPECT_EQ(s.level[k], s.level[i]);
      EXPECT_EQ(s.rho[k], s.rho[i]);  // mirrored pressure mode: density and pressure copied
      EXPECT_EQ(s.p[k], s.p[i]);
      EXPECT_EQ(s.a[k], Vec<2>::Zero());
      EXPECT_EQ(s.drho[k], 0.0);
      // A ghost is outside the fluid domain, at one of its source's images with that image's velocity.
      EXPECT_FALSE(st.geometry.in_fluid_domain(s.x[k])) << s.x[k].transpose();
      const auto im = gb.images(s.x[i], s.v[i], s.h[i]);
      auto& seen = matched[s.id[k]];
      seen.resize(static_cast<std::size_t>(im.count), 0);
      int found = -1;
      for (int g = 0; g < im.count; ++g) {
        if (im.x[static_cast<std::size_t>(g)] == s.x[k]) found = g;
      }
      ASSERT_GE(found, 0) << "ghost at " << s.x[k].transpose() << " is no image of its source";
      ++seen[static_cast<std::size_t>(found)];
      EXPECT_EQ(s.v[k], im.v[static_cast<std::size_t>(found)]);
      if (slip == GhostSlip::free_slip) {
        EXPECT_NEAR(s.v[k].norm(), s.v[i].norm(), 1e-12);
      } else {
        EXPECT_EQ(s.v[k], -s.v[i]);
      }
    }
    // Every image of every fluid particle exactly once, and nothing else.
    std::size_t expected_ghosts = 0;
    for (std::size_t src = 0; src < expected.size(); ++src) {
      const int n = expected[src];
      expected_ghosts += static_cast<std::size_t>(n);
      EXPECT_EQ(gb.images(before.x[src], before.v[src], before.h[src]).count, n) << src;
      if (n == 0) {
        EXPECT_FALSE(matched.count(before.id[src])) << src;
        continue;
      }
      EXPECT_EQ(matched[before.id[src]], std::vector<int>(static_cast<std::size_t>(n), 1)) << src;
    }
    EXPECT_EQ(ghosts, expected_ghosts);
    // Rebuilding again drops the old ghosts first: the same particles and the same ghosts.
    const auto ghosts_once = ghosts_by_id(s);
    sim.prepare_neighbours();
    EXPECT_EQ(sim.store().size(), before.size() + expected_ghosts);
    EXPECT_EQ(particles_by_id(sim.store()), particles_by_id(before));
    EXPECT_EQ(ghosts_by_id(sim.store()), ghosts_once);
    // And removing them gives back the original particles.
    sim.remove_ghosts();
    ASSERT_EQ(sim.store().size(), before.size());
    EXPECT_EQ(particles_by_id(sim.store()), particles_by_id(before));
  }
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

/// Expects images `im` to be exactly `x` (positions) and `v` (velocities), in that order.
void expect_images(const GhostBuilder::Images& im, const std::vector<Vec<2>>& x, const std::vector<Vec<2>>& v) {
  ASSERT_EQ(im.count, static_cast<int>(x.size()));
  for (std::size_t g = 0; g < x.size(); ++g) {
    EXPECT_NEAR((im.x[g] - x[g]).norm(), 0.0, 1e-12) << "image " << g << ": " << im.x[g].transpose();
    EXPECT_EQ(im.v[g], v[g]) << "image " << g;
  }
}

// Walls beside an obstacle: a particle in a gap narrower than 4 h between an obstacle standing on the floor and
// the right wall has three walls in reach (the shipped scenes, which have no obstacles, never have more than
// two): an image for each, and a corner image for each perpendicular pair that meets, here the container's
// bottom-right corner and the obstacle's foot.
TEST(Ghosts, EveryWallInReachAndEveryCornerWhereTwoMeetGiveAnImage) {
  SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::mirrored);
  st.geometry.obstacles.push_back({Vec<2>(7, 0), Vec<2>(8.5, 6)});  // gap x in [8.5, 10]
  const GhostBuilder gb(st.geometry.walls(), GhostSlip::free_slip);
  const Vec<2> v(0.7, -0.4);
  // Walls in list order: bottom, right wall, the obstacle's right face; then the corners bottom x right wall
  // and bottom x the obstacle's face (the face ends on the floor); the two vertical walls are parallel.
  expect_images(gb.images(Vec<2>(9.25, 0.4), v, 0.6),
                {Vec<2>(9.25, -0.4), Vec<2>(10.75, 0.4), Vec<2>(7.75, 0.4), Vec<2>(10.75, -0.4), Vec<2>(7.75, -0.4)},
                {Vec<2>(0.7, 0.4), Vec<2>(-0.7, -0.4), Vec<2>(-0.7, -0.4), Vec<2>(-0.7, 0.4), Vec<2>(-0.7, 0.4)});
  // At the obstacle's other foot: the floor, its left face, and the corner where they meet.
  expect_images(gb.images(Vec<2>(6.7, 0.3), v, 0.6), {Vec<2>(6.7, -0.3), Vec<2>(7.3, 0.3), Vec<2>(7.3, -0.3)},
                {Vec<2>(0.7, 0.4), Vec<2>(-0.7, -0.4), Vec<2>(-0.7, 0.4)});
  // Higher up in the gap: the two parallel walls only.
  expect_images(gb.images(Vec<2>(9.25, 3.0), v, 0.6), {Vec<2>(10.75, 3.0), Vec<2>(7.75, 3.0)},
                {Vec<2>(-0.7, -0.4), Vec<2>(-0.7, -0.4)});
}

TEST(Ghosts, PerpendicularWallsThatDoNotMeetGiveNoCornerImage) {
  SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::mirrored);
  st.geometry.obstacles.push_back({Vec<2>(4, 1), Vec<2>(6, 3)});  // clear of the floor by 1 m
  const GhostBuilder gb(st.geometry.walls(), GhostSlip::free_slip);
  // Near the floor and the obstacle's left face, which ends 1 m above the floor: no corner between them.
  expect_images(gb.images(Vec<2>(3.7, 1.1), Vec<2>(0.7, -0.4), 0.6), {Vec<2>(3.7, -1.1), Vec<2>(4.3, 1.1)},
                {Vec<2>(0.7, 0.4), Vec<2>(-0.7, -0.4)});
}

TEST(Ghosts, BeyondFourWallsInReachTheNearestFourAreMirrored) {
  // A pocket among thin obstacles: five walls within 2 h = 1.2 of (4, 0.8): the floor at 0.8, a thin plate's
  // top at 0.3, two obstacles' facing sides at 0.5 each and an obstacle's bottom face at 0.7 above. The floor,
  // farthest, gets no image; none of the perpendicular pairs meet.
  SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::mirrored);
  st.geometry.obstacles = {{Vec<2>(2, 0.3), Vec<2>(6, 0.5)},
                           {Vec<2>(4.5, 0.6), Vec<2>(5, 3)},
                           {Vec<2>(3, 0.6), Vec<2>(3.5, 3)},
                           {Vec<2>(3.6, 1.5), Vec<2>(4.4, 2)}};
  const GhostBuilder gb(st.geometry.walls(), GhostSlip::free_slip);
  const Vec<2> x(4.0, 0.8), v(0.7, -0.4);
  ASSERT_TRUE(st.geometry.in_fluid_domain(x));
  // In wall-list order: the plate's top, the second obstacle's left face, the third's right face, the
  // fourth's bottom face.
  expect_images(gb.images(x, v, 0.6), {Vec<2>(4.0, 0.2), Vec<2>(5.0, 0.8), Vec<2>(3.0, 0.8), Vec<2>(4.0, 2.2)},
                {Vec<2>(0.7, 0.4), Vec<2>(-0.7, -0.4), Vec<2>(-0.7, -0.4), Vec<2>(0.7, 0.4)});
}

// What the rule is for: still water in a 1.5 m gap between an obstacle and the right wall (three particle
// columns at d = 0.5 m, 2 h = 1.2 m) stays still. With images of the first two walls found only (the bottom
// and the right wall), the bottom particle at the obstacle's foot got no image of its face and ran into the
// obstacle at t = 0.86 s.
TEST(Ghosts, StillWaterInAGapBesideAnObstacleStaysStill) {
  const double depth = 5.0, d = 0.5, g = 9.81;
  SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::hydrostatic);
  st.eos.c0 = sph::sound_speed_from_height(10.0, g, depth);
  st.geometry.obstacles.push_back({Vec<2>(6, 0), Vec<2>(8.5, 7)});
  sph::Simulation sim(st);
  sph::FluidBlockSpec block;
  block.spacing = d;
  for (const auto& [lo, hi] : {std::pair{Vec<2>(0, 0), Vec<2>(6, depth)}, std::pair{Vec<2>(8.5, 0), Vec<2>(10, depth)}}) {
    sph::add_fluid(sim.store(), sph::lattice_rectangle(lo, hi, d), block, st.eos.rho0);
  }
  sph::set_hydrostatic(sim.store(), 0, sim.store().size(), depth, g, st.eos);
  sim.refresh();
  const double t_end = 1.0;
  ASSERT_NO_THROW(sim.run_until(t_end));  // the watchdog stops a particle entering the obstacle
  // Still water stays still: no speed beyond a small fraction of the long-wave speed sqrt(g depth).
  EXPECT_LT(sim.diagnostics().max_speed, 0.05 * std::sqrt(g * depth));
  for (std::size_t i = 0; i < sim.store().size(); ++i) {
    if (sim.store().kind[i] == Kind::fluid) {
      EXPECT_TRUE(st.geometry.in_fluid_domain(sim.store().x[i]));
    }
  }
}

TEST(Ghosts, HydrostaticGhostPressureAddsTheWeightOfTheGapBelowTheWall) {
  const SolverSettings st = box_settings(GhostSlip::free_slip, GhostPressure::hydrostatic);
  sph::Simulation sim(st);
  add_scene(sim.store(), st.eos);
  sim.prepare_neighbours();
  const ParticleStore<2>& s = sim.store();
  const auto source = sources_by_id(s);
  std::size_t checked = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (s.kind[k] != Kind::ghost) continue;
    const std::size_t src = source.at(s.id[k]);
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
