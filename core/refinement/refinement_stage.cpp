#include "core/refinement/refinement_stage.hpp"

#include <limits>

namespace sph::refine {

namespace {

std::vector<std::size_t> level_counts(const ParticleStore<2>& store) {
  std::vector<std::size_t> per_level;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (store.kind[i] != Kind::fluid) continue;
    const auto l = static_cast<std::size_t>(std::max(0, store.level[i]));
    if (per_level.size() <= l) per_level.resize(l + 1, 0);
    ++per_level[l];
  }
  return per_level;
}

std::size_t split_with(Simulation& sim, std::vector<std::uint8_t>& marks, Pattern pattern, double rsp_k,
                       int max_level) {
  const SplitResult r = split_marked(sim.store(), marks, pattern, rsp_k, max_level, sim.settings().geometry.walls());
  sim.refresh();
  return r.refined;
}

}  // namespace

RefinementStage::RefinementStage(const RefinementSettings& settings)
    : settings_(settings), criterion_(make_criterion(settings)) {}

bool RefinementStage::after_step(Simulation& sim) {
  const auto interval = static_cast<std::uint64_t>(std::max(1, settings_.check_interval));
  if (sim.step_count() % interval != 0) return false;
  ParticleStore<2>& store = sim.store();
  std::vector<std::uint8_t> marks(store.size(), 0);
  criterion_->mark(store, marks);
  bool any = false;
  for (std::size_t i = 0; i < store.size() && !any; ++i) {
    any = marks[i] && store.kind[i] == Kind::fluid && store.level[i] < settings_.max_level;
  }
  if (!any) return false;
  const SplitResult r =
      split_marked(store, marks, settings_.pattern, settings_.rsp_k, settings_.max_level, sim.settings().geometry.walls());
  total_ += r.refined;
  log_.push_back({sim.step_count(), sim.time(), r.refined, r.shifted, level_counts(store)});
  return r.refined > 0;
}

RefinementStage& add_refinement_stage(Simulation& sim, const RefinementSettings& settings) {
  auto stage = std::make_unique<RefinementStage>(settings);
  RefinementStage& ref = *stage;
  sim.add_stage(std::move(stage));
  return ref;
}

std::size_t refine_all(Simulation& sim, Pattern pattern, double rsp_k) {
  std::vector<std::uint8_t> marks(sim.store().size(), 1);
  return split_with(sim, marks, pattern, rsp_k, std::numeric_limits<int>::max());
}

std::size_t refine_region(Simulation& sim, const Box2& box, Pattern pattern, double rsp_k) {
  std::vector<std::uint8_t> marks(sim.store().size(), 0);
  ZoneCriterion(box).mark(sim.store(), marks);
  return split_with(sim, marks, pattern, rsp_k, std::numeric_limits<int>::max());
}

}  // namespace sph::refine
