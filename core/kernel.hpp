#pragma once
// Cubic-spline kernel (Monaghan & Lattanzio), support radius 2h, q = r/h:
//   W = sigma_D / h^D * { 1 - 1.5 q^2 + 0.75 q^3 (0 <= q < 1); 0.25 (2 - q)^3 (1 <= q < 2); 0 }.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace sph {

template <int D>
struct CubicSpline {
  static_assert(D >= 1 && D <= 3, "kernel defined for D = 1, 2, 3");
  static constexpr double sigma = D == 1 ? 2.0 / 3.0 : (D == 2 ? 10.0 / (7.0 * std::numbers::pi) : 1.0 / std::numbers::pi);

  static double norm(double h) {
    double hd = h;
    for (int k = 1; k < D; ++k) hd *= h;
    return sigma / hd;
  }

  /// The kernel's shape without its normalisation: W(r, h) = norm(h) * shape(r / h).
  static double shape(double q) {
    if (q < 1.0) return 1.0 - 1.5 * q * q + 0.75 * q * q * q;
    if (q < 2.0) {
      const double t = 2.0 - q;
      return 0.25 * t * t * t;
    }
    return 0.0;
  }

  /// W(r, h).
  static double value(double r, double h) { return norm(h) * shape(r / h); }

  /// dW/dr(r, h); the gradient is dW/dr * x_ij / r_ij (zero at r = 0).
  static double derivative(double r, double h) {
    const double q = r / h;
    if (q < 1.0) return norm(h) / h * (-3.0 * q + 2.25 * q * q);
    if (q < 2.0) {
      const double t = 2.0 - q;
      return norm(h) / h * (-0.75 * t * t);
    }
    return 0.0;
  }

  /// (dW/dr) / r, the factor that multiplies x_ij to give grad_i W. Written in q so that the inner branch
  /// needs no division by r; at r = 0 it returns 0 (the gradient there is zero).
  static double gradient_factor(double r, double h) { return gradient_factor_inv(r, 1.0 / h); }

  /// The same with 1/h given (the sweep reuses it across pairs of equal h): no division in the inner core.
  static double gradient_factor_inv(double r, double inv_h) {
    const double q = r * inv_h;
    double c = sigma * inv_h * inv_h;  // sigma / h^(D+2)
    for (int k = 0; k < D; ++k) c *= inv_h;
    if (q < 1.0) return r > 0.0 ? c * (-3.0 + 2.25 * q) : 0.0;
    if (q < 2.0) {
      const double t = 2.0 - q;
      return c * (-0.75 * t * t / q);
    }
    return 0.0;
  }

  /// d^2W/dr^2(r, h). Continuous (the spline is C^2): -3 + 4.5 q and 1.5 (2 - q) meet at q = 1.
  static double second_derivative(double r, double h) {
    const double q = r / h;
    const double c = norm(h) / (h * h);
    if (q < 1.0) return c * (-3.0 + 4.5 * q);
    if (q < 2.0) return c * 1.5 * (2.0 - q);
    return 0.0;
  }

  /// The stiffness S of the alternating-layer shear mode of the square (cubic) lattice under pressure, for h = h_over_d
  /// d. In the mode the layers normal to the last axis (up) move along the first axis by +u and -u in turn: the wave
  /// vector is pi / d along the last axis, so every lattice vector's phase is a multiple of pi and the mode changes no
  /// particle's density (sum_j grad W_ij sin(k.x_ij) = 0): the speed of sound does not resist it, only the way the
  /// pressure term depends on the particles' arrangement. The symmetric pressure term, -sum_j m (p_i / rho_i^2 +
  /// p_j / rho_j^2) grad W_ij, linearised about the lattice at uniform p and rho (m = rho d^D), gives
  ///   u'' = -(2 p / rho) (S / d^2) u,   S = sum over the lattice points n of spacing 1 with n_last odd of 2 d^2W/dx_0^2(n)
  /// (W at h = h_over_d). Where S < 0 the mode grows as exp(t sqrt(-2 S p / rho) / d): under hydrostatic pressure
  /// it grows fastest at the floor, at a rate set by the water's depth and not by c0. S < 0 in 3D for h / d in about
  /// 0.5-0.9, 1.03-1.26, 1.51-1.70, 1.79-2.19 and 2.52-3 (the paper's 1.2 among them), in 2D in 0.5-0.81, 0.95-1.20,
  /// 1.52-2.10 and 2.43-3 (at 1.2 S is +0.002); a refinement pass seeds the mode (docs/METHOD.md, "Three dimensions: a lattice mode").
  static double layer_shear_stiffness(double h_over_d) {
    double sum = 0.0;
    for_each_lattice_point(h_over_d, [&](const int (&idx)[3], double r) {
      if (idx[D - 1] % 2 == 0) return;  // the layers that move with the particle at the origin
      const double e0 = static_cast<double>(idx[0]) / r;  // the first axis' share of the unit vector
      // d^2W/dx_0^2 = W'' e0^2 + (W' / r) (1 - e0^2)
      sum += 2.0 * (second_derivative(r, h_over_d) * e0 * e0 + derivative(r, h_over_d) / r * (1.0 - e0 * e0));
    });
    return sum;
  }

  /// h sum_j d^D |grad W(x_j, h)| over the points x_j != 0 of a square (cubic) lattice of spacing d, for
  /// h = h_over_d d: the kernel-gradient sum a particle on its own lattice sees, in units of 1/h (it does not
  /// depend on d). 2D at h = 1.2 d: 1.964; 3D at h = 1.2 d: 2.651.
  static double lattice_gradient_sum(double h_over_d) {
    double sum = 0.0;
    for_each_lattice_point(h_over_d, [&](const int (&)[3], double r) { sum += std::abs(derivative(r, h_over_d)); });
    return sum * h_over_d;
  }

 private:
  /// f(idx, r) for every point idx != 0 of the square (cubic) lattice of spacing 1 with |idx_k| <= ceil(2 h_over_d) (the
  /// kernel's support at h = h_over_d, and the cube's corners beyond it), r = |idx|; in a fixed order, the first axis
  /// fastest. (idx[k] is 0 for k >= D.)
  template <class F>
  static void for_each_lattice_point(double h_over_d, F&& f) {
    const int n = static_cast<int>(std::ceil(2.0 * h_over_d));
    const int side = 2 * n + 1;
    int count = 1;
    for (int k = 0; k < D; ++k) count *= side;
    for (int c = 0; c < count; ++c) {
      int rest = c;
      int idx[3] = {0, 0, 0};
      double r2 = 0.0;
      for (int k = 0; k < D; ++k) {
        idx[k] = rest % side - n;
        rest /= side;
        r2 += static_cast<double>(idx[k] * idx[k]);
      }
      if (r2 > 0.0) f(idx, std::sqrt(r2));
    }
  }
};

/// CubicSpline<D>::lattice_gradient_sum tabulated for h / d from 0.5 to 4 in steps of 0.01 (every scene's
/// h_factor lies inside), linear in between (its error bound is tested in tests/test_kernel.cpp).
template <int D>
class LatticeGradientSum {
 public:
  static constexpr double kFirst = 0.5;
  static constexpr double kStep = 0.01;

  LatticeGradientSum() {
    for (std::size_t k = 0; k < table_.size(); ++k) {
      table_[k] = CubicSpline<D>::lattice_gradient_sum(kFirst + kStep * static_cast<double>(k));
    }
  }

  double operator()(double h_over_d) const {
    const double t = std::clamp((h_over_d - kFirst) / kStep, 0.0, static_cast<double>(table_.size() - 1) - 1e-9);
    const auto k = static_cast<std::size_t>(t);
    return table_[k] + (t - static_cast<double>(k)) * (table_[k + 1] - table_[k]);
  }

  /// The acoustic time-step limit's length for a particle of smoothing length h, lattice spacing d and density
  /// rho whose neighbours sum grad_mass = sum_j m_j |grad W_ij| (fluid and ghost pairs, with h_ij): h, or
  /// kappa(h / d) rho / grad_mass where that is shorter. The acoustic frequency of a particle scales as
  /// (c / rho) grad_mass; on the particle's own lattice grad_mass = rho kappa / h, so there the length is h
  /// (the classic limit h / c). A neighbourhood stiffer than the lattice (clumped particles, a fine particle
  /// among heavier coarse ones) shortens it in proportion.
  double acoustic_length(double h, double d, double rho, double grad_mass) const {
    if (!(grad_mass > 0.0)) return h;
    return std::min(h, (*this)(h / d) * rho / grad_mass);
  }

 private:
  std::array<double, 351> table_{};
};

}  // namespace sph
