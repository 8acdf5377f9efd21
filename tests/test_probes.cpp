// The probes measure the body of water: isolated splash particles beyond a gap do not move them.
#include <gtest/gtest.h>

#include "core/scene/probes.hpp"
#include "core/setup.hpp"

namespace {

using namespace sph;

ParticleStore<2> block_with_splash(bool splash) {
  ParticleStore<2> s;
  FluidBlockSpec spec;
  spec.spacing = 1.0;
  add_fluid(s, lattice_rectangle(Vec<2>(0, 0), Vec<2>(10, 5), 1.0), spec, 1000.0);
  if (splash) {
    // A droplet 4 spacings ahead of the front, and one 3 spacings above the column at the wall.
    add_fluid(s, {Vec<2>(14.5, 0.5), Vec<2>(0.5, 8.5)}, spec, 1000.0);
  }
  return s;
}

TEST(Probes, SurgeFrontAndWaterHeightIgnoreIsolatedSplashParticles) {
  const double gap = 1.0;  // one spacing of empty space between edges
  for (bool splash : {false, true}) {
    const ParticleStore<2> s = block_with_splash(splash);
    EXPECT_DOUBLE_EQ(scene::surge_front(s, 0.0, gap), 10.0) << "splash " << splash;
    EXPECT_DOUBLE_EQ(scene::water_height(s, 0.0, 1.0, 0.0, gap), 5.0) << "splash " << splash;
  }
}

TEST(Probes, ConnectedParticlesDoMoveTheFront) {
  ParticleStore<2> s = block_with_splash(false);
  FluidBlockSpec spec;
  spec.spacing = 1.0;
  // Empty spaces of exactly one spacing, then half a spacing, between edges: connected.
  add_fluid(s, {Vec<2>(11.5, 0.5), Vec<2>(13.0, 0.5)}, spec, 1000.0);
  EXPECT_DOUBLE_EQ(scene::surge_front(s, 0.0, 1.0), 13.5);
  EXPECT_DOUBLE_EQ(scene::water_height(s, 30.0, 1.0, 0.0, 1.0), 0.0);  // a dry column
}

// The gap is empty space between particle edges, so a droplet of fine particles and one of coarse particles
// at the same distance from the body are treated alike (with centre distances the fine droplet, whose
// centres sit closer to its edge, stayed connected across a wider gap: a refined run and a coarse one then
// disagreed about when a falling drop joins the pool).
TEST(Probes, GapIsMeasuredBetweenEdgesWhateverTheParticleSize) {
  for (double empty : {0.9, 1.2}) {
    for (double d : {1.0, 0.25}) {
      ParticleStore<2> s = block_with_splash(false);  // spacing 1, top edge at y = 5, front edge at x = 10
      FluidBlockSpec spec;
      spec.spacing = d;
      // A droplet of 2 x 2 particles of spacing d above the column at x ~ 0.5 (the probe's band) and one
      // ahead of the front, each with its near edge `empty` away from the body.
      std::vector<Vec<2>> drop;
      for (int a = 0; a < 2; ++a) {
        for (int b = 0; b < 2; ++b) {
          drop.emplace_back(0.5 + (a - 0.5) * d, 5.0 + empty + (b + 0.5) * d);
          drop.emplace_back(10.0 + empty + (a + 0.5) * d, 0.5 + (b - 0.5) * d);
        }
      }
      add_fluid(s, drop, spec, 1000.0);
      const bool joined = empty <= 1.0;
      EXPECT_DOUBLE_EQ(scene::water_height(s, 0.5, 1.0, 0.0, 1.0), joined ? 5.0 + empty + 2 * d : 5.0)
          << "empty " << empty << " d " << d;
      EXPECT_DOUBLE_EQ(scene::surge_front(s, 0.0, 1.0), joined ? 10.0 + empty + 2 * d : 10.0)
          << "empty " << empty << " d " << d;
    }
  }
}

// A wave plunging over an air cavity: a layer at least two gaps thick above the gap counts (the gauge sees
// its crest); a thin layer above a gap (splash) does not, wherever it lies. The surge front still ends at the
// body of water.
TEST(Probes, ColumnTopCountsThickLayersAboveAnAirCavityAndNotSplash) {
  FluidBlockSpec spec;
  spec.spacing = 1.0;
  const double gap = 1.0;
  for (double thickness : {1.0, 2.0, 3.0}) {
    for (bool droplet_between : {false, true}) {
      ParticleStore<2> s = block_with_splash(false);  // top edge at y = 5
      // A layer from y = 9 (4 spacings of air) to 9 + thickness over x in [0, 2].
      std::vector<Vec<2>> layer;
      for (double y = 9.5; y < 9.0 + thickness; y += 1.0) {
        layer.emplace_back(0.5, y);
        layer.emplace_back(1.5, y);
      }
      add_fluid(s, layer, spec, 1000.0);
      // A thin droplet in the cavity, 1.5 spacings of air above and below it, ignored either way.
      if (droplet_between) add_fluid(s, {Vec<2>(0.5, 7.0)}, spec, 1000.0);
      const double expected = thickness >= 2.0 * gap ? 9.0 + thickness : 5.0;
      EXPECT_DOUBLE_EQ(scene::water_height(s, 0.5, 1.0, 0.0, gap), expected)
          << "thickness " << thickness << " droplet " << droplet_between;
    }
  }
  // A thick layer ahead of the front is not part of the body: the front stays at the body's edge.
  ParticleStore<2> s = block_with_splash(false);
  std::vector<Vec<2>> ahead;
  for (double x = 13.5; x < 17.0; x += 1.0) ahead.emplace_back(x, 0.5);
  add_fluid(s, ahead, spec, 1000.0);
  EXPECT_DOUBLE_EQ(scene::surge_front(s, 0.0, gap), 10.0);
}

}  // namespace
