#pragma once
// Tait equation of state, eqs. (7)-(8): p = B ((rho/rho0)^gamma - 1), B = c0^2 rho0 / gamma.
#include <cmath>

namespace sph {

/// The sound speed from a Mach factor and a reference height H (PHYSICS.md, eq. (8) decision; docs/SCENES.md,
/// material.reference_height): c0 = mach_factor * sqrt(2 g H), sqrt(2 g H) being the free-fall speed from H.
/// Flow at that speed then compresses the fluid by about 1 / mach_factor^2 (1 % at the default 10), and so does
/// a hydrostatic column 2 H deep at its floor (g 2H / c0^2).
inline double sound_speed_from_height(double mach_factor, double g, double height) {
  return mach_factor * std::sqrt(2.0 * g * height);
}

struct TaitEquationOfState {
  double rho0 = 1000.0;
  double c0 = 10.0;
  double gamma = 7.0;

  double B() const { return c0 * c0 * rho0 / gamma; }

  double pressure(double rho) const {
    const double r = rho / rho0;
    if (gamma == 7.0) {
      const double r2 = r * r, r4 = r2 * r2;
      return B() * (r4 * r2 * r - 1.0);
    }
    return B() * (std::pow(r, gamma) - 1.0);
  }

  /// dp/drho = c0^2 (rho / rho0)^(gamma - 1): the local sound speed squared.
  double sound_speed_squared(double rho) const { return c0 * c0 * std::pow(rho / rho0, gamma - 1.0); }

  /// Inverse: the density at pressure p (hydrostatic initial state).
  double density(double p) const { return rho0 * std::pow(1.0 + p / B(), 1.0 / gamma); }

  /// Specific elastic energy e(rho) = int_{rho0}^{rho} p / rho'^2 drho' (zero at rho0, never negative).
  double specific_energy(double rho) const {
    const double g1 = gamma - 1.0;
    return B() * ((std::pow(rho, g1) - std::pow(rho0, g1)) / (g1 * std::pow(rho0, gamma)) + 1.0 / rho - 1.0 / rho0);
  }
};

}  // namespace sph
