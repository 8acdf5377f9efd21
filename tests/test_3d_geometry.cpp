// Three dimensions (issue #18), the geometry: the walls of a box container, and ghosts in its corners, on its edges
// and on its faces, with the hydrostatic ghost pressure.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/boundary/ghosts.hpp"
#include "core/boundary/wall.hpp"
#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"
#include "tests/support/physics_helpers.hpp"

namespace {

using sph::Kind;
using Vec3 = sph::Vec<3>;

constexpr double kG = 9.81;  // the ghost pressure's gravity (m/s^2)

sph::Geometry3 unit_box(bool open_top) {
  sph::Geometry3 g;
  g.container = {Vec3(0, 0, 0), Vec3(1, 1, 1)};
  g.open_top = open_top;
  return g;
}

// ---------------------------------------------------------------------------------------------------
// Walls

TEST(Walls3D, BoxFacesPointIntoTheFluid) {
  sph::Geometry3 g = unit_box(true);
  EXPECT_EQ(g.walls().size(), 5u) << "floor and four sides; the top is open";
  g.open_top = false;
  EXPECT_EQ(g.walls().size(), 6u);
  const Vec3 inside(0.3, 0.6, 0.4);
  for (const auto& w : g.walls()) {
    EXPECT_GT(w.signed_distance(inside), 0.0);
    EXPECT_TRUE(w.projects_onto(inside));
    EXPECT_DOUBLE_EQ(w.n.norm(), 1.0);
  }
  g.obstacles.push_back({Vec3(0.4, 0.4, 0.0), Vec3(0.6, 0.6, 0.5)});
  const auto walls = g.walls();
  ASSERT_EQ(walls.size(), 12u);
  const Vec3 centre(0.5, 0.5, 0.25);
  for (std::size_t k = 6; k < walls.size(); ++k) EXPECT_LT(walls[k].signed_distance(centre), 0.0) << "face " << k;
  EXPECT_FALSE(g.in_fluid_domain(centre));
  EXPECT_TRUE(g.in_fluid_domain(inside + Vec3(0, 0, 0.5)));
  EXPECT_FALSE(g.in_fluid_domain(Vec3(0.5, 0.5, -0.01)));
  EXPECT_FALSE(g.in_fluid_domain(Vec3(0.5, 1.01, 0.5)));
  EXPECT_NEAR(g.distance_to_walls(Vec3(0.1, 0.2, 0.3)), 0.1, 1e-15);
  EXPECT_NEAR(g.distance_to_walls(Vec3(0.35, 0.5, 0.25)), 0.05, 1e-15) << "the obstacle's face";
}

TEST(Walls3D, SplashOverTheRimIsToldFromWallPenetration) {
  const sph::Geometry3 g = unit_box(true);
  // Beside the container above the rim: over the top. Below the floor: through a wall.
  EXPECT_TRUE(g.left_through_open_top(Vec3(1.05, 0.5, 1.2), Vec3(1, 0, 0)));
  EXPECT_FALSE(g.left_through_open_top(Vec3(0.5, 0.5, -0.01), Vec3(0, 0, -1)));
  // Beside the container below the rim, having crossed the side plane (y = 1) above the rim on its way down.
  EXPECT_TRUE(g.left_through_open_top(Vec3(0.5, 1.1, 0.95), Vec3(0, 1, -1)));
  // The same place reached through the side wall, moving level.
  EXPECT_FALSE(g.left_through_open_top(Vec3(0.5, 1.1, 0.95), Vec3(0, 1, 0)));
}

// ---------------------------------------------------------------------------------------------------
// Ghosts

/// Every image of x through a subset of the walls {x = 0, y = 0, z = 0} of the unit box: the expected set.
std::vector<Vec3> corner_images(const Vec3& x, const std::vector<int>& axes) {
  std::vector<Vec3> out;
  const int n = static_cast<int>(axes.size());
  for (int mask = 1; mask < (1 << n); ++mask) {
    Vec3 y = x;
    for (int k = 0; k < n; ++k)
      if (mask & (1 << k)) y[axes[static_cast<std::size_t>(k)]] = -y[axes[static_cast<std::size_t>(k)]];
    out.push_back(y);
  }
  return out;
}

bool contains(const std::vector<Vec3>& set, const Vec3& y) {
  return std::any_of(set.begin(), set.end(), [&](const Vec3& z) { return (z - y).norm() < 1e-14; });
}

TEST(Ghosts3D, CornerEdgeAndFaceHaveSevenThreeAndOneImages) {
  const sph::GhostBuilderT<3> gb(unit_box(true).walls(), sph::GhostSlip::free_slip);
  const Vec3 v(0.3, -0.2, 0.5);
  struct Case {
    Vec3 x;
    std::vector<int> axes;  // the walls in reach: x = 0, y = 0, z = 0
  };
  for (const Case& c : {Case{Vec3(0.1, 0.15, 0.05), {0, 1, 2}}, Case{Vec3(0.1, 0.5, 0.05), {0, 2}},
                        Case{Vec3(0.5, 0.5, 0.05), {2}}, Case{Vec3(0.5, 0.5, 0.5), {}}}) {
    const auto im = gb.images(c.x, v, 0.1);  // reach 2 h = 0.2
    const std::vector<Vec3> expected = corner_images(c.x, c.axes);
    ASSERT_EQ(im.count, static_cast<int>(expected.size())) << c.x.transpose();
    for (int k = 0; k < im.count; ++k) {
      const Vec3& y = im.x[static_cast<std::size_t>(k)];
      EXPECT_TRUE(contains(expected, y)) << "image " << y.transpose() << " of " << c.x.transpose();
      // Free slip: each reflected coordinate's velocity component is reversed, the others kept.
      for (int a = 0; a < 3; ++a) {
        const double sign = y[a] == c.x[a] ? 1.0 : -1.0;
        EXPECT_EQ(im.v[static_cast<std::size_t>(k)][a], sign * v[a]);
      }
    }
    // The first images are the single reflections, in wall order (floor first).
    if (im.count == 7) {
      EXPECT_EQ(im.x[0], Vec3(0.1, 0.15, -0.05));
    }
  }
  const sph::GhostBuilderT<3> no_slip(unit_box(true).walls(), sph::GhostSlip::no_slip);
  const auto ns = no_slip.images(Vec3(0.1, 0.15, 0.05), v, 0.1);
  ASSERT_EQ(ns.count, 7);
  for (int k = 0; k < ns.count; ++k) EXPECT_EQ(ns.v[static_cast<std::size_t>(k)], -v);
}

TEST(Ghosts3D, WallsThatDoNotMeetGiveNoCornerImage) {
  // An obstacle standing clear of the floor: its bottom face and the floor are parallel, its side face and the
  // floor perpendicular but apart (the face starts 0.1 above the floor), so a particle near both gets one image
  // from each and none through their "corner".
  sph::Geometry3 g = unit_box(true);
  g.obstacles.push_back({Vec3(0.5, 0.3, 0.1), Vec3(0.7, 0.7, 0.5)});
  const sph::GhostBuilderT<3> gb(g.walls(), sph::GhostSlip::free_slip);
  const Vec3 x(0.45, 0.5, 0.12);  // 0.05 from the obstacle's x-face, 0.12 above the floor
  const auto im = gb.images(x, Vec3::Zero(), 0.1);
  ASSERT_EQ(im.count, 2);
  EXPECT_TRUE(contains({Vec3(0.45, 0.5, -0.12), Vec3(0.55, 0.5, 0.12)}, im.x[0]));
  EXPECT_TRUE(contains({Vec3(0.45, 0.5, -0.12), Vec3(0.55, 0.5, 0.12)}, im.x[1]));
}

TEST(Ghosts3D, HydrostaticGhostPressureAddsTheDepthOfTheImage) {
  const sph::TaitEquationOfState eos{1000.0, 20.0, 7.0};
  const sph::GhostBuilderT<3> gb(unit_box(true).walls(), sph::GhostSlip::free_slip, sph::GhostPressure::hydrostatic,
                                 Vec3(0, 0, -kG), eos);
  sph::ParticleStore<3> s;
  sph::test::ParticleInitT<3> p;
  p.x = Vec3(0.1, 0.15, 0.05);
  p.rho = 1000.5;
  p.h = 0.1;  // reach 0.2: the floor and the walls x = 0, y = 0
  sph::test::add_particle(s, p, eos);
  const double p_source = s.p[0];
  const auto im = gb.images(p.x, p.v, 0.1);
  for (int k = 0; k < im.count; ++k) {
    sph::ParticleStore<3> copy = s;
    auto cv = copy.view();
    gb.make_ghost(cv, 0, k);
    const double dz = im.x[static_cast<std::size_t>(k)][2] - p.x[2];
    EXPECT_NEAR(copy.p[0], p_source + s.rho[0] * (-kG) * dz, 1e-9 * p_source) << "image " << k;
    EXPECT_GT(copy.p[0], p_source - 1e-9 * p_source) << "an image is at or below its source";
    EXPECT_EQ(copy.kind[0], Kind::ghost);
  }
}

}  // namespace
