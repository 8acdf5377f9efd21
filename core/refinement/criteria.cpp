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

void ZoneCriterion::mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const {
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] == Kind::fluid && zone_.contains(store.x[i])) marks[i] = 1;
  });
}

void FewNeighboursCriterion::mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const {
  const NeighbourQuery query(store);
  par::parallel_for(store.size(), [&](std::size_t i) {
    if (store.kind[i] != Kind::fluid) return;
    int count = 0;
    query.for_each_fluid_neighbour(i, [&](std::size_t, double) { ++count; });
    if (count < min_) marks[i] = 1;
  });
}

std::unique_ptr<Criterion> make_criterion(const RefinementSettings& s) {
  switch (s.criterion) {
    case CriterionKind::velocity:
      return std::make_unique<VelocityCriterion>(s.v_threshold);
    case CriterionKind::zone:
      return std::make_unique<ZoneCriterion>(s.zone);
    case CriterionKind::few_neighbours:
      return std::make_unique<FewNeighboursCriterion>(s.min_neighbours);
  }
  return nullptr;
}

}  // namespace sph::refine
