#include "core/scene/scene_builder.hpp"

#include "core/boundary/wall_particles.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/scene/scene_error.hpp"
#include "core/setup.hpp"

#include <stdexcept>
#include <string>

namespace sph::scene {

template <int D>
SolverSettingsT<D> solver_settings(const Scene& scene) {
  SolverSettingsT<D> s;
  s.eos.rho0 = scene.material.rho0;
  s.eos.gamma = scene.material.gamma;
  s.eos.c0 = sound_speed(scene);
  const Effects& e = scene.effects;
  s.gravity.reset();
  if (e.gravity) s.gravity = e.gravity->fixed<D>();
  s.viscosity = e.artificial_viscosity;
  s.artificial_stress = e.artificial_stress;
  s.density_diffusion = e.density_diffusion;
  s.lennard_jones.reset();
  if (e.lennard_jones_wall) {
    s.lennard_jones = LennardJonesSettings{lennard_jones_strength(scene), e.lennard_jones_wall->r0_factor, wall_spacing(scene)};
  }
  s.ghosts = e.ghost_walls;
  s.ghost_pressure = e.ghost_pressure;
  s.geometry.container = scene.container.box.fixed<D>();
  s.geometry.open_top = scene.container.open_top;
  s.geometry.outflow = scene.container.outflow;
  s.geometry.obstacles.clear();
  for (const Rect& o : scene.obstacles) s.geometry.obstacles.push_back(o.fixed<D>());
  s.cfl = scene.time.cfl;
  s.dt_max = scene.time.dt_max;
  s.stepping = scene.time.stepping;
  s.bin_jump = scene.time.bin_jump;
  s.predictor = scene.time.predictor;
  return s;
}

template <int D>
SimulationT<D> build_simulation(const Scene& scene, const par::Comm* comm) {
  if (dimension(scene) != D) {
    throw std::invalid_argument("build_simulation<" + std::to_string(D) + ">: the scene is " +
                                std::to_string(dimension(scene)) + "D");
  }
  const SolverSettingsT<D> settings = solver_settings<D>(scene);
  if (comm != nullptr && comm->distributed() && scene.effects.refinement &&
      scene.effects.refinement->coupling == LevelCoupling::buffered) {
    // The passive particles' fit reads fluid and ghosts only, not another rank's halos: across ranks it would
    // differ from one process.
    throw SceneError("effects.refinement.coupling",
                     "\"buffered\" runs in one process only so far (a passive particle's fit does not read halos); "
                     "run without mpirun, or use \"mixed\"");
  }
  SimulationT<D> sim(settings);
  ParticleStore<D>& store = sim.store();
  const double g = gravity_magnitude(scene);
  constexpr int up = D - 1;
  const bool shared = comm != nullptr && comm->distributed();
  const auto stride = shared ? static_cast<std::size_t>(comm->size()) : 1, offset = shared ? static_cast<std::size_t>(comm->rank()) : 0;
  for (const FluidRegion& f : scene.fluid) {
    const double d = f.lattice_spacing();
    // This rank's share of the lattice (the whole lattice in one process), generated without the rest.
    const LatticeShare<D> points = lattice_share<D>(
        [&](auto&& visit) {
          if (f.shape == Shape::rectangle) {
            each_block_point<D>(f.rect.lo.fixed<D>(), f.rect.hi.fixed<D>(), d, visit);
          } else {
            each_round_point<D>(f.centre.fixed<D>(), f.radius, d, visit);
          }
        },
        stride, offset);
    FluidBlockSpecT<D> block;
    block.spacing = d;
    block.h_factor = scene.h_factor;
    block.level = f.level;
    block.velocity = f.velocity.fixed<D>();
    const std::size_t first = add_fluid(store, points, block, settings.eos.rho0);
    if (f.hydrostatic) {
      const double surface = f.surface.value_or(f.shape == Shape::rectangle ? f.rect.hi[up] : f.centre[up] + f.radius);
      set_hydrostatic(store, first, store.size(), surface, g, settings.eos);
    }
  }
  if (settings.lennard_jones) {
    add_wall_particles(store, settings.geometry.walls(), settings.lennard_jones->spacing, settings.eos.rho0);
  }
  if (shared) sim.distribute(*comm, false);
  sim.refresh();
  if (const auto& st = scene.effects.static_refinement) {
    if (st->box) {
      refine::refine_region(sim, st->box->fixed<D>(), st->pattern, st->rsp_k);
    } else {
      refine::refine_all(sim, st->pattern, st->rsp_k);
    }
    // The decomposition cells follow the largest support, which a split of every particle halves.
    if (shared) sim.distribute(*comm, false);
  }
  if (scene.effects.refinement) refine::add_refinement_stage(sim, *scene.effects.refinement);
  return sim;
}

template SolverSettingsT<2> solver_settings<2>(const Scene&);
template SolverSettingsT<3> solver_settings<3>(const Scene&);
template SimulationT<2> build_simulation<2>(const Scene&, const par::Comm*);
template SimulationT<3> build_simulation<3>(const Scene&, const par::Comm*);

}  // namespace sph::scene
