#include "core/refinement/criteria.hpp"

#include "core/refinement/neighbour_query.hpp"
#include "parallel/parallel_for.hpp"

namespace sph::refine {

void VelocityCriterion::mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const {
  const double t2 = threshold_ * threshold_;
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] == Kind::fluid && store.v[i].squaredNorm() > t2) marks[i] = 1;
  });
}

void VelocityCriterion::mark_mergeable(const ParticleStore<2>& store, double horizon, std::vector<std::uint8_t>& marks) const {
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] != Kind::fluid) return;
    const double speed = store.v[i].norm();
    if (speed < merge_threshold_ && speed + horizon * store.a[i].norm() <= threshold_) marks[i] = 1;
  });
}

void ZoneCriterion::mark_mergeable(const ParticleStore<2>& store, double horizon, std::vector<std::uint8_t>& marks) const {
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] != Kind::fluid) return;
    if (!zone_.contains(store.x[i]) && !zone_.contains(store.x[i] + horizon * store.v[i])) marks[i] = 1;
  });
}

void ZoneCriterion::mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const {
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] == Kind::fluid && zone_.contains(store.x[i])) marks[i] = 1;
  });
}

namespace {

/// Marks the fluid particles whose count of fluid neighbours (r_ij < 2 h_ij) passes `pass(count)`.
template <class Pass>
void mark_by_neighbour_count(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks, Pass&& pass) {
  const NeighbourQuery query(store);
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] != Kind::fluid) return;
    int count = 0;
    query.for_each_fluid_neighbour(i, [&](std::size_t, double) { ++count; });
    if (pass(count)) marks[i] = 1;
  });
}

}  // namespace

void FewNeighboursCriterion::mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const {
  mark_by_neighbour_count(store, marks, [&](int count) { return count < min_; });
}

void FewNeighboursCriterion::mark_mergeable(const ParticleStore<2>& store, double /*horizon*/,
                                            std::vector<std::uint8_t>& marks) const {
  mark_by_neighbour_count(store, marks, [&](int count) { return count >= merge_min_; });
}

std::unique_ptr<Criterion> make_criterion(const RefinementSettings& s) {
  switch (s.criterion) {
    case CriterionKind::velocity:
      return std::make_unique<VelocityCriterion>(s.v_threshold, s.coarsening ? s.coarsening->v_threshold : 0.0);
    case CriterionKind::zone:
      return std::make_unique<ZoneCriterion>(s.zone);
    case CriterionKind::few_neighbours:
      return std::make_unique<FewNeighboursCriterion>(s.min_neighbours,
                                                      s.coarsening ? s.coarsening->min_neighbours : 0);
  }
  return nullptr;
}

}  // namespace sph::refine
