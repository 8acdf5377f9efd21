#pragma once
// Basic types shared by the whole library.
#include <Eigen/Core>
#include <cstdint>

namespace sph {

/// A point or vector in D dimensions (D = 2 or 3).
template <int D>
using Vec = Eigen::Matrix<double, D, 1>;

/// What a particle is: a real fluid particle, a fixed wall particle (Lennard-Jones repulsion, eq. 10),
/// or a ghost mirrored from a fluid particle across a wall (section 2.4).
enum class Kind : std::uint8_t { fluid = 0, wall = 1, ghost = 2 };

/// How a particle took its level: at set-up, as a daughter of a split, or as the particle a merge made
/// (`fresh_merge` until the refinement check after that merge, which does not split it, then `merge`).
enum class Origin : std::uint8_t { setup = 0, split = 1, fresh_merge = 2, merge = 3 };

/// time.stepping (core/integrator.hpp): one global step (the paper's), or power-of-two steps per refinement level.
enum class TimeStepping { global, per_level };

using Index = std::uint32_t;
using ParticleId = std::uint64_t;

}  // namespace sph
