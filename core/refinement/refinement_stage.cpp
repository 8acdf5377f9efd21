#include "core/refinement/refinement_stage.hpp"

#include <algorithm>
#include <limits>

#include "core/refinement/buffer.hpp"
#include "core/refinement/family.hpp"

namespace sph::refine {

namespace {

template <int D>
std::vector<std::size_t> level_counts(const ParticleStore<D>& store) {
  std::vector<std::size_t> per_level;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (store.kind[i] != Kind::fluid || is_passive(store.role[i])) continue;  // active fluid only, as diagnostics
    const auto l = static_cast<std::size_t>(std::max(0, store.level[i]));
    if (per_level.size() <= l) per_level.resize(l + 1, 0);
    ++per_level[l];
  }
  return per_level;
}

template <int D>
std::size_t split_with(SimulationT<D>& sim, std::vector<std::uint8_t>& marks, Pattern pattern, double rsp_k,
                       int max_level) {
  const SplitResult r =
      split_marked(sim.store(), marks, pattern, rsp_k, max_level, sim.settings().geometry.walls(), sim.time());
  sim.refresh();
  return r.refined;
}

}  // namespace

template <int D>
MergeResultIn<D> merge_pass(SimulationT<D>& sim, std::vector<std::uint8_t>& may,
                            const std::function<bool(const Vec<D>&, const Vec<D>&)>& would_split, std::size_t* across,
                            MergeGroups groups) {
  ParticleStore<D>& store = sim.store();
  // Across ranks, a family split over them is brought whole to one rank: its members' copies are lent there.
  const DomainT<D>* domain = sim.domain();
  typename DomainT<D>::Lent lent;
  lent.first = store.size();
  if (domain != nullptr) lent = domain->lend_families(store, may, groups, sim.settings().geometry.container.lo);
  MergeResultIn<D> m =
      merge_families<D>(store, may, sim.settings().geometry, sim.time(), would_split, lent.first, groups);
  if (domain != nullptr) {
    domain->settle_families(store, m.merged_copies, lent);
    if (across != nullptr) *across += m.merged_with_copies;
  }
  return m;
}

template <int D>
RefinementStageIn<D>::RefinementStageIn(const RefinementSettings& settings)
    : settings_(settings), criterion_(make_criterion<D>(settings)) {}

template <int D>
bool RefinementStageIn<D>::after_step(SimulationT<D>& sim) {
  // Every check_interval steps of the finest bin: a check after the step in which their count passed a multiple
  // of the interval (with one global step, every check_interval-th step).
  const auto interval = static_cast<std::uint64_t>(std::max(1, settings_.check_interval));
  const std::uint64_t fine = sim.fine_step_count();
  if ((fine - static_cast<std::uint64_t>(sim.last_substeps())) / interval == fine / interval) return false;
  ParticleStore<D>& store = sim.store();
  std::vector<std::uint8_t> marks(store.size(), 0);
  criterion_->mark(store, marks);
  // No family flips between split and merge from one check to the next (Origin): a particle a merge made at the last
  // check is not split at this one (the merge test looked one check ahead, but an impact can still change course
  // within it), and a family a split made (or made active) at the last check does not merge at this one (a split by
  // the criterion is kept apart from a merge by the thresholds' gap, but buffered levels also split where the levels
  // mix, whatever the speed).
  for (std::size_t i = 0; i < store.size(); ++i)
    if (store.origin[i] == Origin::fresh_merge) marks[i] = 0;
  std::vector<ParticleId> split_last;  // ids, sorted: fresh_split until the end of this pass
  for (std::size_t i = 0; i < store.size(); ++i)
    if (store.origin[i] == Origin::fresh_split) split_last.push_back(store.id[i]);
  std::sort(split_last.begin(), split_last.end());
  PassRecordIn<D> rec;
  rec.step = sim.step_count();
  rec.time = sim.time();
  // A particle whose daughters' ids would not fit stays whole, and is counted: a split that could not be told
  // apart from its siblings later would break the families and the id order of every cell.
  bool any = false;
  const bool buffered = settings_.coupling == LevelCoupling::buffered;
  const DaughterDensityIn<D> density{settings_.daughter_density_rule(),
                                     sim.settings().gravity.value_or(Vec<D>::Zero()), sim.settings().eos};
  const std::size_t flips = buffered ? prepare_buffered_marks(store, marks, settings_.max_level, density) : 0;
  for (std::size_t i = 0; i < store.size(); ++i)
    if (store.origin[i] == Origin::fresh_merge) store.origin[i] = Origin::merge;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (!(marks[i] && store.kind[i] == Kind::fluid && store.level[i] < settings_.max_level)) continue;
    if (has_room_for_daughters<D>(store.id[i])) {
      any = true;
    } else {
      marks[i] = 0;
      ++rec.refused;
    }
  }
  if (any) {
    const SplitResult r = split_marked(store, marks, settings_.pattern, settings_.rsp_k, settings_.max_level,
                                       sim.settings().geometry.walls(), sim.time(), buffered, density);
    rec.refined = r.refined;
    rec.shifted = r.shifted;
  }
  if (settings_.coarsening) {
    // On the store as the split left it: daughters born in this pass are held by their level_time.
    std::vector<std::uint8_t> may(store.size(), 0);
    const double horizon = static_cast<double>(interval) * sim.dt();  // about the time to the next check
    criterion_->mark_mergeable(store, horizon, may);
    const double held_since = sim.time() - settings_.coarsening->hold_time;
    for (std::size_t i = 0; i < store.size(); ++i) {
      if (may[i] && (store.level_time[i] > held_since || store.origin[i] == Origin::fresh_split)) may[i] = 0;
    }
    const auto would_split = [&](const Vec<D>& x, const Vec<D>& v) { return criterion_->would_split(x, v); };
    if (buffered) {  // one process (the scene refuses buffered levels across ranks)
      const RetractResultIn<D> m = retract_buffered<D>(store, may, sim.settings().geometry, sim.time(), horizon, would_split,
                                                       settings_.max_level);
      rec.merged = m.merged;
      rec.declined = {m.kept_off_walls, m.kept_by_criterion, m.kept_dispersed, m.kept_intermixed};
      rec.unbuffered = m.unbuffered;
      rec.merge_d_kinetic = m.d_kinetic;
      rec.merge_d_angular = m.d_angular;
    } else {
      const MergeResultIn<D> m = merge_pass<D>(sim, may, would_split, &merged_across_, settings_.coarsening->groups);
      rec.merged = m.merged;
      rec.declined = {m.kept_off_walls, m.kept_by_criterion, m.kept_dispersed, 0};
      rec.merge_d_kinetic = m.d_kinetic;
      rec.merge_d_angular = m.d_angular;
    }
  }
  if (!split_last.empty()) {
    for (std::size_t i = 0; i < store.size(); ++i)
      if (store.origin[i] == Origin::fresh_split && std::binary_search(split_last.begin(), split_last.end(), store.id[i]))
        store.origin[i] = Origin::split;
  }
  total_refused_ += rec.refused;
  total_declined_ += rec.declined;
  // Only a split or a merge changes the particles (and asks for a refresh); a pass that refused splits is logged.
  const bool changed = rec.refined > 0 || rec.merged > 0 || rec.unbuffered > 0 || flips > 0;
  if (!changed && rec.refused == 0) return false;
  total_ += rec.refined;
  total_merged_ += rec.merged;
  rec.per_level = level_counts(store);
  log_.push_back(std::move(rec));
  return changed;
}

template <int D>
RefinementStageIn<D>& add_refinement_stage(SimulationT<D>& sim, const RefinementSettings& settings) {
  auto stage = std::make_unique<RefinementStageIn<D>>(settings);
  RefinementStageIn<D>& ref = *stage;
  sim.set_coupling(settings.coupling);
  sim.add_stage(std::move(stage));
  return ref;
}

template <int D>
std::size_t refine_all(SimulationT<D>& sim, Pattern pattern, double rsp_k) {
  std::vector<std::uint8_t> marks(sim.store().size(), 1);
  return split_with(sim, marks, pattern, rsp_k, std::numeric_limits<int>::max());
}

template <int D>
std::size_t refine_region(SimulationT<D>& sim, const Box<D>& box, Pattern pattern, double rsp_k) {
  const auto& s = sim.store();
  std::vector<std::uint8_t> marks(s.size(), 0);
  for (std::size_t i = 0; i < s.size(); ++i) marks[i] = s.kind[i] == Kind::fluid && box.contains(s.x[i]) ? 1 : 0;
  return split_with(sim, marks, pattern, rsp_k, std::numeric_limits<int>::max());
}

template MergeResultIn<2> merge_pass<2>(SimulationT<2>&, std::vector<std::uint8_t>&,
                                        const std::function<bool(const Vec<2>&, const Vec<2>&)>&, std::size_t*,
                                        MergeGroups);
template MergeResultIn<3> merge_pass<3>(SimulationT<3>&, std::vector<std::uint8_t>&,
                                        const std::function<bool(const Vec<3>&, const Vec<3>&)>&, std::size_t*,
                                        MergeGroups);
template class RefinementStageIn<2>;
template class RefinementStageIn<3>;
template RefinementStageIn<2>& add_refinement_stage<2>(SimulationT<2>&, const RefinementSettings&);
template RefinementStageIn<3>& add_refinement_stage<3>(SimulationT<3>&, const RefinementSettings&);
template std::size_t refine_all<2>(SimulationT<2>&, Pattern, double);
template std::size_t refine_all<3>(SimulationT<3>&, Pattern, double);
template std::size_t refine_region<2>(SimulationT<2>&, const Box<2>&, Pattern, double);
template std::size_t refine_region<3>(SimulationT<3>&, const Box<3>&, Pattern, double);

}  // namespace sph::refine
