#include "core/scene/scene_builder.hpp"

#include "core/boundary/wall_particles.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/setup.hpp"

namespace sph::scene {

SolverSettings solver_settings(const Scene& scene) {
  SolverSettings s;
  s.eos.rho0 = scene.material.rho0;
  s.eos.gamma = scene.material.gamma;
  s.eos.c0 = sound_speed(scene);
  const Effects& e = scene.effects;
  s.gravity = e.gravity;
  s.viscosity = e.artificial_viscosity;
  s.artificial_stress = e.artificial_stress;
  s.density_diffusion = e.density_diffusion;
  s.lennard_jones.reset();
  if (e.lennard_jones_wall) {
    s.lennard_jones = LennardJonesSettings{lennard_jones_strength(scene), e.lennard_jones_wall->r0_factor, wall_spacing(scene)};
  }
  s.ghosts = e.ghost_walls;
  s.ghost_pressure = e.ghost_pressure;
  s.geometry.container = scene.container.box;
  s.geometry.open_top = scene.container.open_top;
  s.geometry.outflow = scene.container.outflow;
  s.geometry.obstacles = scene.obstacles;
  s.cfl = scene.time.cfl;
  s.dt_max = scene.time.dt_max;
  s.stepping = scene.time.stepping;
  return s;
}

Simulation build_simulation(const Scene& scene) {
  const SolverSettings settings = solver_settings(scene);
  Simulation sim(settings);
  ParticleStore<2>& store = sim.store();
  const double g = gravity_magnitude(scene);
  for (const FluidRegion& f : scene.fluid) {
    const double d = f.lattice_spacing();
    const std::vector<Vec<2>> points = f.shape == Shape::rectangle ? lattice_rectangle(f.rect.lo, f.rect.hi, d)
                                                                  : lattice_circle(f.centre, f.radius, d);
    FluidBlockSpec block;
    block.spacing = d;
    block.h_factor = scene.h_factor;
    block.level = f.level;
    block.velocity = f.velocity;
    const std::size_t first = add_fluid(store, points, block, settings.eos.rho0);
    if (f.hydrostatic) {
      const double surface = f.surface.value_or(f.shape == Shape::rectangle ? f.rect.hi[1] : f.centre[1] + f.radius);
      set_hydrostatic(store, first, store.size(), surface, g, settings.eos);
    }
  }
  if (settings.lennard_jones) {
    add_wall_particles(store, settings.geometry.walls(), settings.lennard_jones->spacing, settings.eos.rho0);
  }
  sim.refresh();
  if (const auto& st = scene.effects.static_refinement) {
    if (st->box) {
      refine::refine_region(sim, *st->box, st->pattern, st->rsp_k);
    } else {
      refine::refine_all(sim, st->pattern, st->rsp_k);
    }
  }
  if (scene.effects.refinement) refine::add_refinement_stage(sim, *scene.effects.refinement);
  return sim;
}

}  // namespace sph::scene
