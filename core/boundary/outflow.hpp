#pragma once
// Outflow through an open top: the fluid particles that left the container over its rim
// (Geometry2::left_through_open_top) are taken out of the store, counted, and their mass summed, so a run
// that removes fluid accounts for every kilogram (M + removed mass = M0 up to rounding).
//
// A function of the store and the geometry alone: the step calls it once after the drift, before the
// neighbour search and the watchdog's check (core/simulation.cpp), when the scene asks for it
// (container.outflow = "remove").
#include <cstdint>

#include "core/boundary/wall.hpp"
#include "core/diagnostics.hpp"
#include "core/particle_store.hpp"
#include "parallel/exact_sum.hpp"

namespace sph {

/// Fluid removed through the open top: how many particles and their mass (an exact sum, so the running total is
/// the same bits whatever the order of the removals, and however they are split between threads or ranks). Part
/// of the run's state.
struct RemovedFluid {
  std::uint64_t particles = 0;
  par::ExactSum mass;

  RemovedFluid& add(const RemovedFluid& more) {
    particles += more.particles;
    mass.merge(more.mass);
    return *this;
  }
};

/// Removes every fluid particle outside the fluid domain that left through the open top (its drift velocity
/// vh traced back crosses a side line above the rim), keeping the others in order (one compaction of every
/// field through the registry, only when something leaves). Particles that left through a wall stay for the
/// watchdog. Deterministic: the same particles in the same order at any thread count. Returns what it removed.
template <int D>
RemovedFluid remove_outflow(ParticleStore<D>& store, const Geometry<D>& geometry);

}  // namespace sph
