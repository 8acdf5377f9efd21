#pragma once
// Families of daughters: a particle's id says who its parent is, without a table and without a global
// counter per split.
//
// An id holds the particle's generation (how many splits separate it from a particle of the set-up) in its
// top bits and its path below: a particle of the set-up has generation 0 and the path its set-up id; daughter
// a (0 .. 2^D - 1) of a particle with path P has path 2^D P + a, one generation more (D bits). So
//   - daughters' ids are unique wherever the parent is (the same on every thread and, later, every rank);
//   - the daughters of one parent share parent_id(), and a merge gives the parent its own id back, so
//     a merged particle can merge again with its own siblings.
// A path grows by D bits a generation: set-up ids below 2^(58 - D g) leave room for g generations.
#include <cstdint>

#include "core/types.hpp"

namespace sph::refine {

inline constexpr int kGenerationShift = 58;
inline constexpr ParticleId kPathMask = (ParticleId{1} << kGenerationShift) - 1;

/// A split makes 2^D daughters: D bits of path a generation.
template <int D = 2>
inline constexpr unsigned kChildren = 1u << D;
template <int D = 2>
inline constexpr int kChildBits = D;
/// Generations an id has room for: 16 in 2D (32 bits of path), 10 in 3D (30 bits). Either leaves set-up ids
/// below 2^26 = 6.7e7 (2D) or 2^28 (3D), above the 5e7 particle cap.
template <int D = 2>
inline constexpr int kMaxGenerationsIn = D == 2 ? 16 : 10;
inline constexpr int kMaxGenerations = kMaxGenerationsIn<2>;
/// Set-up ids must stay below this for the dimension's generations to fit in the path.
template <int D = 2>
inline constexpr ParticleId kMaxRootIdIn = ParticleId{1} << (kGenerationShift - kChildBits<D> * kMaxGenerationsIn<D>);
inline constexpr ParticleId kMaxRootId = kMaxRootIdIn<2>;

inline constexpr int generation(ParticleId id) { return static_cast<int>(id >> kGenerationShift); }
inline constexpr ParticleId path(ParticleId id) { return id & kPathMask; }

/// The id of daughter a (0 .. 2^D - 1) of the particle with id `parent`.
template <int D = 2>
inline constexpr ParticleId daughter_id(ParticleId parent, unsigned a) {
  return (static_cast<ParticleId>(generation(parent) + 1) << kGenerationShift) | (path(parent) << kChildBits<D>) | a;
}

/// True when a daughter of `id` still fits in an id: its generation and its path.
template <int D = 2>
inline constexpr bool has_room_for_daughters(ParticleId id) {
  return generation(id) < kMaxGenerationsIn<D> && path(id) <= (kPathMask >> kChildBits<D>);
}

/// True for a daughter (generation > 0): it has a parent and siblings.
inline constexpr bool has_parent(ParticleId id) { return generation(id) > 0; }

/// The id of the particle that was split into `id` and its siblings (for has_parent(id) only).
template <int D = 2>
inline constexpr ParticleId parent_id(ParticleId id) {
  return (static_cast<ParticleId>(generation(id) - 1) << kGenerationShift) | (path(id) >> kChildBits<D>);
}

/// Which of its parent's daughters `id` is (0 .. 2^D - 1).
template <int D = 2>
inline constexpr unsigned sibling_index(ParticleId id) {
  return static_cast<unsigned>(id & (kChildren<D> - 1u));
}

static_assert(parent_id(daughter_id(12345, 2)) == 12345);
static_assert(sibling_index(daughter_id(12345, 3)) == 3);
static_assert(parent_id(daughter_id(daughter_id(7, 1), 3)) == daughter_id(7, 1));
static_assert(parent_id<3>(daughter_id<3>(12345, 7)) == 12345);
static_assert(sibling_index<3>(daughter_id<3>(daughter_id<3>(9, 2), 5)) == 5);

}  // namespace sph::refine
