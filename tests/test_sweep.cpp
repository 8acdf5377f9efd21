// The pair sweep: pair forces are antisymmetric with mixed smoothing lengths (section 2.3), and the
// sweep equals an independent O(N^2) evaluation of eqs. (5), (6), (9) and (10), with and without the
// optional artificial stress (Monaghan 2000) and density diffusion (delta-SPH), on grids the tests build and
// on the solver's own (a refined dam break with wall particles and ghosts, as Simulation::refresh leaves it).
// With time bins (each active bin, rebin, the jerk, the single-rate loop against the binned one):
// tests/test_sweep_bins.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <random>
#include <vector>

#include "core/boundary/ghosts.hpp"
#include "core/integrator.hpp"
#include "core/kernel.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "core/sweep_factory.hpp"
#include "tests/support/brute_force.hpp"
#include "tests/support/brute_force_sweep.hpp"
#include "tests/support/physics_helpers.hpp"

namespace {

using sph::Kind;
using sph::CellGrid;
using sph::ParticleStore;
using sph::SolverSettings;
using sph::Vec;
using namespace sph::test;

double cross(const Vec<2>& a, const Vec<2>& b) { return a[0] * b[1] - a[1] * b[0]; }

// ---------------------------------------------------------------------------------------------------
// (a) Antisymmetry: the force of j on i is minus that of i on j, with h_i != h_j.

TEST(Sweep, TwoParticlesWithDifferentSmoothingLengthsFeelOppositeForces) {
  for (bool viscosity : {false, true}) {
    SolverSettings st = isolated_settings(20.0, viscosity);
    if (st.viscosity) *st.viscosity = {0.3, 0.7};
    ParticleStore<2> s;
    ParticleInit a, b;
    a.x = Vec<2>(0.0, 0.0);
    a.v = Vec<2>(0.4, 0.1);
    a.rho = 1004.0;
    a.m = 0.25;
    a.h = 0.6;
    a.d = 0.5;
    a.level = 1;
    b.x = Vec<2>(0.7, 0.3);
    b.v = Vec<2>(-0.3, 0.2);  // approaching: v_ab . x_ab < 0
    b.rho = 995.0;
    b.m = 1.0;
    b.h = 1.2;
    b.d = 1.0;
    add_particle(s, a, st.eos);
    add_particle(s, b, st.eos);
    ASSERT_LT((a.v - b.v).dot(a.x - b.x), 0.0);
    run_sweep(s, st);
    const Vec<2> fa = s.m[0] * s.a[0], fb = s.m[1] * s.a[1];
    ASSERT_GT(fa.norm(), 0.0);
    EXPECT_LE((fa + fb).norm(), 1e-14 * fa.norm()) << "viscosity " << viscosity;
    // Central: along the line of centres.
    EXPECT_LE(std::abs(cross(fa, s.x[0] - s.x[1])), 1e-14 * fa.norm() * (s.x[0] - s.x[1]).norm());
  }
}

TEST(Sweep, InteractionRangeIsTwiceTheMeanSmoothingLength) {
  // h_a = 0.5, h_b = 1.5: h_ab = 1.0, so the pair interacts for r < 2.0 even though r > 2 h_a, and from
  // both sides (gather on either particle sees the other).
  const SolverSettings st = isolated_settings(10.0, false);
  for (double r : {1.2, 1.9, 2.05}) {
    ParticleStore<2> s;
    ParticleInit a, b;
    a.h = 0.5;
    a.rho = 1010.0;
    b.h = 1.5;
    b.x = Vec<2>(r, 0.0);
    b.rho = 1010.0;
    add_particle(s, a, st.eos);
    add_particle(s, b, st.eos);
    run_sweep(s, st);
    if (r < 2.0) {
      EXPECT_GT(s.a[0].norm(), 0.0) << r;
      EXPECT_GT(s.a[1].norm(), 0.0) << r;
      EXPECT_LE((s.m[0] * s.a[0] + s.m[1] * s.a[1]).norm(), 1e-14 * s.a[0].norm()) << r;
    } else {
      EXPECT_EQ(s.a[0].norm(), 0.0) << r;
      EXPECT_EQ(s.a[1].norm(), 0.0) << r;
    }
  }
}

TEST(Sweep, MixedLevelCloudHasZeroNetForceAndTorque) {
  for (int variant = 0; variant < 3; ++variant) {
    const bool viscosity = variant > 0;
    SolverSettings st = isolated_settings(15.0, viscosity);
    if (st.viscosity) *st.viscosity = {0.5, 1.0};
    if (variant == 2) st.artificial_stress = sph::ArtificialStressSettings{0.3, 4};
    ParticleStore<2> s = random_cloud(800, 10.0, 0.5, st.eos, 12345u, 2.0);
    run_sweep(s, st);
    Vec<2> net = Vec<2>::Zero();
    double torque = 0.0, scale = 0.0, torque_scale = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Vec<2> f = s.m[i] * s.a[i];
      net += f;
      torque += cross(s.x[i], f);
      scale += f.norm();
      torque_scale += s.x[i].norm() * f.norm();
    }
    ASSERT_GT(scale, 0.0);
    EXPECT_LE(net.norm(), 1e-13 * scale) << "viscosity " << viscosity;
    EXPECT_LE(std::abs(torque), 1e-13 * torque_scale) << "viscosity " << viscosity;
  }
}

// (b) Brute-force twin: tests/support/brute_force_sweep.hpp (eqs. (5), (6), (9), (10) over all pairs); the 3D
// twins are tests/test_sweep_3d.cpp.

TEST(Sweep, EqualsBruteForceWithoutViscosity) {
  const SolverSettings st = twin_settings(false, false);
  ParticleStore<2> s = twin_cloud(st, 7u);
  expect_matches_brute_force(s, st, "no viscosity");
}

TEST(Sweep, EqualsBruteForceWithViscosity) {
  const SolverSettings st = twin_settings(true, false);
  ParticleStore<2> s = twin_cloud(st, 8u);
  expect_matches_brute_force(s, st, "viscosity");
  // The comparison is sensitive to the viscous term: it changes many accelerations far beyond tolerance.
  EXPECT_GT(changed_accelerations(brute_force(s, st), brute_force(s, twin_settings(false, false))), 100u);
}

// The extrapolated predictor's acoustic length (AcousticLimit) against the twin where it binds. Its bound,
// 0.5 rho / (0.61 C sum m |grad W|), is shorter than h for a neighbourhood more than 0.5 / (0.61 C kappa) times as
// stiff as the lattice: 2.09 at C = 0.2, which the twin cloud may never reach, 0.42 at C = 1, which every particle
// passes. The comparison is sharp: the limit at C = 1 is shorter than at C = 0.2 (both before the Courant number).
TEST(Sweep, ExtrapolatedAcousticLimitEqualsBruteForceWhereItBinds) {
  SolverSettings st = twin_settings(true, false);
  ASSERT_EQ(st.predictor, sph::TimePredictor::extrapolated);
  st.cfl = 1.0;
  ParticleStore<2> s = twin_cloud(st, 9u);
  expect_matches_brute_force(s, st, "extrapolated acoustic limit, C = 1");
  SolverSettings lattice_c = st;
  lattice_c.cfl = 0.2;
  EXPECT_LT(brute_force(s, st).dt_cfl, brute_force(s, lattice_c).dt_cfl);
}

TEST(Sweep, EqualsBruteForceWithLennardJonesWalls) {
  for (bool viscosity : {false, true}) {
    const SolverSettings st = twin_settings(viscosity, true);
    ParticleStore<2> s = twin_cloud(st, 9u);
    // Some fluid particles close to the wall row so that eq. (10) acts (r0 = d_i / 2).
    std::size_t near = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.kind[i] == Kind::fluid && i % 5 == 1) {
        s.x[i][1] = 0.02 + 0.2 * s.d[i] * (static_cast<double>(i % 11) / 11.0);
        ++near;
      }
    }
    ASSERT_GT(near, 20u);
    expect_matches_brute_force(s, st, viscosity ? "lj+viscosity" : "lj");
    SolverSettings no_lj = st;
    no_lj.lennard_jones.reset();
    const Reference with = brute_force(s, st), without = brute_force(s, no_lj);
    std::size_t repelled = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
      if (with.a[i][1] - without.a[i][1] > 1e-6 * with.a_scale[i]) ++repelled;  // pushed up, away from y = 0
    EXPECT_GT(repelled, 20u);
  }
}

TEST(Sweep, EqualsBruteForceWithArtificialStress) {
  for (bool viscosity : {false, true}) {
    SolverSettings st = twin_settings(viscosity, true);
    st.artificial_stress = sph::ArtificialStressSettings{0.2, 4};
    ParticleStore<2> s = twin_cloud(st, 11u);
    std::size_t tension = 0;
    for (std::size_t i = 0; i < s.size(); ++i) tension += s.kind[i] == Kind::fluid && s.p[i] < 0.0;
    ASSERT_GT(tension, 100u);  // the cloud's densities straddle rho0
    expect_matches_brute_force(s, st, viscosity ? "stress+viscosity+lj" : "stress+lj");
    SolverSettings off = st;
    off.artificial_stress.reset();
    EXPECT_GT(changed_accelerations(brute_force(s, st), brute_force(s, off)), 100u);
  }
}

TEST(Sweep, EqualsBruteForceWithDensityDiffusion) {
  for (bool stress : {false, true}) {
    SolverSettings st = twin_settings(true, true);
    st.density_diffusion = sph::DensityDiffusionSettings{0.1};
    if (stress) st.artificial_stress = sph::ArtificialStressSettings{0.2, 4};
    ParticleStore<2> s = twin_cloud(st, 13u);
    expect_matches_brute_force(s, st, stress ? "diffusion+stress" : "diffusion");
    SolverSettings off = st;
    off.density_diffusion.reset();
    EXPECT_GT(changed_density_rates(brute_force(s, st), brute_force(s, off)), 100u);
  }
}

/// The store's particles without its ghosts, in its order, then the images `gb` gives each fluid particle, each
/// made a ghost as the solver makes them: the brute force's own set of ghosts for the solver's rates.
ParticleStore<2> with_images(const ParticleStore<2>& s, const sph::GhostBuilder& gb) {
  std::vector<std::uint32_t> src;
  std::vector<int> image;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::ghost) continue;
    src.push_back(static_cast<std::uint32_t>(i));
    image.push_back(-1);
  }
  const std::size_t sources = src.size();
  for (std::size_t k = 0; k < sources; ++k) {
    const std::size_t i = src[k];
    if (s.kind[i] != Kind::fluid) continue;
    const int count = gb.images(s.x[i], s.v[i], s.h[i]).count;
    for (int g = 0; g < count; ++g) {
      src.push_back(static_cast<std::uint32_t>(i));
      image.push_back(g);
    }
  }
  ParticleStore<2> out = s;
  out.gather(src);
  auto view = out.view();
  for (std::size_t k = sources; k < src.size(); ++k) gb.make_ghost(view, k, image[k]);
  return out;
}

// The twin on the solver's own path: the store, ghosts, grid and rates exactly as Simulation::refresh() leaves
// them (the cell size and query reach that prepare_neighbours computes, the driver's ghost expansion), in a
// dam break with Lennard-Jones wall particles, free-slip ghost walls and a statically refined quarter (level-1
// particles next to level-0 ones and next to walls), set in motion. The twins above choose their own grid.
TEST(Sweep, SolverPathEqualsBruteForceInARefinedDamBreakWithWallsAndGhosts) {
  const std::filesystem::path cases = std::filesystem::path(__FILE__).parent_path().parent_path() / "cases";
  for (bool more_effects : {false, true}) {
    SCOPED_TRACE(more_effects ? "with density diffusion and artificial stress" : "dam_break.json's effects");
    sph::scene::Json doc = sph::scene::read_json_file(cases / "dam_break.json");
    // The acoustic limit's two rules (AcousticLimit): the last-rate predictor's with the effects of the scene.
    if (!more_effects) doc["time"]["predictor"] = "last_rate";
    doc["effects"]["static_refinement"] = sph::scene::Json{{"box", {{"lo", {0, 0}}, {"hi", {12.5, 12.5}}}}};
    if (more_effects) {
      doc["effects"]["density_diffusion"] = sph::scene::Json{{"delta", 0.1}};
      doc["effects"]["artificial_stress"] = sph::scene::Json{{"epsilon", 0.2}};
    }
    sph::Simulation sim = sph::scene::build_simulation(sph::scene::scene_from_json(doc));
    // At rest every velocity is zero and continuity and viscosity vanish: 200 steps (t ~ 0.1 s) set the
    // column moving (the front at about 1 m/s).
    for (int k = 0; k < 200; ++k) sim.step();
    sim.refresh();
    const ParticleStore<2>& s = sim.store();
    const SolverSettings& st = sim.settings();
    ASSERT_TRUE(st.lennard_jones && st.ghosts && st.viscosity);
    std::size_t kinds[3] = {0, 0, 0}, levels[2] = {0, 0};
    for (std::size_t i = 0; i < s.size(); ++i) {
      ++kinds[static_cast<int>(s.kind[i])];
      if (s.kind[i] == Kind::fluid) ++levels[s.level[i] == 0 ? 0 : 1];
    }
    ASSERT_GT(kinds[static_cast<int>(Kind::wall)], 100u);
    ASSERT_GT(kinds[static_cast<int>(Kind::ghost)], 100u);
    ASSERT_GT(levels[0], 100u);
    ASSERT_GT(levels[1], 100u);
    // The neighbour sets of the solver's grid are the brute force's, and they include mixed-level pairs.
    const auto expected = brute_force_neighbours(s.x.values(), s.h.values());
    std::size_t mixed = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.kind[i] != Kind::fluid) continue;
      std::vector<std::uint32_t> got;
      sim.grid().for_each_neighbour(i, s.x.data(), s.h.data(), [&](std::uint32_t j, double) { got.push_back(j); });
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, expected[i]) << "neighbours of " << i << " at " << s.x[i].transpose();
      for (std::uint32_t j : got) mixed += s.kind[j] == Kind::fluid && s.level[j] != s.level[i];
    }
    EXPECT_GT(mixed, 100u);
    expect_rates_match_brute_force(s, sim.last_limits(), st, "solver path");
    // The comparison is sharp: the flow is under way, so viscosity alone moves many accelerations.
    SolverSettings inviscid = st;
    inviscid.viscosity.reset();
    EXPECT_GT(changed_accelerations(brute_force(s, st), brute_force(s, inviscid)), 100u);
  }
}

// The solver's ghosts are every image a pair reaches. A coarse particle by a wall interacts with a fine one within
// h_c + h_f, and so with the fine particle's image while the two distances to the wall add up to less than that:
// the fine particle needs an image up to h_f + h_c from the wall, beyond its own support 2 h_f. On the set-up's
// lattice no such pair occurs (a coarse particle's nearest fine neighbour across the jump sits 1.5 d_f aside), so
// the dam break's refined corner is jittered by a quarter of each particle's spacing. Against a brute force that
// mirrors every fluid particle across every wall, whatever its distance (the kernel's support is then the only
// cut), the solver's rates and pair count are the same.
TEST(Sweep, SolverGhostsAreEveryImageThatACoarseParticleByAWallReaches) {
  const std::filesystem::path cases = std::filesystem::path(__FILE__).parent_path().parent_path() / "cases";
  sph::scene::Json doc = sph::scene::read_json_file(cases / "dam_break.json");
  doc["effects"]["static_refinement"] = sph::scene::Json{{"box", {{"lo", {0, 0}}, {"hi", {12.5, 12.5}}}}};
  sph::Simulation sim = sph::scene::build_simulation(sph::scene::scene_from_json(doc));
  sim.remove_ghosts();
  ParticleStore<2>& js = sim.store();
  std::mt19937 rng(7u);
  std::uniform_real_distribution<double> u(-0.25, 0.25);
  const SolverSettings& st = sim.settings();
  for (std::size_t i = 0; i < js.size(); ++i) {
    if (js.kind[i] != Kind::fluid) continue;
    const Vec<2> moved = js.x[i] + js.d[i] * Vec<2>(u(rng), u(rng));
    if (st.geometry.in_fluid_domain(moved)) js.x[i] = moved;
  }
  sim.refresh();
  const ParticleStore<2>& s = sim.store();
  ASSERT_TRUE(st.ghosts.has_value());
  // The solver's ghosts (as Simulation builds them) with a reach of each particle's images of h_i + largest_h.
  const auto builder = [&](double largest_h) {
    sph::GhostBuilder gb(st.geometry.walls(), *st.ghosts, st.ghost_pressure, st.gravity.value_or(Vec<2>::Zero()),
                         st.eos);
    gb.set_largest_h(largest_h);
    return gb;
  };
  const ParticleStore<2> full = with_images(s, builder(1e3));  // every wall the particle projects onto
  expect_rates_match_brute_force(full, sim.last_limits(), st, "every image");
  // Sharp: with images of each particle within 2 h_i only, as the ghosts were until 2026-12-03, a pair goes missing
  // and a coarse particle by the floor moves by far more than the twin's tolerance (1e-12 of its terms' sum).
  const auto with_all = brute_force(full, st);
  const auto near_only = brute_force(with_images(s, builder(0.0)), st);  // the same sources first, fewer ghosts
  EXPECT_GT(with_all.pairs, near_only.pairs);
  std::size_t moved = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (full.kind[i] != Kind::fluid) continue;
    if ((with_all.a[i] - near_only.a[i]).norm() <= 1e-10 * with_all.a_scale[i]) continue;
    ++moved;
    EXPECT_EQ(full.level[i], 0) << "only a coarse particle reaches beyond a fine one's 2 h_f";
  }
  EXPECT_GT(moved, 0u);
}

TEST(Sweep, ArtificialStressActsOnlyUnderTension) {
  SolverSettings st = twin_settings(true, true);
  ParticleStore<2> s = twin_cloud(st, 12u);
  for (std::size_t i = 0; i < s.size(); ++i) {  // every particle at or above rho0: no negative pressure
    s.rho[i] = st.eos.rho0 * (1.0 + 0.01 * static_cast<double>(i % 7) / 7.0);
    s.p[i] = st.eos.pressure(s.rho[i]);
  }
  CellGrid<2> grid;
  build_grid(s, grid);
  sph::make_sweep(st)->run(s.view(), grid);
  const std::vector<Vec<2>> a_off = s.a.values();
  st.artificial_stress = sph::ArtificialStressSettings{0.2, 4};
  const auto sweep = sph::make_sweep(st);
  EXPECT_STREQ(sweep->name(), "continuity+pressure+viscosity+artificial_stress|lj");
  sweep->run(s.view(), grid);
  EXPECT_EQ(a_off, s.a.values());
}

TEST(Sweep, ArtificialStressPushesApartAPairThatTensionPullsTogether) {
  // Two equal particles below rho0 (p < 0): the pressure term attracts them at every distance. With the
  // artificial stress the pair repels at short range (eps f^n > 1, f = W(r)/W(d)) and still attracts at
  // the lattice spacing (f = 1, eps < 1), so a stretched lattice is not pushed apart.
  const double d = 0.5;
  for (double r_over_d : {0.3, 1.0}) {
    double along[2];
    for (int with = 0; with < 2; ++with) {
      SolverSettings st = isolated_settings(20.0, false);
      if (with) st.artificial_stress = sph::ArtificialStressSettings{0.2, 4};
      ParticleStore<2> s;
      ParticleInit a, b;
      a.rho = b.rho = 990.0;
      a.m = b.m = 1000.0 * d * d;
      a.h = b.h = 1.2 * d;
      a.d = b.d = d;
      b.x = Vec<2>(r_over_d * d, 0.0);
      add_particle(s, a, st.eos);
      add_particle(s, b, st.eos);
      ASSERT_LT(s.p[0], 0.0);
      run_sweep(s, st);
      const std::size_t ia = s.x[0][0] < s.x[1][0] ? 0 : 1, ib = 1 - ia;
      along[with] = s.a[ia].dot(s.x[ia] - s.x[ib]);  // > 0: pushed away from the other
    }
    EXPECT_LT(along[0], 0.0) << r_over_d;
    if (r_over_d < 0.5) {
      EXPECT_GT(along[1], 0.0) << r_over_d;
    } else {
      EXPECT_LT(along[1], 0.0) << r_over_d;
      EXPECT_GT(along[1], along[0]) << r_over_d;
    }
  }
}

TEST(Sweep, RepeatedSweepIsBitwiseIdentical) {
  const SolverSettings st = twin_settings(true, true);
  ParticleStore<2> s = twin_cloud(st, 10u);
  CellGrid<2> grid;
  build_grid(s, grid);
  const auto sweep = sph::make_sweep(st);
  sweep->run(s.view(), grid);
  const std::vector<Vec<2>> a1 = s.a.values();
  const std::vector<double> d1 = s.drho.values();
  sweep->run(s.view(), grid);
  EXPECT_EQ(a1, s.a.values());
  EXPECT_EQ(d1, s.drho.values());
}

}  // namespace
