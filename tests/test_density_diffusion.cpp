// Density diffusion (delta-SPH with the hydrostatic correction, core/effects/density_diffusion.hpp) through the
// pair sweep: a density bump on a still lattice spreads to its neighbours with antisymmetric fluxes, and a
// hydrostatic column feels none. Its pair terms are also in the sweep's brute-force twin (tests/test_sweep.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "tests/support/physics_helpers.hpp"

namespace {

using sph::ParticleStore;
using sph::SolverSettings;
using sph::Vec;
using namespace sph::test;

/// A still lattice (no velocity) of n x n particles at spacing d, densities given by rho(x).
template <class F>
ParticleStore<2> still_lattice(int n, double d, const SolverSettings& st, F rho) {
  ParticleStore<2> s;
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      ParticleInit p;
      p.x = Vec<2>((a + 0.5) * d, (b + 0.5) * d);
      p.rho = rho(p.x);
      p.m = st.eos.rho0 * d * d;
      p.h = 1.2 * d;
      p.d = d;
      add_particle(s, p, st.eos);
    }
  }
  return s;
}

TEST(DensityDiffusion, SmoothsABumpAndConservesVolumeWeightedDensity) {
  SolverSettings st = isolated_settings(20.0, false);
  st.density_diffusion = sph::DensityDiffusionSettings{0.1};
  const double d = 0.1;
  const Vec<2> centre(1.05, 1.05);  // a particle centre of the 21 x 21 lattice
  ParticleStore<2> s = still_lattice(21, d, st, [&](const Vec<2>& x) {
    return (x - centre).norm() < 1e-9 ? 1010.0 : 1000.0;
  });
  run_sweep(s, st);
  double weighted = 0.0, scale = 0.0;
  std::size_t peak = 0, raised = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    weighted += s.m[i] / s.rho[i] * s.drho[i];
    scale += s.m[i] / s.rho[i] * std::abs(s.drho[i]);
    if ((s.x[i] - centre).norm() < 1e-9) peak = i;
  }
  for (std::size_t i = 0; i < s.size(); ++i) raised += i != peak && s.drho[i] > 0.0;
  EXPECT_LT(s.drho[peak], 0.0);  // the denser particle loses density
  EXPECT_GE(raised, 8u);          // to its neighbours
  ASSERT_GT(scale, 0.0);
  EXPECT_LE(std::abs(weighted), 1e-13 * scale);  // sum_i V_i drho_i = 0: antisymmetric fluxes
  // Without the effect a still lattice has no density rate at all.
  st.density_diffusion.reset();
  run_sweep(s, st);
  for (std::size_t i = 0; i < s.size(); ++i) EXPECT_EQ(s.drho[i], 0.0);
}

TEST(DensityDiffusion, LeavesAHydrostaticColumnAlone) {
  // The hydrostatic correction: a still column whose density follows the linearised hydrostatic law has no
  // diffusive flux (uncorrected, every particle would see rho_j - rho_i != 0).
  SolverSettings st = isolated_settings(20.0, false);
  st.gravity = Vec<2>(0.0, -9.81);
  st.density_diffusion = sph::DensityDiffusionSettings{0.1};
  const double H = 2.0;
  ParticleStore<2> s = still_lattice(20, 0.1, st, [&](const Vec<2>& x) {
    return st.eos.rho0 * (1.0 + 9.81 * (H - x[1]) / (st.eos.c0 * st.eos.c0));
  });
  run_sweep(s, st);
  double largest = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) largest = std::max(largest, std::abs(s.drho[i]));
  EXPECT_LE(largest, 1e-9);
  // The same densities shifted by one row's worth at one particle are not hydrostatic: flux appears.
  s.rho[0] += 1.0;
  run_sweep(s, st);
  double moved = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) moved = std::max(moved, std::abs(s.drho[i]));
  EXPECT_GT(moved, 1.0);
}

}  // namespace
