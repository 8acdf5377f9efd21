#pragma once
// The merge pass between steps (coarsening, the inverse of the split pass): the 2^D daughters of one parent
// (four in 2D, eight in 3D) become one particle again when all may merge. Families are found through the ids
// (core/refinement/family.hpp): candidates sorted by parent id, 2^D consecutive with one parent form a family.
// The merged particle takes the parent's id, level, spacing and smoothing length back, and sits where the
// lowest store index of the family sat; the three others leave by one stream compaction. The order of the
// store and every sum (sibling order) are fixed by the data, so the result is the same at any thread count.
//
// Merged state: mass M = sum m_a; position and velocity (and the half-step velocity) the mass-weighted means,
// so mass and linear momentum are kept exactly (to rounding); density M / sum (m_a / rho_a), so the volume
// is kept. What one particle cannot hold is the family's motion about its centre of mass: the merge removes
// the kinetic energy sum 1/2 m_a |v_a - V|^2 and the angular momentum sum m_a (x_a - X) x (v_a - V); the pass
// reports both.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/boundary/wall.hpp"
#include "core/diagnostics.hpp"
#include "core/particle_store.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

template <int D>
struct MergeResultIn {
  std::size_t merged = 0;            // families merged (each 2^D particles into one)
  std::size_t kept_off_walls = 0;    // complete families left alone: their centre of mass was too close to a wall
  std::size_t kept_by_criterion = 0; // complete families left alone: the merged particle would be split again
  std::size_t kept_dispersed = 0;    // complete families left alone: a member is outside the merged particle's square
  double d_kinetic = 0.0;            // kinetic energy after - before (J/m in 2D, J in 3D), <= 0
  Angular<D> d_angular = zero_angular<D>();  // angular momentum after - before (2D: L_z)
  std::vector<ParticleId> merged_copies;     // the ids of lent copies (see below) whose family merged
  std::size_t merged_with_copies = 0;        // families merged with a lent copy among their members
};
using MergeResult = MergeResultIn<2>;

/// Merges every family whose 2^D members are fluid and have may_merge[i] != 0 (may_merge has store.size()
/// entries). A family is left alone when a member lies outside the square (cube) of side d (the merged spacing)
/// centred on the family's centre of mass (the family has dispersed: the merged particle would land among
/// others), when that centre is outside the fluid domain or closer to a wall than d / 2 (where the set-up
/// puts a particle of spacing d, and where the Lennard-Jones wall force of such a particle begins), or when
/// `would_split(X, V)` says the merged particle would be marked for a split at once. `time` is written as
/// the merged particle's level_time.
///
/// Across ranks (DomainT::lend_families), the store's particles from index `copies_from` on are copies of other
/// ranks' members, lent so that a family split over ranks is whole here. A copy merges like a member, but never holds
/// the merged particle (this rank holds the family's lowest sibling, at a lower index), and every copy leaves the
/// store; the ids of those whose family merged are returned, for their ranks to remove the originals.
template <int D>
MergeResultIn<D> merge_families(ParticleStore<D>& store, const std::vector<std::uint8_t>& may_merge,
                                const Geometry<D>& geometry, double time,
                                const std::function<bool(const Vec<D>&, const Vec<D>&)>& would_split = {},
                                std::size_t copies_from = static_cast<std::size_t>(-1),
                                MergeGroups groups = MergeGroups::family);

}  // namespace sph::refine
