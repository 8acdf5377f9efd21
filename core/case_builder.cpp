#include "core/case_builder.hpp"

#include <cmath>

#include "core/boundary/wall_particles.hpp"
#include "core/setup.hpp"

namespace sph {

namespace {

constexpr double kG = 9.81;

void add_lattice(Simulation& sim, const std::vector<Vec<2>>& pts, double spacing, double h_factor, int level,
                 const Vec<2>& velocity) {
  FluidBlockSpec block;
  block.spacing = spacing;
  block.h_factor = h_factor;
  block.level = level;
  block.velocity = velocity;
  add_fluid(sim.store(), pts, block, sim.settings().eos.rho0);
}

double level_spacing(double d0, int level) { return d0 / std::pow(2.0, level); }

/// The finest level a run can reach (wall particles are spaced at half its spacing).
int finest_level(int initial, bool fully_refined, const std::optional<refine::RefinementSettings>& r) {
  int finest = initial + (fully_refined ? 1 : 0);
  if (r) finest = std::max(finest, r->max_level);
  return finest;
}

/// Static refinement and the dynamic stage, as the spec asks.
void apply_refinement(Simulation& sim, bool fully_refined, const std::optional<refine::RefinementSettings>& r) {
  if (fully_refined) refine::refine_all(sim, refine::Pattern::aap, 1.0);
  if (r) refine::add_refinement_stage(sim, *r);
}

}  // namespace

Simulation make_still_tank(const TankSpec& spec) {
  SolverSettings s;
  s.eos.rho0 = 1000.0;
  s.eos.c0 = sound_speed_from_height(spec.mach_factor, kG, spec.reference_height);
  s.geometry.container = {Vec<2>(0, 0), Vec<2>(spec.width, 2.0 * spec.depth)};
  s.ghost_pressure = spec.ghost_pressure;
  if (spec.density_diffusion) s.density_diffusion = DensityDiffusionSettings{0.1};
  s.stepping = spec.stepping;
  if (spec.lennard_jones) s.lennard_jones = LennardJonesSettings{5.0 * kG * spec.depth, 0.5, spec.spacing / 2};
  Simulation sim(s);
  add_lattice(sim, lattice_rectangle(Vec<2>(0, 0), Vec<2>(spec.width, spec.depth), spec.spacing), spec.spacing,
              spec.h_factor, 0, Vec<2>::Zero());
  set_hydrostatic(sim.store(), 0, sim.store().size(), spec.depth, kG, s.eos);
  if (spec.lennard_jones) add_wall_particles(sim.store(), s.geometry.walls(), spec.spacing / 2, s.eos.rho0);
  sim.refresh();
  return sim;
}

SimulationT<3> make_still_tank(const Tank3Spec& spec) {
  SolverSettingsT<3> s;
  s.eos.rho0 = 1000.0;
  s.eos.c0 = sound_speed_from_height(spec.mach_factor, kG, spec.reference_height);
  s.geometry.container = {Vec<3>(0, 0, 0), Vec<3>(spec.length, spec.width, 2.0 * spec.depth)};
  s.ghost_pressure = spec.ghost_pressure;
  SimulationT<3> sim(s);
  FluidBlockSpecT<3> block;
  block.spacing = spec.spacing;
  block.h_factor = spec.h_factor;
  add_fluid(sim.store(), lattice_box(Vec<3>(0, 0, 0), Vec<3>(spec.length, spec.width, spec.depth), spec.spacing),
            block, s.eos.rho0);
  set_hydrostatic(sim.store(), 0, sim.store().size(), spec.depth, kG, s.eos);
  sim.refresh();
  return sim;
}

SimulationT<3> make_dam_break(const DamBreak3Spec& spec) {
  SolverSettingsT<3> s;
  s.eos.rho0 = 1000.0;
  const double H = spec.water[2];
  s.eos.c0 = spec.coef_sound * std::sqrt(kG * H);
  s.viscosity = ViscositySettings{spec.alpha, 0.0};
  if (spec.density_diffusion) s.density_diffusion = DensityDiffusionSettings{0.1};
  s.geometry.container = {Vec<3>::Zero(), spec.tank};
  s.geometry.obstacles.push_back({spec.column_lo, spec.column_hi});
  const double wall_spacing = 0.5 * spec.spacing;
  s.lennard_jones = LennardJonesSettings{5.0 * kG * H, 0.5, wall_spacing};
  SimulationT<3> sim(s);
  FluidBlockSpecT<3> block;
  block.spacing = spec.spacing;
  block.h_factor = spec.h_factor;
  add_fluid(sim.store(), lattice_box(Vec<3>::Zero(), spec.water, spec.spacing), block, s.eos.rho0);
  set_hydrostatic(sim.store(), 0, sim.store().size(), H, kG, s.eos);
  add_wall_particles(sim.store(), s.geometry.walls(), wall_spacing, s.eos.rho0);
  sim.refresh();
  return sim;
}

Simulation make_dam_break(const DamBreakSpec& spec) {
  SolverSettings s;
  s.eos.rho0 = 1000.0;
  s.eos.c0 = sound_speed_from_height(spec.mach_factor, kG, spec.column_height);
  s.geometry.container = {Vec<2>(0, 0), Vec<2>(spec.tank_width, spec.tank_height)};
  if (!spec.viscosity) s.viscosity.reset();
  if (!spec.ghosts) s.ghosts.reset();
  const double d = level_spacing(spec.spacing, spec.initial_level);
  const double wall_spacing =
      0.5 * level_spacing(spec.spacing, finest_level(spec.initial_level, spec.fully_refined, spec.refinement));
  if (spec.lennard_jones) s.lennard_jones = LennardJonesSettings{5.0 * kG * spec.column_height, 0.5, wall_spacing};
  Simulation sim(s);
  add_lattice(sim, lattice_rectangle(Vec<2>(0, 0), Vec<2>(spec.column_width, spec.column_height), d),
              d, spec.h_factor, spec.initial_level, Vec<2>::Zero());
  set_hydrostatic(sim.store(), 0, sim.store().size(), spec.column_height, kG, s.eos);
  if (spec.lennard_jones) add_wall_particles(sim.store(), s.geometry.walls(), wall_spacing, s.eos.rho0);
  sim.refresh();
  apply_refinement(sim, spec.fully_refined, spec.refinement);
  return sim;
}

Simulation make_drop(const DropSpec& spec) {
  SolverSettings s;
  s.eos.rho0 = 1000.0;
  s.eos.c0 = sound_speed_from_height(spec.mach_factor, kG, spec.reference_height);
  s.viscosity = ViscositySettings{spec.alpha, 0.0};
  if (spec.density_diffusion) s.density_diffusion = DensityDiffusionSettings{0.1};
  const double half = 0.5 * spec.width;
  s.geometry.container = {Vec<2>(-half, 0), Vec<2>(half, 2.0 * spec.depth)};
  const double d = level_spacing(spec.spacing, spec.initial_level);
  const double wall_spacing =
      0.5 * level_spacing(spec.spacing, finest_level(spec.initial_level, spec.fully_refined, spec.refinement));
  if (spec.lennard_jones) s.lennard_jones = LennardJonesSettings{5.0 * kG * spec.depth, 0.5, wall_spacing};
  Simulation sim(s);
  add_lattice(sim, lattice_rectangle(Vec<2>(-half, 0), Vec<2>(half, spec.depth), d), d, spec.h_factor,
              spec.initial_level, Vec<2>::Zero());
  const std::size_t pool = sim.store().size();
  set_hydrostatic(sim.store(), 0, pool, spec.depth, kG, s.eos);
  add_lattice(sim, lattice_circle(spec.centre, spec.radius, d), d, spec.h_factor, spec.initial_level,
              Vec<2>(0.0, -spec.drop_speed));
  if (spec.lennard_jones) add_wall_particles(sim.store(), s.geometry.walls(), wall_spacing, s.eos.rho0);
  sim.refresh();
  apply_refinement(sim, spec.fully_refined, spec.refinement);
  return sim;
}

}  // namespace sph
