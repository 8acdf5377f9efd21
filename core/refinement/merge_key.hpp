#pragma once
// Which merge group a coarsening candidate belongs to (coarsening.groups), in one place for the merge pass and
// for the ranks that bring a group split over them together (DomainT::lend_families).
//   - family: the 2^D daughters of one parent (the group is the parent id, the order the sibling index);
//   - cell: the particles of one level, spacing and smoothing length in one cell of side 2 d (the merged spacing)
//     on the lattice anchored at the container's low corner (the order is the id). A cell's first 2^D candidates
//     by id merge.
// A group merges when it has at least 2^D candidates, its first 2^D in key order; a family never has more.
#include <array>
#include <bit>
#include <cmath>
#include <compare>
#include <cstdint>

#include "core/particle_store.hpp"
#include "core/refinement/family.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

struct MergeKey {
  std::array<std::uint64_t, 6> group{};  // family: {parent id}; cell: {level, d, h, cell coordinates}
  ParticleId order = 0;                  // family: sibling index; cell: id
  auto operator<=>(const MergeKey&) const = default;
  bool same_group(const MergeKey& o) const { return group == o.group; }
};

/// The key of fluid particle i under `groups`; false when it cannot merge so (family: a particle of the set-up, with
/// no parent; cell: level 0).
template <int D>
bool merge_key(const ParticleStore<D>& s, std::size_t i, MergeGroups groups, const Vec<D>& anchor, MergeKey& key) {
  key = MergeKey{};
  if (groups == MergeGroups::family) {
    if (!has_parent(s.id[i])) return false;
    key.group[0] = parent_id<D>(s.id[i]);
    key.order = sibling_index<D>(s.id[i]);
    return true;
  }
  if (s.level[i] < 1) return false;
  key.group[0] = static_cast<std::uint64_t>(s.level[i]);
  key.group[1] = std::bit_cast<std::uint64_t>(s.d[i]);  // positive doubles order as their bits
  key.group[2] = std::bit_cast<std::uint64_t>(s.h[i]);
  const double inv = 1.0 / (2.0 * s.d[i]);
  for (int k = 0; k < D; ++k) {
    const auto c = static_cast<std::int64_t>(std::floor((s.x[i][k] - anchor[k]) * inv));
    key.group[3 + static_cast<std::size_t>(k)] = static_cast<std::uint64_t>(c) ^ (std::uint64_t{1} << 63);  // keeps the order
  }
  key.order = s.id[i];
  return true;
}

}  // namespace sph::refine
