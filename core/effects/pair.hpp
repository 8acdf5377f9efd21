#pragma once
// The geometry of one interacting pair (i, j), computed once by the sweep and shared by every effect.
#include <cstddef>

#include "core/particle_store.hpp"
#include "core/types.hpp"

namespace sph {

template <int D>
struct Pair {
  std::size_t i = 0, j = 0;
  Vec<D> xij = Vec<D>::Zero();  // x_i - x_j
  Vec<D> vij = Vec<D>::Zero();  // v_i - v_j
  double r2 = 0;   // |x_ij|^2
  double r = 0;    // |x_ij|
  double hij = 0;  // (h_i + h_j) / 2, section 2.3
  double vx = 0;   // v_ij . x_ij
  double mu = 0;   // h_ij v_ij.x_ij / (r_ij^2 + 0.01 h_ij^2), eq. (9) and the time-step limit
  double p_rho2_i = 0;  // p_i / rho_i^2, fixed for particle i
  double weight = 1.0;  // 2^-b_ij, the pair's share of dt0 (core/sweep.hpp); gradW already carries it
  Vec<D> gradW = Vec<D>::Zero();  // weight * grad_i W(x_ij, h_ij)
};

/// The running sums of particle i over its neighbours.
template <int D>
struct PairSums {
  double drho = 0.0;
  Vec<D> a = Vec<D>::Zero();
};

}  // namespace sph
