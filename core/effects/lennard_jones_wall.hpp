#pragma once
// Repulsion of a fixed wall particle j on fluid particle i, eq. (10) (an acceleration):
//   f = D ((r0/r)^12 - (r0/r)^6) x_ij / r^2 for r < r0, with r0 = r0_factor * d^{l_i}.
#include "core/effects/pair.hpp"

namespace sph {

struct LennardJonesWall {
  double strength = 1.0;   // D, m^2/s^2
  double r0_factor = 0.5;  // r0 = r0_factor * d_i

  /// The farthest a wall particle acts on fluid particle i: r0. The sweep skips wall particles beyond it.
  template <int D>
  double reach(const ParticleView<D>& s, std::size_t i) const {
    return r0_factor * s.d[i];
  }

  template <int D>
  void operator()(const ParticleView<D>& s, const Pair<D>& pr, PairSums<D>& acc) const {
    const double r0 = r0_factor * s.d[pr.i];
    if (pr.r >= r0 || pr.r2 <= 0.0) return;
    const double q2 = r0 * r0 / pr.r2;
    const double q6 = q2 * q2 * q2;
    acc.a += (pr.weight * (strength * (q6 * q6 - q6) / pr.r2)) * pr.xij;
  }
};

}  // namespace sph
