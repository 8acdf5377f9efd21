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
/// its dimension).
template <int D = 2>
SimulationT<D> build_simulation(const Scene& scene);

}  // namespace sph::scene
