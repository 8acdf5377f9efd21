#pragma once
// The split pass between steps (section 3.2): mark -> count (1 or 2^D; ghosts 0, they are rebuilt) ->
// exclusive scan -> one gather of every field through the store's registry -> daughters written in place.
// The new particle order is fixed by the scan and the new ids by the parents' ids, so the result is the same
// at any thread count and whichever criterion marked.
#include <cstdint>
#include <vector>

#include "core/boundary/wall.hpp"
#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

/// How daughters take their density (RefinementSettings::daughter_density_rule). With `pressure_gradient`, daughter k
/// at offset o_k from its parent takes rho_k = rho + rho (g - a) . o_k / c^2(rho): the parent's density carried along
/// the pressure gradient grad p = rho (g - a) that its last evaluation's acceleration a balanced (the viscous force
/// neglected), through the equation of state (c^2 = dp/drho). At rest this is the hydrostatic gradient; copying the
/// parent's density instead (`parent`, the paper's) puts the upper daughters' pressure above the field's and the lower
/// ones' below it, by |rho g . o_k|. The offsets sum to zero (but where the wall rule shifts a pattern, along with its
/// centroid), so the family's mean density is the parent's to first order, and the pass's elastic energy changes at
/// second order only.
template <int D>
struct DaughterDensityIn {
  DaughterDensity rule = DaughterDensity::parent;
  Vec<D> gravity = Vec<D>::Zero();
  TaitEquationOfState eos{};
};

/// The density gradient daughters are given about their parent's density rho: rho (g - a) / c^2(rho) with
/// `pressure_gradient` (DaughterDensityIn), where a is the acceleration the parent's pressure gradient balanced along
/// with gravity; zero with `parent`. A split passes the parent's last evaluation's acceleration; a host's flip
/// (buffered levels, prepare_buffered_marks) passes zero, the hydrostatic part alone.
template <int D>
Vec<D> daughter_density_gradient(const DaughterDensityIn<D>& density, double rho, const Vec<D>& a) {
  if (density.rule != DaughterDensity::pressure_gradient) return Vec<D>::Zero();
  return rho * (density.gravity - a) / density.eos.sound_speed_squared(rho);
}

struct SplitResult {
  std::size_t refined = 0;  // particles split
  std::size_t shifted = 0;  // patterns shifted inward by the wall rule (centroid moved)
};

/// Splits every fluid particle with marks[i] != 0 and level < max_level into 2^D daughters (four in 2D, eight in
/// 3D) of mass m / 2^D, smoothing length h / 2 and spacing d / 2, placed by `pattern`, keeping them inside
/// `walls`. marks has store.size() entries. Daughter a of the particle with id P gets id daughter_id<D>(P, a)
/// (core/refinement/family.hpp) and level_time = `time`, and its density by `density` (DaughterDensityIn).
/// Throws std::length_error when a daughter's generation would not fit in its id (kMaxGenerationsIn<D>).
/// buffered (LevelCoupling::buffered): the parent stays, right before its daughters. marks[i] == 1 splits an active
/// particle into active daughters and makes it a shadow; marks[i] == 2 splits an active particle (which becomes a
/// host) or a buffer particle (which stays one) into buffer daughters (core/refinement/buffer.hpp). RSP takes its
/// reference among the particle's own level.
template <int D>
SplitResult split_marked(ParticleStore<D>& store, const std::vector<std::uint8_t>& marks, Pattern pattern,
                         double rsp_k, int max_level, const std::vector<Wall<D>>& walls, double time = 0.0,
                         bool buffered = false, const DaughterDensityIn<D>& density = {});

}  // namespace sph::refine
