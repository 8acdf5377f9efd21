#pragma once
// Settings of dynamic refinement (section 3; PHYSICS.md "Refinement").
#include <optional>

#include "core/boundary/wall.hpp"
#include "core/types.hpp"

namespace sph::refine {

/// Where daughters go: the axis-aligned square (AAP) or the square rotated towards and scaled by the
/// neighbour of largest F_ij = d_ij / r_ij (RSP), side s = k d^{l_i} / F_ij.
enum class Pattern { aap, rsp };

/// Which particles get marked. The split pass never knows which criterion marked a particle.
enum class CriterionKind {
  velocity,       // |v_i| > v_threshold (the paper's)
  zone,           // x_i inside a fixed box
  few_neighbours  // fewer than min_neighbours fluid neighbours within 2 h_ij
};

/// Coarsening: the four daughters of a parent merge back into one when all four have been at their level for
/// hold_time and all four pass the merge test of the criterion, which is stricter than the split test
/// (hysteresis): velocity |v| < v_threshold (below the split threshold); zone: outside the zone;
/// few_neighbours: at least min_neighbours fluid neighbours (above the split count).
/// Which particles merge into one (core/refinement/merge_pass.hpp): the 2^D daughters of one parent, or any 2^D
/// particles of one level (and spacing) that lie in one cell of a lattice of the merged spacing.
enum class MergeGroups { family, cell };

/// effects.refinement.daughter_density: what density the daughters of a split take (core/refinement/split_pass.hpp).
/// `parent`: the parent's (the paper's). `pressure_gradient`: the parent's, carried to each daughter's place along
/// the pressure gradient the parent's momentum balance gives, so that a split in still water leaves the hydrostatic
/// field as it is.
enum class DaughterDensity { parent, pressure_gradient };

struct CoarseningSettings {
  double v_threshold = 5.0;  // m/s
  int min_neighbours = 16;
  double hold_time = 0.5;    // s
  MergeGroups groups = MergeGroups::family;
  bool operator==(const CoarseningSettings&) const = default;
};

struct RefinementSettings {
  CriterionKind criterion = CriterionKind::velocity;
  double v_threshold = 10.0;  // m/s
  AnyBox zone;  // the scene's dimension
  int min_neighbours = 8;
  Pattern pattern = Pattern::aap;
  double rsp_k = 1.0;       // 1/2 as printed in the paper, 1 the consistent reading
  int check_interval = 100; // steps between checks
  int max_level = 1;        // daughters of level max_level are never refined
  std::optional<CoarseningSettings> coarsening;  // none: nothing ever merges
  LevelCoupling coupling = LevelCoupling::mixed;  // core/types.hpp, core/refinement/buffer.hpp
  std::optional<DaughterDensity> daughter_density;  // none: pressure_gradient with buffered, parent with mixed
  DaughterDensity daughter_density_rule() const {
    return daughter_density.value_or(coupling == LevelCoupling::buffered ? DaughterDensity::pressure_gradient
                                                                          : DaughterDensity::parent);
  }
  bool operator==(const RefinementSettings&) const = default;
};

}  // namespace sph::refine
