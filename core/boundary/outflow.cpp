#include "core/boundary/outflow.hpp"

#include "parallel/parallel_for.hpp"

namespace sph {

template <int D>
RemovedFluid remove_outflow(ParticleStore<D>& store, const Geometry<D>& geometry) {
  RemovedFluid removed;
  if (!geometry.open_top) return removed;
  const auto leaves = [&](std::size_t i) {
    return store.kind[i] == Kind::fluid && !geometry.in_fluid_domain(store.x[i]) &&
           geometry.left_through_open_top(store.x[i], store.vh[i]);
  };
  removed.particles = par::sum(store.size(), std::uint64_t{0}, [&](std::size_t i) { return std::uint64_t{leaves(i)}; });
  if (removed.particles == 0) return removed;
  // Rare (a step where fluid leaves): the mass in store order, serially, then one compaction.
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (leaves(i)) removed.mass.add(store.m[i]);
  }
  store.compact([&](std::size_t i) { return !leaves(i); });
  return removed;
}

template RemovedFluid remove_outflow<2>(ParticleStore<2>&, const Geometry<2>&);
template RemovedFluid remove_outflow<3>(ParticleStore<3>&, const Geometry<3>&);

}  // namespace sph
