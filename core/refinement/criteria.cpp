#include "core/refinement/criteria.hpp"

#include <stdexcept>

#include "core/refinement/neighbour_query.hpp"
#include "parallel/parallel_for.hpp"

namespace sph::refine {

template <int D>
void VelocityCriterionIn<D>::mark(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks) const {
  const double t2 = threshold_ * threshold_;
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] == Kind::fluid && store.v[i].squaredNorm() > t2) marks[i] = 1;
  });
}

template <int D>
void VelocityCriterionIn<D>::mark_mergeable(const ParticleStore<D>& store, double horizon, std::vector<std::uint8_t>& marks) const {
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] != Kind::fluid) return;
    const double speed = store.v[i].norm();
    if (speed < merge_threshold_ && speed + horizon * store.a[i].norm() <= threshold_) marks[i] = 1;
  });
}

template <int D>
void ZoneCriterionIn<D>::mark_mergeable(const ParticleStore<D>& store, double horizon, std::vector<std::uint8_t>& marks) const {
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] != Kind::fluid) return;
    if (!zone_.contains(store.x[i]) && !zone_.contains(store.x[i] + horizon * store.v[i])) marks[i] = 1;
  });
}

template <int D>
void ZoneCriterionIn<D>::mark(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks) const {
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] == Kind::fluid && zone_.contains(store.x[i])) marks[i] = 1;
  });
}

namespace {

/// Marks the fluid particles whose count of fluid neighbours (r_ij < 2 h_ij) passes `pass(count)`.
template <int D, class Pass>
void mark_by_neighbour_count(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks, Pass&& pass) {
  const NeighbourQueryIn<D> query(store);
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] != Kind::fluid) return;
    int count = 0;
    query.for_each_fluid_neighbour(i, [&](std::size_t, double) { ++count; });
    if (pass(count)) marks[i] = 1;
  });
}

}  // namespace

template <int D>
void FewNeighboursCriterionIn<D>::mark(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks) const {
  mark_by_neighbour_count(store, marks, [&](int count) { return count < min_; });
}

template <int D>
void FewNeighboursCriterionIn<D>::mark_mergeable(const ParticleStore<D>& store, double /*horizon*/,
                                            std::vector<std::uint8_t>& marks) const {
  mark_by_neighbour_count(store, marks, [&](int count) { return count >= merge_min_; });
}

template <int D>
std::unique_ptr<CriterionIn<D>> make_criterion(const RefinementSettings& s) {
  switch (s.criterion) {
    case CriterionKind::velocity:
      return std::make_unique<VelocityCriterionIn<D>>(s.v_threshold, s.coarsening ? s.coarsening->v_threshold : 0.0);
    case CriterionKind::zone:
      return std::make_unique<ZoneCriterionIn<D>>(s.zone.fixed<D>());
    case CriterionKind::few_neighbours:
      return std::make_unique<FewNeighboursCriterionIn<D>>(s.min_neighbours,
                                                           s.coarsening ? s.coarsening->min_neighbours : 0);
  }
  return nullptr;
}

template class VelocityCriterionIn<2>;
template class VelocityCriterionIn<3>;
template class ZoneCriterionIn<2>;
template class ZoneCriterionIn<3>;
template class FewNeighboursCriterionIn<2>;
template class FewNeighboursCriterionIn<3>;
template std::unique_ptr<CriterionIn<2>> make_criterion<2>(const RefinementSettings&);
template std::unique_ptr<CriterionIn<3>> make_criterion<3>(const RefinementSettings&);

}  // namespace sph::refine
