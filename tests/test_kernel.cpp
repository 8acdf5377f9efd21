#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/kernel.hpp"

namespace {

using sph::CubicSpline;

// Midpoint-rule integral of W over its support in polar (2D) or spherical (3D) shells.
template <int D>
double radial_integral(double h, int n) {
  const double R = 2.0 * h;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double r = (k + 0.5) * R / n;
    const double shell = D == 2 ? 2.0 * std::numbers::pi * r : 4.0 * std::numbers::pi * r * r;
    sum += CubicSpline<D>::value(r, h) * shell * (R / n);
  }
  return sum;
}

TEST(Kernel, IntegratesToOneIn2D) { EXPECT_NEAR(radial_integral<2>(0.7, 200000), 1.0, 1e-6); }
TEST(Kernel, IntegratesToOneIn3D) { EXPECT_NEAR(radial_integral<3>(1.3, 200000), 1.0, 1e-6); }

TEST(Kernel, IntegratesToOneOnACartesianGrid2D) {
  // Independent of the radial reduction: a plain 2D Riemann sum over [-2h, 2h]^2.
  const double h = 1.0, step = 4.0 * h / 2000;
  double sum = 0.0;
  for (int i = 0; i < 2000; ++i)
    for (int j = 0; j < 2000; ++j) {
      const double x = -2 * h + (i + 0.5) * step, y = -2 * h + (j + 0.5) * step;
      sum += CubicSpline<2>::value(std::hypot(x, y), h) * step * step;
    }
  EXPECT_NEAR(sum, 1.0, 1e-6);
}

template <int D>
void check_derivative(double h) {
  for (double r = 0.05 * h; r < 2.0 * h; r += 0.0937 * h) {
    if (std::abs(r - h) < 1e-3 * h) continue;  // piecewise join
    const double eps = 1e-6 * h;
    const double fd = (CubicSpline<D>::value(r + eps, h) - CubicSpline<D>::value(r - eps, h)) / (2 * eps);
    EXPECT_NEAR(CubicSpline<D>::derivative(r, h), fd, 1e-6 * std::abs(CubicSpline<D>::norm(h) / h) + 1e-9)
        << "r/h = " << r / h;
  }
}

TEST(Kernel, GradientEqualsFiniteDifference) {
  check_derivative<2>(0.8);
  check_derivative<3>(1.7);
}

TEST(Kernel, GradientFactorTimesRIsTheDerivative) {
  // The sweep's fast form (written in q, no division by r inside the core) against dW/dr / r.
  for (double h : {0.4, 1.0, 3.0})
    for (double r = 0.013 * h; r < 2.1 * h; r += 0.0517 * h) {
      const double ref = CubicSpline<2>::derivative(r, h) / r;
      EXPECT_NEAR(CubicSpline<2>::gradient_factor(r, h), ref, 1e-13 * std::abs(CubicSpline<2>::norm(h)) / (h * h));
      const double ref3 = CubicSpline<3>::derivative(r, h) / r;
      EXPECT_NEAR(CubicSpline<3>::gradient_factor(r, h), ref3, 1e-13 * std::abs(CubicSpline<3>::norm(h)) / (h * h));
    }
}

// The lattice gradient sum kappa(h / d) = h sum_j d^D |grad W(x_j)| is a Riemann sum of h integral |grad W| dV
// (= integral over the unit-h support of |dW/dq| in shells), taken here by the midpoint rule in q.
template <int D>
double gradient_integral() {
  const int n = 400000;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double q = (k + 0.5) * 2.0 / n;
    const double shell = D == 2 ? 2.0 * std::numbers::pi * q : 4.0 * std::numbers::pi * q * q;
    sum += std::abs(CubicSpline<D>::derivative(q, 1.0)) * shell * (2.0 / n);
  }
  return sum;
}

TEST(Kernel, LatticeGradientSumTendsToTheIntegralOnFineLattices) {
  // A lattice sum of a function with a kink (q = 1) and a cusp at the origin, which the sum leaves out: its error
  // is O((d / h)^2) of the integral, (1/8)^2 = 1.6 % at h = 8 d; hence 2 %.
  EXPECT_NEAR(CubicSpline<2>::lattice_gradient_sum(8.0) / gradient_integral<2>(), 1.0, 0.02);
  EXPECT_NEAR(CubicSpline<3>::lattice_gradient_sum(8.0) / gradient_integral<3>(), 1.0, 0.02);
}

TEST(Kernel, LatticeGradientSumAtThePapersSpacing) {
  // h = 1.2 d: the neighbours at distance 1 (4), sqrt 2 (4), 2 (4) and sqrt 5 (8) in 2D, summed here by hand.
  const double h = 1.2;
  double by_hand = 0.0;
  for (const auto& [r, count] : {std::pair{1.0, 4}, {std::sqrt(2.0), 4}, {2.0, 4}, {std::sqrt(5.0), 8}}) {
    by_hand += count * std::abs(CubicSpline<2>::derivative(r, h));
  }
  EXPECT_NEAR(CubicSpline<2>::lattice_gradient_sum(h), by_hand * h, 1e-14 * by_hand * h);
  EXPECT_NEAR(CubicSpline<2>::lattice_gradient_sum(h), 1.9641, 1e-4);  // the value docs/METHOD.md quotes
}

template <int D>
void check_table() {
  // Linear interpolation between nodes dx apart errs by at most dx^2 / 8 max |kappa''| over the interval. The
  // second derivative is bounded here from second differences of the sum itself on a grid 20x finer (kappa is
  // piecewise smooth: a shell entering the support at q = 2 does so with zero value and slope).
  const sph::LatticeGradientSum<D> t;
  const double dx = sph::LatticeGradientSum<D>::kStep, e = dx / 20.0;
  for (double hd = 0.6; hd < 3.9; hd += 0.0137) {
    const double lo = sph::LatticeGradientSum<D>::kFirst + dx * std::floor((hd - sph::LatticeGradientSum<D>::kFirst) / dx);
    double curvature = 0.0;
    for (double y = lo; y <= lo + dx + 1e-12; y += e) {
      const double k2 = (CubicSpline<D>::lattice_gradient_sum(y + e) - 2.0 * CubicSpline<D>::lattice_gradient_sum(y) +
                         CubicSpline<D>::lattice_gradient_sum(y - e)) / (e * e);
      curvature = std::max(curvature, std::abs(k2));
    }
    const double bound = dx * dx / 8.0 * curvature * 1.05 + 1e-13;  // 5 %: the finite-difference estimate's own error
    EXPECT_NEAR(t(hd), CubicSpline<D>::lattice_gradient_sum(hd), bound) << "h / d = " << hd;
  }
}

TEST(Kernel, TabulatedLatticeGradientSumFollowsTheSum) {
  check_table<2>();
  check_table<3>();
}

TEST(Kernel, AcousticLengthIsHOnTheLatticeAndShorterWhereStiffer) {
  const sph::LatticeGradientSum<2> t;
  const double d = 0.5, h = 1.2 * d, rho = 1000.0;
  // The particle's own lattice: m_j = rho d^2 and sum_j d^2 |grad W_ij| = kappa / h, so the length is h.
  const double lattice_mass = rho * CubicSpline<2>::lattice_gradient_sum(1.2) / h;  // = m sum_j |grad W_ij|
  EXPECT_NEAR(t.acoustic_length(h, d, rho, lattice_mass), h, 1e-4 * h);
  EXPECT_DOUBLE_EQ(t.acoustic_length(h, d, rho, 0.5 * lattice_mass), h);  // a free surface: never longer than h
  EXPECT_NEAR(t.acoustic_length(h, d, rho, 2.0 * lattice_mass), 0.5 * h, 1e-4 * h);
  EXPECT_DOUBLE_EQ(t.acoustic_length(h, d, rho, 0.0), h);  // an isolated particle
}

TEST(Kernel, SecondDerivativeEqualsFiniteDifferenceOfTheDerivative) {
  // Central differences of dW/dr with step e: their rounding, 1e-16 |dW/dr| / e, is about 1e-11 norm(h), and their
  // truncation e^2/6 d^4W/dr^4 smaller still (the points stay off q = 1, where the third derivative jumps). The bound,
  // 1e-7 norm(h), stands far above both and far below a wrong coefficient (of order norm(h) / h^2).
  const double e = 1e-6;
  for (double r : {0.1, 0.55, 0.9, 1.3, 1.9, 2.6}) {
    const double fd = (CubicSpline<3>::derivative(r + e, 1.4) - CubicSpline<3>::derivative(r - e, 1.4)) / (2 * e);
    EXPECT_NEAR(CubicSpline<3>::second_derivative(r, 1.4), fd, 1e-7 * CubicSpline<3>::norm(1.4)) << r;
  }
}

/// The force along x on the particle at the origin of a lattice of spacing 1 whose layers with an odd last index are
/// moved by -eps along x and the others (the origin's among them) by +eps: the pressure term's kernel sum
/// sum_j grad_i W(x_i - x_j), from the gradient the pair sweep uses (gradient_factor). Its slope in eps is S.
template <int D>
double layer_shear_force(double h, double eps) {
  const int n = 4;
  double f = 0.0;
  int idx[3] = {0, 0, 0};
  for (int a = -n; a <= n; ++a)
    for (int b = -n; b <= n; ++b)
      for (int c = (D == 3 ? -n : 0); c <= (D == 3 ? n : 0); ++c) {
        idx[0] = a;
        idx[1] = b;
        idx[2] = c;
        if (a == 0 && b == 0 && c == 0) continue;
        const bool odd = idx[D - 1] % 2 != 0;
        double x[3] = {-static_cast<double>(a) + (odd ? 2.0 * eps : 0.0), -static_cast<double>(b), -static_cast<double>(c)};
        double r2 = 0.0;
        for (int k = 0; k < D; ++k) r2 += x[k] * x[k];
        f += CubicSpline<D>::gradient_factor(std::sqrt(r2), h) * x[0];
      }
  return f;
}

// The fast sum (layer_shear_stiffness: the Hessian summed over the moving layers) against its brute-force twin,
// the slope of the force the sweep's own gradient gives on the moved lattice, by central differences: error of
// order eps^2 times the kernel's fourth derivative, about 1e-10 at eps = 1e-5 (rounding adds 1e-15 / eps), within the
// bound 1e-8 (|S| is 0.002-0.1 here). The h avoid a lattice point at q = 2 that the displacement moves across (at
// h = 1.5, n = (2, 2, 1) sits at r = 3): there the third derivative jumps, and the difference errs by order eps.
TEST(Kernel, LayerShearStiffnessIsTheSlopeOfTheSweepsForceOnTheMovedLattice) {
  const double eps = 1e-5;
  for (double h : {1.0, 1.2, 1.3, 1.45, 1.732}) {
    const double fd3 = (layer_shear_force<3>(h, eps) - layer_shear_force<3>(h, -eps)) / (2 * eps);
    const double fd2 = (layer_shear_force<2>(h, eps) - layer_shear_force<2>(h, -eps)) / (2 * eps);
    EXPECT_NEAR(CubicSpline<3>::layer_shear_stiffness(h), fd3, 1e-8) << h;
    EXPECT_NEAR(CubicSpline<2>::layer_shear_stiffness(h), fd2, 1e-8) << h;
  }
}

TEST(Kernel, CompactSupport) {
  for (double h : {0.3, 1.0, 2.5}) {
    EXPECT_EQ(CubicSpline<2>::value(2.0 * h, h), 0.0);
    EXPECT_EQ(CubicSpline<2>::value(2.5 * h, h), 0.0);
    EXPECT_EQ(CubicSpline<3>::derivative(2.0 * h, h), 0.0);
    EXPECT_GT(CubicSpline<2>::value(1.999 * h, h), 0.0);
  }
}

TEST(Kernel, ZeroGradientAtOrigin) {
  EXPECT_EQ(CubicSpline<2>::derivative(0.0, 1.0), 0.0);
  EXPECT_EQ(CubicSpline<2>::gradient_factor(0.0, 1.0), 0.0);
  EXPECT_EQ(CubicSpline<3>::gradient_factor(0.0, 1.0), 0.0);
}

}  // namespace
