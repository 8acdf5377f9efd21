#pragma once
// Monaghan's artificial viscosity, eq. (9), in the standard sign convention (it opposes approach):
//   for v_ij . x_ij < 0:  mu_ij = h_ij v_ij.x_ij / (r_ij^2 + 0.01 h_ij^2),
//   Pi_ij = (-alpha c mu_ij + beta mu_ij^2) / rho_bar_ij,   dv_i/dt -= m_j Pi_ij grad_i W.
#include "core/effects/pair.hpp"

namespace sph {

struct ArtificialViscosity {
  // Built from ViscositySettings (core/solver_settings.hpp), where the defaults are declared, and the EOS's c0.
  double alpha;
  double beta;
  double c0;

  template <int D>
  void operator()(const ParticleView<D>& s, const Pair<D>& pr, PairSums<D>& acc) const {
    if (pr.vx >= 0.0) return;  // receding pairs feel no viscosity
    const double mu = pr.mu;
    const double rho_bar = 0.5 * (s.rho[pr.i] + s.rho[pr.j]);
    const double Pi = (-alpha * c0 * mu + beta * mu * mu) / rho_bar;
    acc.a -= (s.m[pr.j] * Pi) * pr.gradW;
  }
};

}  // namespace sph
