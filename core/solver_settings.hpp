#pragma once
// Plain settings of the solver: which effects a scene enables and their constants.
// An effect that is off is absent from the pair sweep's pack and allocates nothing.
#include <optional>

#include "core/boundary/ghosts.hpp"
#include "core/boundary/wall.hpp"
#include "core/equation_of_state.hpp"
#include "core/types.hpp"
#include "core/watchdog.hpp"

namespace sph {

struct ViscositySettings {
  double alpha = 0.02;
  double beta = 0.0;
  bool operator==(const ViscositySettings&) const = default;
};

struct ArtificialStressSettings {
  double epsilon = 0.2;  // Monaghan (2000): 0.2 with the cubic spline
  int exponent = 4;      // n in f_ij^n
  bool operator==(const ArtificialStressSettings&) const = default;
};

struct DensityDiffusionSettings {
  double delta = 0.1;  // Molteni & Colagrossi (2009); 0.1 is the usual value
  bool operator==(const DensityDiffusionSettings&) const = default;
};

struct LennardJonesSettings {
  double strength = 1.0;   // D (PHYSICS.md default 5 g H_ref, set by the case)
  double r0_factor = 0.5;  // r0 = r0_factor d^{l_i}; 0.5 keeps it zero at rest with lattices d/2 off the wall
  double spacing = 0.0;    // wall particle spacing (0: half the finest fluid spacing the scene can reach)
};

/// Gravity's default: 9.81 m/s^2 down the last axis (y in 2D, z in 3D).
template <int D>
Vec<D> standard_gravity() {
  Vec<D> g = Vec<D>::Zero();
  g[D - 1] = -9.81;
  return g;
}

template <int D>
struct SolverSettingsT {
  TaitEquationOfState eos;
  std::optional<Vec<D>> gravity = standard_gravity<D>();
  std::optional<ViscositySettings> viscosity = ViscositySettings{};
  std::optional<ArtificialStressSettings> artificial_stress;  // off by default (PHYSICS.md: optional effect)
  std::optional<DensityDiffusionSettings> density_diffusion;  // off by default (PHYSICS.md: optional effect)
  std::optional<LennardJonesSettings> lennard_jones;
  std::optional<GhostSlip> ghosts = GhostSlip::free_slip;
  GhostPressure ghost_pressure = GhostPressure::hydrostatic;
  Geometry<D> geometry;
  double cfl = 0.2;
  double dt_max = 1.0;  // upper bound on the step (s)
  TimeStepping stepping = TimeStepping::global;
  int bin_jump = kDefaultBinJump;  // per_level: neighbours' bins at most this far apart (Integrator::limit_bins)
  TimePredictor predictor = TimePredictor::extrapolated;  // Integrator::drift
  // How levels interact (core/types.hpp). The refinement stage sets it from effects.refinement.coupling when it is
  // added (refine::add_refinement_stage), the scene key's one home.
  LevelCoupling coupling = LevelCoupling::mixed;
  WatchdogSettings watchdog;
};

using SolverSettings = SolverSettingsT<2>;

}  // namespace sph
