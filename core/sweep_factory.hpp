#pragma once
// Picks the pair-sweep instantiation whose effect pack matches the enabled effects. The choice is made
// once per run; the sweep is then one virtual call per step, never per pair.
#include <memory>
#include <tuple>

#include "core/effects/artificial_viscosity.hpp"
#include "core/effects/continuity.hpp"
#include "core/effects/lennard_jones_wall.hpp"
#include "core/effects/pressure_gradient.hpp"
#include "core/solver_settings.hpp"
#include "core/sweep.hpp"

namespace sph {

class SweepBase {
 public:
  virtual ~SweepBase() = default;
  virtual SweepLimits run(ParticleView<2> s, const CellGrid<2>& grid) const = 0;
  virtual const char* name() const = 0;
};

template <class Fluid, class Wall>
class SweepImpl final : public SweepBase {
 public:
  SweepImpl(Fluid f, Wall w, double c0, Vec<2> g, const char* name) : sweep_(f, w, c0, g), name_(name) {}
  SweepLimits run(ParticleView<2> s, const CellGrid<2>& grid) const override { return sweep_(s, grid); }
  const char* name() const override { return name_; }

 private:
  PairSweep<2, Fluid, Wall> sweep_;
  const char* name_;
};

inline std::unique_ptr<SweepBase> make_sweep(const SolverSettings& s) {
  const double c0 = s.eos.c0;
  const Vec<2> g = s.gravity.value_or(Vec<2>::Zero());
  const std::tuple<Continuity, PressureGradient> base{};
  if (s.viscosity) {
    const ArtificialViscosity av{s.viscosity->alpha, s.viscosity->beta, c0};
    const auto fluid = std::tuple_cat(base, std::make_tuple(av));
    if (s.lennard_jones) {
      const auto wall = std::make_tuple(LennardJonesWall{s.lennard_jones->strength, s.lennard_jones->r0_factor});
      return std::make_unique<SweepImpl<decltype(fluid), decltype(wall)>>(fluid, wall, c0, g,
                                                                          "continuity+pressure+viscosity|lj");
    }
    return std::make_unique<SweepImpl<decltype(fluid), std::tuple<>>>(fluid, std::tuple<>{}, c0, g,
                                                                      "continuity+pressure+viscosity");
  }
  if (s.lennard_jones) {
    const auto wall = std::make_tuple(LennardJonesWall{s.lennard_jones->strength, s.lennard_jones->r0_factor});
    return std::make_unique<SweepImpl<decltype(base), decltype(wall)>>(base, wall, c0, g, "continuity+pressure|lj");
  }
  return std::make_unique<SweepImpl<decltype(base), std::tuple<>>>(base, std::tuple<>{}, c0, g,
                                                                   "continuity+pressure");
}

}  // namespace sph
