#pragma once
// Monaghan's artificial stress (Monaghan 2000, J. Comput. Phys. 159:290; Gray, Monaghan & Swift 2001), the
// fluid form: a short-range repulsion between particles under tension, which stops the cubic spline's
// pairing (tensile) instability. It is an optional effect, off unless a scene asks for it (docs/METHOD.md).
//   R_i = epsilon |p_i| / rho_i^2 if p_i < 0, else 0;   R_ij = R_i + R_j;
//   f_ij = W(r_ij, h_ij) / W(d_ij, h_ij),  d_ij = (d_i + d_j) / 2 (the pair's mean lattice spacing);
//   dv_i/dt -= m_j R_ij f_ij^n grad_i W(x_ij, h_ij).
// R_ij and f_ij are symmetric and grad W antisymmetric, so the pair forces are equal and opposite.
#include "core/effects/pair.hpp"
#include "core/kernel.hpp"

namespace sph {

struct ArtificialStress {
  // Built from ArtificialStressSettings (core/solver_settings.hpp), where the defaults are declared.
  double epsilon;
  int exponent;

  template <int D>
  void operator()(const ParticleView<D>& s, const Pair<D>& pr, PairSums<D>& acc) const {
    const double rj = s.rho[pr.j];
    const double p_rho2_j = s.p[pr.j] / (rj * rj);
    const double tension = (pr.p_rho2_i < 0.0 ? -pr.p_rho2_i : 0.0) + (p_rho2_j < 0.0 ? -p_rho2_j : 0.0);
    if (tension == 0.0) return;
    const double inv_h = 1.0 / pr.hij;
    const double f = CubicSpline<D>::shape(pr.r * inv_h) /
                     CubicSpline<D>::shape(0.5 * (s.d[pr.i] + s.d[pr.j]) * inv_h);
    double fn = 1.0;
    for (int k = 0; k < exponent; ++k) fn *= f;
    acc.a -= (s.m[pr.j] * epsilon * tension * fn) * pr.gradW;
  }
};

}  // namespace sph
