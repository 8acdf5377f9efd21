#pragma once
// The still-tank measurement of the buffered-level tests (BufferedStillTank in 2D, BufferedStillTank3D): step a tank
// with its refinement stage to `end` and record what issue #15's still-tank targets bound.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/boundary/wall.hpp"
#include "core/refinement/refinement_settings.hpp"
#include "core/simulation.hpp"

namespace sph::test {

struct TankRun {
  double window_speed = 0.0;                        // the largest speed of each step, averaged over [end / 3, end]
  std::size_t fluid_after_last = 0, fluid_end = 0;  // active fluid after the last pass and at the end
  double largest_pass_change = 0.0;                 // |E after - E before| of any pass
  double e0 = 0.0;
  std::size_t outside = 0;  // fluid particles outside the fluid domain at the end
  std::size_t passes = 0;   // passes that changed the store
  int coarse_bin = -1;      // the finest time bin of an active level-0 particle at the end (set by the 2D test)
  int fine_bin = -1;        // the coarsest time bin of an active particle of the finest level at the end (the same)
};

/// A zone refined to `levels` with buffered levels, checked every 100 steps: the still-tank tests' refinement.
template <int D>
refine::RefinementSettings buffered_zone(const Box<D>& zone, refine::Pattern pattern, int levels) {
  refine::RefinementSettings r;
  r.criterion = refine::CriterionKind::zone;
  r.zone = zone;
  r.pattern = pattern;
  r.check_interval = 100;
  r.max_level = levels;
  r.coupling = LevelCoupling::buffered;
  return r;
}

/// Steps `sim` (with its stages) to `end`; a pass is a stage run that changes the store's size.
template <int D>
TankRun measure_still_tank(SimulationT<D>& sim, double end) {
  TankRun out;
  out.e0 = sim.diagnostics().total_energy();
  double speed_sum = 0.0;
  std::size_t speed_steps = 0;
  while (sim.time() < end) {
    sim.step();
    const auto before = sim.diagnostics();
    if (sim.time() >= end / 3.0) {
      speed_sum += before.max_speed;
      ++speed_steps;
    }
    const std::size_t stored = sim.store().size();
    sim.run_stages();
    if (sim.store().size() != stored) {
      const auto after = sim.diagnostics();
      out.largest_pass_change = std::max(out.largest_pass_change, std::abs(after.total_energy() - before.total_energy()));
      out.fluid_after_last = after.fluid;
      ++out.passes;
    }
  }
  out.window_speed = speed_sum / static_cast<double>(std::max<std::size_t>(speed_steps, 1));
  out.fluid_end = sim.diagnostics().fluid;
  const auto& s = sim.store();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] == Kind::fluid && !sim.settings().geometry.in_fluid_domain(s.x[i])) ++out.outside;
  }
  return out;
}

}  // namespace sph::test
