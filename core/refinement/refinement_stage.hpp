#pragma once
// Dynamic refinement as a run-time stage: every check_interval steps, the criterion marks, the split pass
// splits, then (with coarsening) the families whose members all pass the merge test and have been at their
// level for the hold time merge, and the solver rebuilds ghosts and grid and re-evaluates the rates
// (Simulation::run_stages).
// Static refinement at set-up (the paper's Fig. 1b) uses the same patterns and pass.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/refinement/criteria.hpp"
#include "core/refinement/merge_pass.hpp"
#include "core/refinement/refinement_settings.hpp"
#include "core/refinement/split_pass.hpp"
#include "core/simulation.hpp"

namespace sph::refine {

/// Families whose members all passed the merge test (and the hold) but were left split, by reason: the merged place
/// too near a wall, the merged particle would be split again, a member outside the merged particle's square
/// (dispersed), or (buffered levels) finer active fluid within the intermix reach (intermixed). A family counts once per check.
struct MergesDeclined {
  std::size_t walls = 0;
  std::size_t criterion = 0;
  std::size_t dispersed = 0;
  std::size_t intermixed = 0;
  MergesDeclined& operator+=(const MergesDeclined& o) {
    walls += o.walls;
    criterion += o.criterion;
    dispersed += o.dispersed;
    intermixed += o.intermixed;
    return *this;
  }
};

/// One line of the refinement log: what a pass did.
template <int D>
struct PassRecordIn {
  std::uint64_t step = 0;
  double time = 0.0;
  std::size_t refined = 0;
  std::size_t shifted = 0;
  std::size_t merged = 0;     // families merged (2^D into one)
  std::size_t unbuffered = 0; // buffered levels: particles whose buffer daughters left (retract_buffered)
  std::size_t refused = 0;    // marked, but left whole: a daughter's id would not fit (family.hpp's generations)
  MergesDeclined declined;    // families whose members all passed the merge test, left split, by reason
  double merge_d_kinetic = 0.0;  // kinetic energy the merges removed (J/m in 2D, J in 3D; <= 0)
  Angular<D> merge_d_angular = zero_angular<D>();  // change of angular momentum by the merges (2D: L_z)
  std::vector<std::size_t> per_level;  // fluid particles per level after the pass
};
using PassRecord = PassRecordIn<2>;

template <int D>
class RefinementStageIn final : public StageT<D> {
 public:
  explicit RefinementStageIn(const RefinementSettings& settings);
  const char* name() const override { return "refinement"; }
  bool after_step(SimulationT<D>& sim) override;

  const RefinementSettings& settings() const { return settings_; }
  const std::vector<PassRecordIn<D>>& log() const { return log_; }
  std::size_t total_refined() const { return total_; }
  std::size_t total_merged() const { return total_merged_; }
  /// Particles marked for a split and left whole because a daughter's id would not fit (kMaxGenerationsIn<D>: in
  /// cell groups a merged particle keeps a member's generation, so split-merge cycles can use them up).
  std::size_t total_refused() const { return total_refused_; }
  /// Over the run: the families that could have merged and were left split, by reason (MergesDeclined).
  const MergesDeclined& total_declined() const { return total_declined_; }
  /// Of those, the families merged on this rank with members lent by others (runs across ranks).
  std::size_t merged_across_ranks() const { return merged_across_; }

 private:
  RefinementSettings settings_;
  std::unique_ptr<CriterionIn<D>> criterion_;
  std::vector<PassRecordIn<D>> log_;
  std::size_t total_ = 0;
  std::size_t total_merged_ = 0;
  std::size_t merged_across_ = 0;
  std::size_t total_refused_ = 0;
  MergesDeclined total_declined_;
};

using RefinementStage = RefinementStageIn<2>;

/// Adds dynamic refinement to a simulation; returns the stage (owned by the simulation) for its log.
template <int D>
RefinementStageIn<D>& add_refinement_stage(SimulationT<D>& sim, const RefinementSettings& settings);

/// The merge pass on a simulation's store: merges the families all of whose members have may[i] != 0
/// (merge_families). In a distributed run, a family whose members sit on several ranks is first brought whole to one
/// of them (DomainT::lend_families), and the others remove the originals of the families that merged (collective);
/// `across`, when given, is increased by the families this rank merged so. The caller refreshes the simulation.
template <int D>
MergeResultIn<D> merge_pass(SimulationT<D>& sim, std::vector<std::uint8_t>& may,
                            const std::function<bool(const Vec<D>&, const Vec<D>&)>& would_split = {},
                            std::size_t* across = nullptr, MergeGroups groups = MergeGroups::family);

/// Static refinement at set-up: splits every fluid particle (fully refined runs) or those in a box, then
/// refreshes the simulation. Returns how many were split. (2D and 3D.)
template <int D>
std::size_t refine_all(SimulationT<D>& sim, Pattern pattern, double rsp_k);
template <int D>
std::size_t refine_region(SimulationT<D>& sim, const Box<D>& box, Pattern pattern, double rsp_k);

}  // namespace sph::refine
