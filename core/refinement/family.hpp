#pragma once
// Families of daughters: a particle's id says who its parent is, without a table and without a global
// counter per split.
//
// An id holds the particle's generation (how many splits separate it from a particle of the set-up) in its
// top bits and its path below: a particle of the set-up has generation 0 and the path its set-up id; daughter
// a (0..3) of a particle with path P has path 4 P + a, one generation more. So
//   - daughters' ids are unique wherever the parent is (the same on every thread and, later, every rank);
//   - the four daughters of one parent share parent_id(), and a merge gives the parent its own id back, so
//     a merged particle can merge again with its own siblings.
// A path grows by two bits a generation: set-up ids below 2^(58 - 2 g) leave room for g generations
// (kMaxGenerations keeps 2^26 = 6.7e7 set-up ids, above the 5e7 particle cap, for 16 generations).
#include <cstdint>

#include "core/types.hpp"

namespace sph::refine {

inline constexpr int kGenerationShift = 58;
inline constexpr ParticleId kPathMask = (ParticleId{1} << kGenerationShift) - 1;
inline constexpr int kMaxGenerations = 16;
/// Set-up ids must stay below this for kMaxGenerations splits to fit in the path.
inline constexpr ParticleId kMaxRootId = ParticleId{1} << (kGenerationShift - 2 * kMaxGenerations);

inline constexpr int generation(ParticleId id) { return static_cast<int>(id >> kGenerationShift); }
inline constexpr ParticleId path(ParticleId id) { return id & kPathMask; }

/// The id of daughter a (0..3) of the particle with id `parent`.
inline constexpr ParticleId daughter_id(ParticleId parent, unsigned a) {
  return (static_cast<ParticleId>(generation(parent) + 1) << kGenerationShift) | (path(parent) << 2) | a;
}

/// True for a daughter (generation > 0): it has a parent and siblings.
inline constexpr bool has_parent(ParticleId id) { return generation(id) > 0; }

/// The id of the particle that was split into `id` and its siblings (for has_parent(id) only).
inline constexpr ParticleId parent_id(ParticleId id) {
  return (static_cast<ParticleId>(generation(id) - 1) << kGenerationShift) | (path(id) >> 2);
}

/// Which of the four daughters `id` is (0..3).
inline constexpr unsigned sibling_index(ParticleId id) { return static_cast<unsigned>(id & 3u); }

static_assert(parent_id(daughter_id(12345, 2)) == 12345);
static_assert(sibling_index(daughter_id(12345, 3)) == 3);
static_assert(parent_id(daughter_id(daughter_id(7, 1), 3)) == daughter_id(7, 1));

}  // namespace sph::refine
