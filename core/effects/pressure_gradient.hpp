#pragma once
// Pressure term of the momentum equation, eq. (6): dv_i/dt -= m_j (p_i/rho_i^2 + p_j/rho_j^2) grad_i W.
//
// Across a level jump (corrected_across_levels, scene key effects.pressure_across_levels = "corrected"):
// a particle with a neighbour of another level within 2 max(h_i, h_j) (the sweep's PairSums::mixed_levels)
// takes the pressure gradient in the difference form with a kernel-gradient correction,
//   grad p_i = M_i^-1 sum_j V_j (p_j - p_i) grad_i W,   M_i = sum_j V_j grad_i W (x_j - x_i)^T,
//   dv_i/dt -= grad p_i / rho_i,
// which is exact for a pressure linear in space (hydrostatics); every other particle keeps the symmetric
// form. The symmetric form's error 2 p_i/rho_i sum_j V_j grad W does not vanish across a jump in h and grows
// with the pressure (docs/METHOD.md, "Still water across a level jump"). The corrected form's pair forces
// are not equal and opposite, so linear momentum is exact only away from level jumps.
#include <Eigen/LU>

#include "core/effects/pair.hpp"
#include "core/particle_store.hpp"

namespace sph {

struct PressureGradient {
  bool corrected_across_levels = false;

  template <int D>
  void operator()(const ParticleView<D>& s, const Pair<D>& pr, PairSums<D>& acc) const {
    const double rj = s.rho[pr.j];
    const double coef = pr.p_rho2_i + s.p[pr.j] / (rj * rj);
    if (!corrected_across_levels) {
      acc.a -= (s.m[pr.j] * coef) * pr.gradW;
      return;
    }
    acc.pressure_symmetric += (s.m[pr.j] * coef) * pr.gradW;
    const double vj = s.m[pr.j] / rj;
    acc.pressure_difference += (vj * (s.p[pr.j] - s.p[pr.i])) * pr.gradW;
    acc.moment -= (vj * pr.gradW) * pr.xij.transpose();  // x_j - x_i = -x_ij
  }

  /// After the neighbour loop of particle i: the pressure acceleration of the chosen form.
  template <int D>
  void finish(const ParticleView<D>& s, std::size_t i, PairSums<D>& acc) const {
    if (!corrected_across_levels) return;
    if (!acc.mixed_levels) {
      acc.a -= acc.pressure_symmetric;
      return;
    }
    // The correction needs a neighbourhood that spans the plane: M = I on a full lattice, det M about 1/2 at a
    // flat free surface; below 1/4 (a splash, a lone particle) the plain difference form is used.
    constexpr double kMinDeterminant = 0.25;
    const double det = acc.moment.determinant();
    const Vec<D> grad_p = det >= kMinDeterminant ? Vec<D>(acc.moment.inverse() * acc.pressure_difference)
                                                  : acc.pressure_difference;
    acc.a -= grad_p / s.rho[i];
  }
};

}  // namespace sph
