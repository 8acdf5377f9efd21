#pragma once
// Scene -> ready Simulation: solver settings (absent effects stay std::nullopt), fluid lattices,
// hydrostatic starts, wall particles, rates evaluated, static refinement applied, dynamic refinement
// added as a stage. The same set-up as the programmatic cases (core/case_builder.hpp).
#include "core/scene/scene.hpp"
#include "core/simulation.hpp"

namespace sph::scene {

/// The solver settings a scene asks for, in the scene's dimension D (the caller picks it: with_dimension).
template <int D = 2>
SolverSettingsT<D> solver_settings(const Scene& scene);

/// A simulation at t = 0, rates evaluated and dt set (the scene must have passed validate_scene(), and D must be
/// its dimension). With a communicator of several ranks, the run is distributed from the start: each rank builds
/// only a share of the fluid (every rank-th lattice point, with the ids the whole set-up gives it, and every wall
/// particle), the shares go to the owners of their cells, and the rates are evaluated across the ranks, so no rank
/// ever holds the whole set (issue #19). Collective then.
template <int D = 2>
SimulationT<D> build_simulation(const Scene& scene, const par::Comm* comm = nullptr);

}  // namespace sph::scene
