#pragma once
// The split pass between steps (section 3.2): mark -> count (1 or 4; ghosts 0, they are rebuilt) ->
// exclusive scan -> one gather of every field through the store's registry -> daughters written in place.
// The new particle order and the new ids are fixed by the scan, so the result is the same at any thread
// count and whichever criterion marked.
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

/// Splits every fluid particle with marks[i] != 0 and level < max_level into four daughters placed by
/// `pattern`, keeping them inside `walls`. marks has store.size() entries.
SplitResult split_marked(ParticleStore<2>& store, const std::vector<std::uint8_t>& marks, Pattern pattern,
                         double rsp_k, int max_level, const std::vector<Wall2>& walls);

}  // namespace sph::refine
