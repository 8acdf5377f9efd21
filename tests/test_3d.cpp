// Three dimensions (issue #18): the walls of a box container, ghosts in its corners and edges, and the driver in
// 3D: a still tank stays still and hydrostatic, and a run is bitwise the same at 1 and 2 threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "tests/support/thread_count.hpp"
#include "core/boundary/ghosts.hpp"
#include "core/boundary/wall.hpp"
#include "core/boundary/wall_particles.hpp"
#include "core/case_builder.hpp"
#include "core/io/hdf5_frames.hpp"
#include "core/io/xdmf.hpp"
#include "core/refinement/family.hpp"
#include "core/scene/probes.hpp"
#include "core/refinement/merge_pass.hpp"
#include "core/refinement/patterns.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/refinement/split_pass.hpp"
#include "core/setup.hpp"
#include "tests/support/io_helpers.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using sph::Kind;
using sph::Vec;
using Vec3 = Vec<3>;

constexpr double kG = 9.81;

using sph::test::ThreadCount;

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

// ---------------------------------------------------------------------------------------------------
// The driver in 3D

/// The time average of the fluid's p / hydrostatic in a layer |z - z0| < d, away from the side walls.
struct LayerAverage {
  double z0 = 0.0;
  double sum = 0.0, time = 0.0;
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(const sph::SimulationT<3>& sim, const sph::Tank3Spec& spec, double dt) {
    const auto& s = sim.store();
    double p = 0.0, expected = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.kind[i] != Kind::fluid) continue;
      const Vec3& x = s.x[i];
      if (std::abs(x[2] - z0) >= spec.spacing || x[0] < 0.2 * spec.length || x[0] > 0.8 * spec.length ||
          x[1] < 0.2 * spec.width || x[1] > 0.8 * spec.width)
        continue;
      p += s.p[i];
      expected += sim.settings().eos.rho0 * kG * (spec.depth - x[2]);
    }
    if (!(expected > 0.0)) return;
    const double r = p / expected;
    sum += r * dt;
    time += dt;
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  double ratio() const { return sum / time; }
};

TEST(StillTank3D, StaysStillAndHydrostatic) {
  // 1 x 0.4 m, 0.5 m deep, d = 0.05 m: 1600 particles. Under the sanitizer preset (SPH_TEST_SCALE=short), which
  // looks for memory and undefined-behaviour errors, a 0.4 x 0.2 m tank 0.3 m deep (192 particles).
  sph::Tank3Spec spec;
  if (sph::test::short_runs()) {
    spec.length = 0.4;
    spec.width = 0.2;
    spec.depth = 0.3;
    spec.reference_height = 0.15;
  }
  sph::SimulationT<3> sim = sph::make_still_tank(spec);
  const auto d0 = sim.diagnostics();
  ASSERT_EQ(d0.fluid, sph::test::short_runs() ? 192u : 1600u);
  EXPECT_GT(d0.ghosts, 0u);
  const double mass0 = sph::test::mass_by_id(sim.store());
  // 1 s: about 5 periods of the tank's compression mode (4 H / c0 = 0.2 s, c0 = 22 m/s), the window its second
  // half. (0.1 s under the sanitizer preset.)
  const double t_end = sph::test::short_runs() ? 0.1 : 1.0;
  LayerAverage bottom{0.5 * spec.spacing}, mid{0.5 * spec.depth};
  double max_speed = 0.0;
  while (sim.time() < t_end * (1.0 - 1e-14)) {
    const sph::StepInfo info = sim.step(t_end - sim.time());
    max_speed = std::max(max_speed, sim.diagnostics().max_speed);
    if (sim.time() > 0.5 * t_end) {
      bottom.add(sim, spec, info.dt);
      mid.add(sim, spec, info.dt);
    }
  }
  sim.remove_ghosts();
  const auto d = sim.diagnostics();
  const double wave_speed = std::sqrt(kG * spec.depth);
  const double c0 = sim.settings().eos.c0;
  SCOPED_TRACE(testing::Message() << sim.step_count() << " steps, max |v| " << max_speed << ", bottom p/p_h "
                                  << bottom.ratio() << " [" << bottom.lo << ", " << bottom.hi << "], mid "
                                  << mid.ratio() << " [" << mid.lo << ", " << mid.hi << "], density error "
                                  << d.max_density_error);
  EXPECT_EQ(d.fluid, d0.fluid);
  EXPECT_EQ(sph::test::mass_by_id(sim.store()), mass0);
  EXPECT_TRUE(sph::test::all_finite(sim.store()));
  for (std::size_t i = 0; i < sim.store().size(); ++i)
    EXPECT_TRUE(sim.settings().geometry.in_fluid_domain(sim.store().x[i])) << "particle " << i;
  // Issue #18's bound: the water moves at less than 1 % of its long-wave speed.
  EXPECT_LT(max_speed, 0.01 * wave_speed);
  // The largest density error of still water is the floor's hydrostatic compression g H / c0^2; noise may add
  // at most as much again.
  EXPECT_LT(d.max_density_error, 2.0 * kG * spec.depth / (c0 * c0));
  // Time-averaged layer pressure against hydrostatic: the 2D tank's bound (test_still_tank.cpp, 5 %), whose
  // offset's cause is open; the figures are recorded.
  for (const LayerAverage* avg : {&bottom, &mid}) {
    ASSERT_GT(avg->time, 0.0);
    EXPECT_NEAR(avg->ratio(), 1.0, 0.05) << "layer at z = " << avg->z0;
  }
  const auto& w = sim.work();
  testing::Test::RecordProperty("pairs_per_evaluation", std::to_string(static_cast<double>(w.pairs) / static_cast<double>(w.evaluations[0])));
  testing::Test::RecordProperty("candidates_per_evaluation", std::to_string(static_cast<double>(w.candidates) / static_cast<double>(w.evaluations[0])));
  testing::Test::RecordProperty("bottom_p_over_hydrostatic", std::to_string(bottom.ratio()));
  testing::Test::RecordProperty("mid_p_over_hydrostatic", std::to_string(mid.ratio()));
}

TEST(Determinism3D, SameBitsAtOneAndTwoThreads) {
  sph::Tank3Spec spec;
  spec.length = 0.5;
  spec.width = 0.3;
  spec.depth = 0.3;
  std::vector<sph::ParticleStore<3>> ends;
  for (const int threads : {1, 2}) {
    ThreadCount tc(threads);
    sph::SimulationT<3> sim = sph::make_still_tank(spec);
    // A disturbance, so the run is not trivially at rest: the fluid starts with a swirl.
    auto& s = sim.store();
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.kind[i] == Kind::fluid) s.v[i] = Vec3(-(s.x[i][1] - 0.15), s.x[i][0] - 0.25, 0.0);
    sim.refresh();
    for (int k = 0; k < 40; ++k) sim.step();
    sim.remove_ghosts();
    ends.push_back(sim.store());
  }
  const auto& a = ends[0];
  const auto& b = ends[1];
  ASSERT_EQ(a.size(), b.size());
  const auto ia = sph::test::index_by_id(a), ib = sph::test::index_by_id(b);
  std::size_t moved = 0;
  for (std::size_t id = 0; id < ia.size(); ++id) {
    if (ia[id] == static_cast<std::size_t>(-1)) continue;
    ASSERT_NE(ib[id], static_cast<std::size_t>(-1));
    EXPECT_EQ(a.x[ia[id]], b.x[ib[id]]) << "id " << id;
    EXPECT_EQ(a.v[ia[id]], b.v[ib[id]]) << "id " << id;
    EXPECT_EQ(a.rho[ia[id]], b.rho[ib[id]]) << "id " << id;
    moved += a.v[ia[id]].norm() > 0.01;
  }
  EXPECT_GT(moved, 100u);
}

// ---------------------------------------------------------------------------------------------------
// Refinement into eight

struct Totals {
  double mass = 0.0, kinetic = 0.0;
  Vec3 momentum = Vec3::Zero(), angular = Vec3::Zero();
  double momentum_scale = 0.0, angular_scale = 0.0, kinetic_scale = 0.0;
};

Totals totals(const sph::ParticleStore<3>& s) {
  Totals t;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    t.mass += s.m[i];
    t.kinetic += 0.5 * s.m[i] * s.v[i].squaredNorm();
    t.momentum += s.m[i] * s.v[i];
    t.angular += s.m[i] * s.x[i].cross(s.v[i]);
    t.momentum_scale += s.m[i] * s.v[i].norm();
    t.angular_scale += s.m[i] * s.x[i].norm() * s.v[i].norm();
    t.kinetic_scale += 0.5 * s.m[i] * s.v[i].squaredNorm();
  }
  return t;
}

TEST(Refinement3D, EightSplitConservesMassMomentaAndKineticEnergy) {
  const sph::TaitEquationOfState eos{1000.0, 20.0, 7.0};
  for (const auto pattern : {sph::refine::Pattern::aap, sph::refine::Pattern::rsp}) {
    sph::ParticleStore<3> s = sph::test::random_cloud<3>(400, 4.0, 0.4, eos, 5u, 2.0);
    const Totals before = totals(s);
    std::vector<std::uint8_t> marks(s.size(), 0);
    std::size_t marked = 0;
    for (std::size_t i = 0; i < s.size(); i += 3) marks[i] = 1, ++marked;
    // No walls: conservation is the pattern's (point symmetry about the parent); the wall rule's shift is 2D's.
    const auto r = sph::refine::split_marked<3>(s, marks, pattern, 1.0, 5, {}, 0.0);
    ASSERT_EQ(r.refined, marked);
    ASSERT_EQ(s.size(), 400u + 7u * marked);
    const Totals after = totals(s);
    // Each daughter is m/8 (exact) at x_i + o_a with v_i; the offsets sum to zero, so every total is the
    // parent's up to the rounding of sums over ~10^3 terms: 1e-12 of each total's scale.
    EXPECT_NEAR(after.mass, before.mass, 1e-12 * before.mass);
    EXPECT_LE((after.momentum - before.momentum).norm(), 1e-12 * before.momentum_scale);
    EXPECT_LE((after.angular - before.angular).norm(), 1e-12 * before.angular_scale);
    EXPECT_NEAR(after.kinetic, before.kinetic, 1e-12 * before.kinetic_scale);
    // Families: the eight daughters of one parent share its id as parent and carry sibling indices 0..7.
    std::vector<std::vector<unsigned>> siblings;
    std::vector<sph::ParticleId> parents;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (!sph::refine::has_parent(s.id[i])) continue;
      EXPECT_GE(s.level[i], 1);
      EXPECT_EQ(s.h[i], 1.2 * s.d[i]) << "h and d both halved";
      const sph::ParticleId p = sph::refine::parent_id<3>(s.id[i]);
      const auto it = std::find(parents.begin(), parents.end(), p);
      if (it == parents.end()) {
        parents.push_back(p);
        siblings.push_back({sph::refine::sibling_index<3>(s.id[i])});
      } else {
        siblings[static_cast<std::size_t>(it - parents.begin())].push_back(sph::refine::sibling_index<3>(s.id[i]));
      }
    }
    ASSERT_EQ(parents.size(), marked);
    for (auto& f : siblings) {
      std::sort(f.begin(), f.end());
      EXPECT_EQ(f, (std::vector<unsigned>{0, 1, 2, 3, 4, 5, 6, 7}));
    }
  }
}

TEST(Refinement3D, CubeLatticeBecomesTheNextFinerLattice) {
  sph::Tank3Spec spec;
  spec.length = 0.4;
  spec.width = 0.3;
  spec.depth = 0.2;
  spec.spacing = 0.05;
  sph::SimulationT<3> sim = sph::make_still_tank(spec);
  const double mass = sph::test::mass_by_id(sim.store());
  sim.remove_ghosts();
  const std::size_t n0 = sim.store().size();
  // Away from the walls the wall rule never acts (every daughter is d/4 from its parent, the parents d/2 from
  // the walls), so AAP turns the lattice of spacing d into exactly that of spacing d/2.
  const std::size_t split = sph::refine::refine_all(sim, sph::refine::Pattern::aap, 1.0);
  EXPECT_EQ(split, n0);
  sim.remove_ghosts();
  const auto& s = sim.store();
  ASSERT_EQ(s.size(), 8 * n0);
  auto finer = sph::lattice_box(Vec3(0, 0, 0), Vec3(spec.length, spec.width, spec.depth), 0.5 * spec.spacing);
  ASSERT_EQ(finer.size(), s.size());
  std::vector<Vec3> got;
  for (std::size_t i = 0; i < s.size(); ++i) got.push_back(s.x[i]);
  const auto less = [](const Vec3& a, const Vec3& b) {
    for (int k = 2; k >= 0; --k) {
      if (std::abs(a[k] - b[k]) > 1e-9) return a[k] < b[k];
    }
    return false;
  };
  std::sort(got.begin(), got.end(), less);
  std::sort(finer.begin(), finer.end(), less);
  for (std::size_t k = 0; k < got.size(); ++k) EXPECT_LE((got[k] - finer[k]).norm(), 1e-12) << k;
  double mass_after = 0.0;  // (daughters' ids are not dense: summed in store order)
  for (std::size_t i = 0; i < s.size(); ++i) mass_after += s.m[i];
  EXPECT_NEAR(mass_after, mass, 1e-12 * mass);
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.d[i], 0.5 * spec.spacing);
    EXPECT_EQ(s.level[i], 1);
  }
}

TEST(Refinement3D, RotatedPatternPointsAnAxisAtTheReferenceAndScalesByF) {
  // Two particles of spacing d at distance r < d: F = d / r. RSP's cube has one axis along x_j - x_i and side
  // k d / F; the three axes are orthonormal.
  const sph::TaitEquationOfState eos{1000.0, 20.0, 7.0};
  sph::ParticleStore<3> s;
  sph::test::ParticleInitT<3> p;
  p.d = 0.1;
  p.h = 0.12;
  p.m = 1.0;
  p.x = Vec3(1.0, 1.0, 1.0);
  sph::test::add_particle(s, p, eos);
  const Vec3 dir = Vec3(1.0, 2.0, -0.5).normalized();
  p.x = Vec3(1.0, 1.0, 1.0) + 0.08 * dir;
  sph::test::add_particle(s, p, eos);
  const sph::refine::NeighbourQueryIn<3> query(s);
  const auto ref = sph::refine::find_reference(s, query, 0);
  ASSERT_TRUE(ref.found);
  EXPECT_NEAR(ref.F, 0.1 / 0.08, 1e-12);
  EXPECT_LE((ref.direction - dir).norm(), 1e-12);
  const auto o = sph::refine::rotated_scaled_pattern<3>(0.1, ref, 1.0);
  const double side = 0.1 / ref.F;
  Vec3 sum = Vec3::Zero();
  for (const Vec3& a : o) {
    sum += a;
    EXPECT_NEAR(a.norm(), std::sqrt(3.0) * side / 4.0, 1e-15) << "a corner of the cube of side k d / F";
    EXPECT_NEAR(std::abs(a.dot(dir)), side / 4.0, 1e-15) << "a face normal along the reference direction";
  }
  EXPECT_LE(sum.norm(), 1e-15);
  const auto frame = sph::refine::frame_along(dir);
  EXPECT_NEAR(frame[0].dot(frame[1]), 0.0, 1e-15);
  EXPECT_NEAR(frame[0].dot(frame[2]), 0.0, 1e-15);
  EXPECT_NEAR(frame[1].dot(frame[2]), 0.0, 1e-15);
  EXPECT_NEAR(frame[0].cross(frame[1]).dot(frame[2]), 1.0, 1e-15) << "right-handed";
  // AAP is the frame of the coordinate axes.
  const auto aap = sph::refine::axis_aligned_pattern<3>(0.1);
  for (const Vec3& a : aap)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::abs(a[k]), 0.025, 1e-17);
}

TEST(Refinement3D, SplitThenMergeGivesBackTheLattice) {
  sph::Tank3Spec spec;
  spec.length = 0.4;
  spec.width = 0.3;
  spec.depth = 0.2;
  sph::SimulationT<3> sim = sph::make_still_tank(spec);
  sim.remove_ghosts();
  const sph::ParticleStore<3> before = sim.store();
  sph::refine::refine_all(sim, sph::refine::Pattern::aap, 1.0);
  sim.remove_ghosts();
  auto& s = sim.store();
  ASSERT_EQ(s.size(), 8 * before.size());
  // Perturb nothing: every family sits as the split left it, so every one merges (the lattice's outer layer is
  // d/2 from the walls, where the merge rule allows a particle of spacing d).
  std::vector<std::uint8_t> may(s.size(), 1);
  const auto r = sph::refine::merge_families<3>(s, may, sim.settings().geometry, 0.0);
  EXPECT_EQ(r.merged, before.size());
  EXPECT_EQ(r.kept_off_walls + r.kept_dispersed + r.kept_by_criterion, 0u);
  ASSERT_EQ(s.size(), before.size());
  const auto ia = sph::test::index_by_id(before), ib = sph::test::index_by_id(s);
  for (std::size_t id = 0; id < ia.size(); ++id) {
    if (ia[id] == static_cast<std::size_t>(-1)) continue;
    ASSERT_NE(ib[id], static_cast<std::size_t>(-1)) << "the merged particle takes its parent's id back";
    const std::size_t i = ia[id], j = ib[id];
    // The mass-weighted mean of eight offsets +-d/4 about x: x up to the rounding of those sums.
    EXPECT_LE((s.x[j] - before.x[i]).norm(), 1e-12 * before.x[i].norm()) << id;
    EXPECT_NEAR(s.m[j], before.m[i], 1e-12 * before.m[i]);
    EXPECT_NEAR(s.rho[j], before.rho[i], 1e-12 * before.rho[i]);
    EXPECT_EQ(s.h[j], before.h[i]);
    EXPECT_EQ(s.d[j], before.d[i]);
    EXPECT_EQ(s.level[j], 0);
  }
}

/// A small 3D breaking dam (a 0.2 x 0.3 x 0.3 m column in a 0.6 x 0.3 x 0.5 m open box, d = 0.05 m) with dynamic
/// AAP refinement above 1 m/s and coarsening below 0.5 m/s.
sph::SimulationT<3> small_dam_break(sph::TimeStepping stepping) {
  sph::SolverSettingsT<3> st;
  st.eos.rho0 = 1000.0;
  st.eos.c0 = 10.0 * std::sqrt(2.0 * kG * 0.3);
  st.geometry.container = {Vec3(0, 0, 0), Vec3(0.6, 0.3, 0.5)};
  st.stepping = stepping;
  // As the 2D dam break: Lennard-Jones wall particles (D = 5 g H, at half the finest spacing) beside the ghosts,
  // which alone do not stop a fast fine particle (their repulsion vanishes as it nears its image).
  st.lennard_jones = sph::LennardJonesSettings{5.0 * kG * 0.3, 0.5, 0.0125};
  sph::SimulationT<3> sim(st);
  sph::add_wall_particles(sim.store(), st.geometry.walls(), 0.0125, st.eos.rho0);
  sph::FluidBlockSpecT<3> block;
  block.spacing = 0.05;
  sph::add_fluid(sim.store(), sph::lattice_box(Vec3(0, 0, 0), Vec3(0.2, 0.3, 0.3), 0.05), block, st.eos.rho0);
  sph::set_hydrostatic(sim.store(), 0, sim.store().size(), 0.3, kG, st.eos);
  sim.refresh();
  sph::refine::RefinementSettings rs;
  rs.v_threshold = sph::test::short_runs() ? 0.4 : 1.0;
  rs.check_interval = 10;
  rs.max_level = 1;
  rs.coarsening = sph::refine::CoarseningSettings{0.5, 16, 0.05};
  sph::refine::add_refinement_stage(sim, rs);
  return sim;
}

TEST(Refinement3D, DynamicDamBreakRefinesConservesMassAndIsThreadIndependent) {
  // Under the sanitizer preset (SPH_TEST_SCALE=short), which looks for memory and undefined-behaviour errors,
  // only the steps per level (the harder path) at two threads, to 0.07 s with the split threshold at 0.4 m/s
  // (free fall gives ~0.7 m/s by then); the release suite runs both steppings at 1 and 2 threads to 0.25 s.
  const double t_end = sph::test::short_runs() ? 0.07 : 0.25;
  std::vector<int> thread_counts{2};
  if (!sph::test::short_runs()) thread_counts.insert(thread_counts.begin(), 1);
  std::vector<sph::TimeStepping> steppings{sph::TimeStepping::per_level};
  if (!sph::test::short_runs()) steppings.push_back(sph::TimeStepping::global);
  for (const auto stepping : steppings) {
    std::vector<sph::ParticleStore<3>> ends;
    std::vector<sph::DiagnosticsT<3>> diags;
    for (const int threads : thread_counts) {
      ThreadCount tc(threads);
      sph::SimulationT<3> sim = small_dam_break(stepping);
      const double m0 = sim.diagnostics().mass;
      sim.run_until(t_end);  // the front reaches the far wall (0.6 m) at about t = 0.2 s
      const auto d = sim.diagnostics();
      SCOPED_TRACE(testing::Message() << "threads " << threads << ", per level " << (stepping == sph::TimeStepping::per_level)
                                      << ": " << d.fluid << " fluid, per level " << d.per_level.size());
      EXPECT_EQ(d.mass, m0) << "splits give m/8 exactly and the diagnostics' mass is a compensated sum";
      ASSERT_GE(d.per_level.size(), 2u);
      EXPECT_GT(d.per_level[1], sph::test::short_runs() ? 16u : 100u) << "the fast front is refined";
      sim.remove_ghosts();
      ends.push_back(sim.store());
      diags.push_back(d);
    }
    if (ends.size() < 2) continue;
    ASSERT_EQ(ends[0].size(), ends[1].size());
    for (std::size_t i = 0; i < ends[0].size(); ++i) {
      ASSERT_EQ(ends[0].id[i], ends[1].id[i]) << i;
      EXPECT_EQ(ends[0].x[i], ends[1].x[i]) << i;
      EXPECT_EQ(ends[0].v[i], ends[1].v[i]) << i;
    }
    EXPECT_EQ(diags[0].total_energy(), diags[1].total_energy());
  }
}

TEST(DamBreak3D, PeerCaseRunsWithItsColumn) {
  // DualSPHysics' CaseDambreak geometry at a coarse spacing (0.04 m: 10 x 16 x 7 fluid particles): the set-up is
  // what the peer benchmark times (bench/bench_peer.cpp), and its first 0.1 s run without a failure.
  sph::DamBreak3Spec spec;
  spec.spacing = 0.04;
  sph::SimulationT<3> sim = sph::make_dam_break(spec);
  const auto d0 = sim.diagnostics();
  EXPECT_EQ(d0.fluid, 10u * 16u * 7u);
  EXPECT_GT(d0.walls, 0u);
  EXPECT_EQ(sim.settings().geometry.walls().size(), 5u + 6u) << "the open tank and the column";
  // 0.1 s (0.01 s under the sanitizer preset, SPH_TEST_SCALE=short).
  const double t_end = sph::test::short_runs() ? 0.01 : 0.1;
  sim.run_until(t_end);
  const auto d = sim.diagnostics();
  EXPECT_EQ(d.mass, d0.mass);
  EXPECT_GT(d.max_speed, 2.5 * t_end) << "the column of water is collapsing (free fall gives g t, ~1 m/s at 0.1 s)";
  EXPECT_LT(d.max_density_error, 0.05);
}

// ---------------------------------------------------------------------------------------------------
// Output in 3D

/// A 0.3 x 0.2 m tank, 0.2 m deep (96 particles).
sph::Tank3Spec small_tank() {
  sph::Tank3Spec spec;
  spec.length = 0.3;
  spec.width = 0.2;
  spec.depth = 0.2;
  return spec;
}

TEST(Io3D, FramesAreNByThreeAndXdmfSaysXYZ) {
  sph::test::TempFolder tmp;
  const sph::Tank3Spec spec = small_tank();
  sph::SimulationT<3> sim = sph::make_still_tank(spec);
  for (int k = 0; k < 3; ++k) sim.step();
  const auto& s = sim.store();
  const auto file = tmp.path() / "frame.h5";
  const sph::io::FrameHeader h = sph::io::write_frame(file, "frame_000001", s, sim.time(), sim.step_count(), 1, {});
  const std::size_t fluid = sim.diagnostics().fluid;
  EXPECT_EQ(h.particles, fluid) << "ghosts are left out";
  const sph::io::FrameHeader r = sph::io::read_frame_header(file, "frame_000001");
  EXPECT_EQ(r.fields, sph::io::field_layouts(3));
  const auto pos = std::find_if(r.fields.begin(), r.fields.end(), [](const auto& f) { return f.name == "position"; });
  ASSERT_NE(pos, r.fields.end());
  EXPECT_EQ(pos->components, 3);
  const std::vector<double> x = sph::io::read_frame_field(file, "frame_000001", "position");
  ASSERT_EQ(x.size(), 3 * fluid);
  std::size_t k = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::ghost) continue;
    EXPECT_EQ(Vec3(x[3 * k], x[3 * k + 1], x[3 * k + 2]), s.x[i]);
    ++k;
  }
  const std::string xdmf = sph::io::xdmf_document({{"frame.h5", r}});
  EXPECT_NE(xdmf.find("GeometryType=\"XYZ\""), std::string::npos);
  EXPECT_NE(xdmf.find("Dimensions=\"" + std::to_string(fluid) + " 3\""), std::string::npos);
}

TEST(Io3D, CheckpointResumesBitwiseAndRefusesTheOtherDimension) {
  sph::test::TempFolder tmp;
  const sph::Tank3Spec spec = small_tank();
  sph::SimulationT<3> a = sph::make_still_tank(spec);
  for (int k = 0; k < 5; ++k) a.step();
  a.remove_ghosts();
  sph::io::CheckpointState st;
  st.time = a.time();
  st.step = a.step_count();
  st.dt = a.dt();
  st.next_id = a.store().next_id();
  const auto file = tmp.path() / "checkpoint.h5";
  sph::io::write_checkpoint(file, a.store(), st);
  EXPECT_EQ(sph::io::checkpoint_dimension(file), 3);
  sph::SimulationT<3> b = sph::make_still_tank(spec);
  const auto got = sph::io::read_checkpoint(file, b.store());
  sph::test::expect_bitwise_equal(a.store(), b.store());
  b.set_clock(got.time, got.step, got.dt);
  b.store_restored();
  // Both continue from the same stored state: the rates are in the store, so the next steps agree bitwise.
  a.prepare_neighbours();
  b.prepare_neighbours();
  for (int k = 0; k < 5; ++k) {
    a.step();
    b.step();
  }
  a.remove_ghosts();
  b.remove_ghosts();
  sph::test::expect_bitwise_equal(a.store(), b.store());
  sph::ParticleStore<2> flat;
  EXPECT_THROW(sph::io::read_checkpoint(file, flat), std::runtime_error);
}

TEST(Probes3D, GaugeIsAVerticalLineAndSensorAPointOnAWall) {
  const sph::Tank3Spec spec;  // 0.5 m of water at rest, d = 0.05 m
  const sph::SimulationT<3> sim = sph::make_still_tank(spec);
  const auto& s = sim.store();
  // A lattice column's top edge is the water's depth exactly, anywhere in the tank; outside it the column is dry.
  using H = sph::scene::Horizontal<3>;
  EXPECT_NEAR(sph::scene::water_height<3>(s, H(0.5, 0.2), spec.spacing, 0.0, spec.spacing), spec.depth, 1e-12);
  EXPECT_NEAR(sph::scene::water_height<3>(s, H(0.02, 0.38), spec.spacing, 0.0, spec.spacing), spec.depth, 1e-12);
  EXPECT_EQ(sph::scene::water_height<3>(s, H(1.5, 0.2), spec.spacing, 0.0, spec.spacing), 0.0);
  // A sensor on the side wall x = 0 at mid-depth reads the hydrostatic pressure there: the lattice (and its ghosts
  // beyond the wall, which carry the same pressure) sits symmetrically about the point, so the Shepard
  // interpolation of the linear field p = rho0 g (H - z) is exact but for the weights' volumes m / rho, which vary
  // with depth by g (2 h) / c0^2 = 2.4e-3 across the kernel; the error is at most that share of p's variation
  // across the kernel, rho0 g 2 h = 0.48 of p here: 1.2e-3 of p. The bound is 2e-3.
  const double p = sph::scene::point_pressure<3>(s, Vec3(0.0, 0.2, 0.25));
  EXPECT_NEAR(p, 1000.0 * kG * 0.25, 2e-3 * 1000.0 * kG * 0.25);
}

}  // namespace
