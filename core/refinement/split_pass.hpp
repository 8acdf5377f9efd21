#pragma once
// The split pass between steps (section 3.2): mark -> count (1 or 2^D; ghosts 0, they are rebuilt) ->
// exclusive scan -> one gather of every field through the store's registry -> daughters written in place.
// The new particle order is fixed by the scan and the new ids by the parents' ids, so the result is the same
// at any thread count and whichever criterion marked.
#include <cstdint>
#include <vector>

#include "core/boundary/wall.hpp"
#include "core/particle_store.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

struct SplitResult {
  std::size_t refined = 0;  // particles split
  std::size_t shifted = 0;  // patterns shifted inward by the wall rule (centroid moved)
};

/// Splits every fluid particle with marks[i] != 0 and level < max_level into 2^D daughters (four in 2D, eight in
/// 3D) of mass m / 2^D, smoothing length h / 2 and spacing d / 2, placed by `pattern`, keeping them inside
/// `walls`. marks has store.size() entries. Daughter a of the particle with id P gets id daughter_id<D>(P, a)
/// (core/refinement/family.hpp) and level_time = `time`.
/// Throws std::length_error when a daughter's generation would not fit in its id (kMaxGenerationsIn<D>).
/// buffered (LevelCoupling::buffered): the parent stays, right before its daughters. marks[i] == 1 splits an active
/// particle into active daughters and makes it a shadow; marks[i] == 2 splits an active particle (which becomes a
/// host) or a buffer particle (which stays one) into buffer daughters (core/refinement/buffer.hpp). RSP takes its
/// reference among the particle's own level.
template <int D>
SplitResult split_marked(ParticleStore<D>& store, const std::vector<std::uint8_t>& marks, Pattern pattern,
                         double rsp_k, int max_level, const std::vector<Wall<D>>& walls, double time = 0.0,
                         bool buffered = false);

}  // namespace sph::refine
