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
  const double gap = 2.0;
  for (bool splash : {false, true}) {
    const ParticleStore<2> s = block_with_splash(splash);
    EXPECT_DOUBLE_EQ(scene::surge_front(s, 0.0, gap), 10.0) << "splash " << splash;
    EXPECT_DOUBLE_EQ(scene::water_height(s, 0.0, 1.0, 0.0, gap), 5.0) << "splash " << splash;
  }
}

TEST(Probes, ConnectedParticlesDoMoveTheFront) {
  ParticleStore<2> s = block_with_splash(false);
  FluidBlockSpec spec;
  add_fluid(s, {Vec<2>(11.5, 0.5), Vec<2>(13.0, 0.5)}, spec, 1000.0);  // gaps of 1.5 spacings: connected
  EXPECT_DOUBLE_EQ(scene::surge_front(s, 0.0, 2.0), 13.5);
  EXPECT_DOUBLE_EQ(scene::water_height(s, 30.0, 1.0, 0.0, 2.0), 0.0);  // a dry column
}

}  // namespace
