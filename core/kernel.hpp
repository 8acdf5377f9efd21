#pragma once
// Cubic-spline kernel (Monaghan & Lattanzio), support radius 2h, q = r/h:
//   W = sigma_D / h^D * { 1 - 1.5 q^2 + 0.75 q^3 (0 <= q < 1); 0.25 (2 - q)^3 (1 <= q < 2); 0 }.
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
};

}  // namespace sph
