#pragma once
// Pressure term of the momentum equation, eq. (6): dv_i/dt -= m_j (p_i/rho_i^2 + p_j/rho_j^2) grad_i W.
#include "core/effects/pair.hpp"

namespace sph {

struct PressureGradient {
  template <int D>
  void operator()(const ParticleView<D>& s, const Pair<D>& pr, PairSums<D>& acc) const {
    const double rj = s.rho[pr.j];
    const double coef = pr.p_rho2_i + s.p[pr.j] / (rj * rj);
    acc.a -= (s.m[pr.j] * coef) * pr.gradW;
  }
};

}  // namespace sph
