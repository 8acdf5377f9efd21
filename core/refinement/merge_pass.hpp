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
#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/boundary/wall.hpp"
#include "core/diagnostics.hpp"
#include "core/particle_store.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

/// True when x is in the fluid domain and at least `margin` from every wall it projects onto: where a merged particle
/// of spacing 2 margin may sit (the set-up puts such a particle no closer to a wall).
template <int D>
bool clear_of_walls(const Vec<D>& x, const Geometry<D>& geometry, const std::vector<Wall<D>>& walls, double margin) {
  if (!geometry.in_fluid_domain(x)) return false;
  for (const Wall<D>& w : walls) {
    const double dist = w.signed_distance(x);
    if (dist > -margin && dist < margin && w.projects_onto(x, margin)) return false;
  }
  return true;
}

/// What 2^D particles become when they merge: mass M = sum m_a; position and velocity (and the half-step velocity)
/// the mass-weighted means; density M / sum (m_a / rho_a) (and the same of rhoh). Summed in the members' order.
template <int D>
struct MergedStateIn {
  double m = 0.0, rho = 0.0, rhoh = 0.0;
  Vec<D> x = Vec<D>::Zero(), v = Vec<D>::Zero(), vh = Vec<D>::Zero();
  double d_kinetic = 0.0;                     // kinetic energy after - before, <= 0
  Angular<D> d_angular = zero_angular<D>();   // angular momentum after - before
  double spread = 0.0;                        // the largest |x_a - X| in any axis
};

template <int D, class Members>
MergedStateIn<D> merged_state(const ParticleStore<D>& store, const Members& members) {
  MergedStateIn<D> f;
  double vol = 0.0, volh = 0.0, ke = 0.0;
  Angular<D> lz = zero_angular<D>();
  Vec<D> mx = Vec<D>::Zero(), mv = Vec<D>::Zero(), mvh = Vec<D>::Zero();
  for (const auto i : members) {
    const double mi = store.m[i];
    f.m += mi;
    mx += mi * store.x[i];
    mv += mi * store.v[i];
    mvh += mi * store.vh[i];
    vol += mi / store.rho[i];
    volh += mi / store.rhoh[i];
    ke += 0.5 * mi * store.v[i].squaredNorm();
    lz += mi * cross<D>(store.x[i], store.v[i]);
  }
  f.x = mx / f.m;
  f.v = mv / f.m;
  f.vh = mvh / f.m;
  f.rho = f.m / vol;
  f.rhoh = f.m / volh;
  for (const auto i : members) f.spread = std::max(f.spread, (store.x[i] - f.x).cwiseAbs().maxCoeff());
  f.d_kinetic = 0.5 * f.m * f.v.squaredNorm() - ke;
  f.d_angular = f.m * cross<D>(f.x, f.v) - lz;
  return f;
}

/// Store slot k becomes the particle a merge has just made (merge_families, and retract_buffered in
/// core/refinement/buffer.hpp): the merged state, born at `time`, marked fresh (not split at the next check), with no
/// rates, step history or limits of its own until the evaluation after the pass; its bin is its level's
/// (Integrator::bin_for). Its level, h, d, id and role are the caller's.
template <int D>
void start_merged(ParticleView<D> s, std::size_t k, const MergedStateIn<D>& state, double time) {
  s.x[k] = state.x;
  s.v[k] = state.v;
  s.vh[k] = state.vh;
  s.m[k] = state.m;
  s.rho[k] = state.rho;
  s.rhoh[k] = state.rhoh;
  s.level_time[k] = time;
  s.origin[k] = Origin::fresh_merge;
  s.tie[k].setZero();  // it took no place beside a parent (and a member's would depend on which one holds it)
  s.a[k].setZero();  // the rates are re-evaluated after the pass
  s.drho[k] = 0.0;
  s.full_a[k].setZero();
  s.full_drho[k] = 0.0;
  s.kick[k].setZero();
  s.kick_rho[k] = 0.0;
  s.jerk[k].setZero();  // no history of its own: its first step predicts from its first rates alone
  s.density_jerk[k] = 0.0;
  s.stiffness[k] = 1.0;
  s.dt_limit[k] = 0.0;
}

/// Why a group that may merge stays apart: 0 it merges, 1 its centre is off the fluid domain or too close to a wall,
/// 2 the merged particle would be split again at once, 3 it has dispersed.
///   - The merged particle stands for the square (cube) of side d_merged centred on it: a member outside it has
///     drifted into another particle's place, and the merged particle would land among other particles.
///   - It must sit as far from a wall as the set-up puts a particle of its spacing, d_merged / 2 (less rounding: a
///     family split from such a particle merges back), where the Lennard-Jones wall force of a particle of that
///     spacing (r0 = d / 2 by default) starts; closer, it would start inside that force's range.
template <int D, class WouldSplit>
int merge_verdict(const MergedStateIn<D>& f, double d_merged, const Geometry<D>& geometry,
                  const std::vector<Wall<D>>& walls, const WouldSplit& would_split) {
  if (f.spread > 0.5 * d_merged) return 3;
  if (!clear_of_walls(f.x, geometry, walls, 0.5 * d_merged * (1.0 - 1e-12))) return 1;
  if (would_split && would_split(f.x, f.v)) return 2;
  return 0;
}

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
