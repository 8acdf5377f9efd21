#pragma once
// Density diffusion ("delta-SPH" of Molteni & Colagrossi 2009, with the hydrostatic correction of Fourtakas
// et al. 2019): an optional effect, off unless a scene asks for it (PHYSICS.md allows it as such). It adds
// to the continuity equation a diffusive term that smooths the high-frequency density (and so pressure)
// noise of weakly-compressible SPH without moving a hydrostatic column:
//   drho_i/dt += 2 delta h_ij c0 sum_j psi_ij (x_ji . grad_i W) / (r_ij^2 + 0.01 h_ij^2) m_j / rho_j,
//   psi_ij = (rho_j - rho_i) - (rho_j^H - rho_i^H),   rho_j^H - rho_i^H = (rho0 / c0^2) g . (x_j - x_i),
// the linearised hydrostatic density difference (the Tait law's, to first order in the density error).
// x_ji . grad_i W >= 0, so density flows from the denser particle to the lighter one. Mass is carried by
// the particles and is untouched.
#include "core/effects/pair.hpp"

namespace sph {

template <int D>
struct DensityDiffusion {
  // Built from DensityDiffusionSettings (core/solver_settings.hpp), where the default is declared.
  double delta;
  double c0;
  Vec<D> hydrostatic = Vec<D>::Zero();  // (rho0 / c0^2) g: the hydrostatic density gradient

  void operator()(const ParticleView<D>& s, const Pair<D>& pr, PairSums<D>& acc) const {
    const double rj = s.rho[pr.j];
    const double psi = (rj - s.rho[pr.i]) + hydrostatic.dot(pr.xij);  // x_j - x_i = -x_ij
    const double xg = -pr.xij.dot(pr.gradW);
    acc.drho += 2.0 * delta * pr.hij * c0 * psi * xg / (pr.r2 + 0.01 * pr.hij * pr.hij) * (s.m[pr.j] / rj);
  }
};

}  // namespace sph
