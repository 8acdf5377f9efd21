#include <gtest/gtest.h>

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
