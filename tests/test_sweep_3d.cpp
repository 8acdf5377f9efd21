// The pair sweep in 3D against its brute-force twin (tests/support/brute_force_sweep.hpp), with every optional
// effect, and at each active bin of a two-bin step.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "tests/support/brute_force_sweep.hpp"

namespace {

using sph::CellGrid;
using sph::Kind;
using sph::ParticleStore;
using sph::Vec;
using namespace sph::test;

// ---------------------------------------------------------------------------------------------------
// The same twin in 3D: a two-level cloud in a 5 m cube (about 40 neighbours a particle), ghost-kind copies, and
// a plane of wall particles at z = 0, with every optional effect and at each active bin of a two-bin step.

sph::SolverSettingsT<3> twin_settings_3d() {
  sph::SolverSettingsT<3> st;
  st.eos.rho0 = 1000.0;
  st.eos.c0 = 25.0;
  st.gravity = Vec<3>(0.0, 0.0, -9.81);
  st.ghosts.reset();
  st.viscosity = sph::ViscositySettings{0.2, 0.5};
  st.lennard_jones = sph::LennardJonesSettings{50.0, 0.5, 0.25};
  return st;
}

ParticleStore<3> twin_cloud_3d(const sph::SolverSettingsT<3>& st, std::uint32_t seed) {
  ParticleStore<3> s = random_cloud<3>(700, 5.0, 0.5, st.eos, seed, 1.5);
  for (std::size_t i = 0; i < s.size(); i += 7) s.kind[i] = Kind::ghost;
  for (std::size_t i = 0; i < s.size(); ++i)  // some fluid within reach of the wall plane's repulsion
    if (s.kind[i] == Kind::fluid && i % 5 == 1) s.x[i][2] = 0.02 + 0.2 * s.d[i] * (static_cast<double>(i % 11) / 11.0);
  for (int kx = 0; kx <= 20; ++kx)
    for (int ky = 0; ky <= 20; ++ky)
      add_particle(s, wall_particle<3>(Vec<3>(0.25 * kx, 0.25 * ky, 0.0), 0.125, st.eos.rho0), st.eos);
  return s;
}

TEST(Sweep, EqualsBruteForceIn3D) {
  for (int effects = 0; effects < 3; ++effects) {
    sph::SolverSettingsT<3> st = twin_settings_3d();
    if (effects >= 1) st.density_diffusion = sph::DensityDiffusionSettings{0.1};
    if (effects >= 2) st.artificial_stress = sph::ArtificialStressSettings{0.2, 4};
    ParticleStore<3> s = twin_cloud_3d(st, 21u + static_cast<std::uint32_t>(effects));
    SCOPED_TRACE(testing::Message() << "effects " << effects);
    expect_matches_brute_force(s, st, "3D");
    // The comparison sees each term: viscosity, the wall repulsion and (when on) diffusion each move many rates.
    sph::SolverSettingsT<3> off = st;
    off.viscosity.reset();
    EXPECT_GT(changed_accelerations(brute_force(s, st), brute_force(s, off)), 100u);
    off = st;
    off.lennard_jones.reset();
    EXPECT_GT(changed_accelerations(brute_force(s, st), brute_force(s, off)), 20u);
    if (st.density_diffusion) {
      off = st;
      off.density_diffusion.reset();
      EXPECT_GT(changed_density_rates(brute_force(s, st), brute_force(s, off)), 100u);
    }
  }
}

TEST(Sweep, TimeBinsEqualBruteForceIn3D) {
  const sph::SolverSettingsT<3> st = twin_settings_3d();
  ParticleStore<3> s = twin_cloud_3d(st, 31u);
  CellGrid<3> grid;
  sph::test::build_level_grid_in_order(s, grid);
  ASSERT_EQ(grid.layer_count(), 2);
  const auto sweep = sph::make_sweep(st);
  for (std::size_t i = 0; i < s.size(); ++i) s.bin[i] = s.next_bin[i] = s.level[i];  // each level in its own bin
  for (const int active : {1, 0}) {
    SCOPED_TRACE(testing::Message() << "active bin " << active);
    sph::Activity act{active, sph::Integrator::kMaxBin};
    const sph::test::DueLists due = sph::test::due_lists(s, act);
    act.due_prefix = due.prefix.data();
    act.due_index = due.index.data();  // the particles that are not due walk the due ones only
    const sph::SweepLimits lim = sweep->run(s.view(), grid, act);
    expect_rates_match_brute_force(s, lim, st, "3D bins", act);
  }
}

}  // namespace
