#pragma once
// Picks the pair-sweep instantiation whose effect pack matches the enabled effects. The choice is made
// once per run; the sweep is then one virtual call per step, never per pair. Each optional effect doubles
// the instantiations: the pack is built one effect at a time, each step a compile-time branch.
#include <memory>
#include <string>
#include <tuple>
#include <utility>

#include "core/effects/artificial_stress.hpp"
#include "core/effects/artificial_viscosity.hpp"
#include "core/effects/continuity.hpp"
#include "core/effects/density_diffusion.hpp"
#include "core/effects/lennard_jones_wall.hpp"
#include "core/effects/pressure_gradient.hpp"
#include "core/solver_settings.hpp"
#include "core/sweep.hpp"

namespace sph {

template <int D>
class SweepBase {
 public:
  virtual ~SweepBase() = default;
  virtual SweepLimits run(ParticleView<D> s, const CellGrid<D>& grid, Activity act = {}) const = 0;
  /// The effects in the pack, e.g. "continuity+pressure+viscosity|lj" (fluid pairs | wall pairs).
  virtual const char* name() const = 0;
};

template <int D, class Fluid, class Wall>
class SweepImpl final : public SweepBase<D> {
 public:
  SweepImpl(Fluid f, Wall w, double c0, Vec<D> g, AcousticLimit acoustic, std::string name)
      : sweep_(std::move(f), std::move(w), c0, std::move(g), acoustic), name_(std::move(name)) {}
  SweepLimits run(ParticleView<D> s, const CellGrid<D>& grid, Activity act = {}) const override {
    return sweep_(s, grid, act);
  }
  const char* name() const override { return name_.c_str(); }

 private:
  PairSweep<D, Fluid, Wall> sweep_;
  std::string name_;
};

namespace sweep_detail {

template <int D, class Fluid>
std::unique_ptr<SweepBase<D>> with_walls(Fluid fluid, const SolverSettingsT<D>& s, std::string name) {
  const Vec<D> g = s.gravity.value_or(Vec<D>::Zero());
  if (s.lennard_jones) {
    auto wall = std::make_tuple(LennardJonesWall{s.lennard_jones->strength, s.lennard_jones->r0_factor});
    return std::make_unique<SweepImpl<D, Fluid, decltype(wall)>>(std::move(fluid), std::move(wall), s.eos.c0, g,
                                                             AcousticLimit{s.predictor, s.cfl},
                                                             name + "|lj");
  }
  return std::make_unique<SweepImpl<D, Fluid, std::tuple<>>>(std::move(fluid), std::tuple<>{}, s.eos.c0, g,
                                                           AcousticLimit{s.predictor, s.cfl}, name);
}

template <int D, class Fluid>
std::unique_ptr<SweepBase<D>> with_diffusion(Fluid fluid, const SolverSettingsT<D>& s, std::string name) {
  if (s.density_diffusion) {
    const double c0 = s.eos.c0;
    const Vec<D> g = s.gravity.value_or(Vec<D>::Zero());
    const DensityDiffusion<D> dd{s.density_diffusion->delta, c0, (s.eos.rho0 / (c0 * c0)) * g};
    return with_walls(std::tuple_cat(std::move(fluid), std::make_tuple(dd)), s, name + "+density_diffusion");
  }
  return with_walls(std::move(fluid), s, std::move(name));
}

template <int D, class Fluid>
std::unique_ptr<SweepBase<D>> with_stress(Fluid fluid, const SolverSettingsT<D>& s, std::string name) {
  if (s.artificial_stress) {
    const ArtificialStress as{s.artificial_stress->epsilon, s.artificial_stress->exponent};
    return with_diffusion(std::tuple_cat(std::move(fluid), std::make_tuple(as)), s, name + "+artificial_stress");
  }
  return with_diffusion(std::move(fluid), s, std::move(name));
}

}  // namespace sweep_detail

template <int D>
std::unique_ptr<SweepBase<D>> make_sweep(const SolverSettingsT<D>& s) {
  const std::tuple<Continuity, PressureGradient> base{};
  if (s.viscosity) {
    const ArtificialViscosity av{s.viscosity->alpha, s.viscosity->beta, s.eos.c0};
    return sweep_detail::with_stress(std::tuple_cat(base, std::make_tuple(av)), s, "continuity+pressure+viscosity");
  }
  return sweep_detail::with_stress(base, s, "continuity+pressure");
}

// Instantiated once, in the library (core/simulation_2d.cpp, core/simulation_3d.cpp): every pack of effects is a
// sweep of its own, six loops each, and a test or benchmark that called make_sweep compiled them all again (the
// partition test alone took a minute to compile).
extern template std::unique_ptr<SweepBase<2>> make_sweep<2>(const SolverSettingsT<2>&);
extern template std::unique_ptr<SweepBase<3>> make_sweep<3>(const SolverSettingsT<3>&);

}  // namespace sph
