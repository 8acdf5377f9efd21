#pragma once
// Continuity equation, eq. (5): drho_i/dt = sum_j m_j v_ij . grad_i W(x_ij, h_ij).
#include "core/effects/pair.hpp"

namespace sph {

struct Continuity {
  template <int D>
  void operator()(const ParticleView<D>& s, const Pair<D>& pr, PairSums<D>& acc) const {
    acc.drho += s.m[pr.j] * pr.vij.dot(pr.gradW);
  }
};

}  // namespace sph
