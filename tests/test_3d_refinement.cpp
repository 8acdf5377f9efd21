// Three dimensions (issue #18), refinement into eight: the split conserves mass, momenta and kinetic energy, a cube
// lattice becomes the next finer lattice, RSP's cube points an axis at its reference neighbour, split then merge
// gives back the lattice, and a dynamic 3D dam break refines, conserves mass and is thread independent; the peer's
// CaseDambreak runs with its column.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/boundary/wall_particles.hpp"
#include "core/case_builder.hpp"
#include "core/refinement/family.hpp"
#include "core/refinement/merge_pass.hpp"
#include "core/refinement/patterns.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/refinement/split_pass.hpp"
#include "core/setup.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"
#include "tests/support/thread_count.hpp"

namespace {

using sph::Kind;
using sph::Vec;
using sph::test::ThreadCount;
using Vec3 = Vec<3>;

constexpr double kG = 9.81;  // gravity of the dam breaks (m/s^2)

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
  // Both groupings: the eight daughters of one parent are a family, and on a lattice anchored at the container's
  // corner they are also the only particles in their parent's cell (coarsening.groups = cell).
  for (const auto groups : {sph::refine::MergeGroups::family, sph::refine::MergeGroups::cell}) {
    SCOPED_TRACE(groups == sph::refine::MergeGroups::family ? "groups: family" : "groups: cell");
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
    const auto r = sph::refine::merge_families<3>(s, may, sim.settings().geometry, 0.0, {},
                                                  static_cast<std::size_t>(-1), groups);
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
      EXPECT_EQ(d.mass, m0) << "splits give m/8 exactly and the diagnostics' mass is an exact sum";
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

}  // namespace
