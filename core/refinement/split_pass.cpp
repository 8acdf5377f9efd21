#include "core/refinement/split_pass.hpp"

#include <optional>
#include <stdexcept>
#include <string>

#include "core/refinement/family.hpp"
#include "core/refinement/patterns.hpp"
#include "parallel/compaction.hpp"
#include "parallel/parallel_for.hpp"

namespace sph::refine {

template <int D>
SplitResult split_marked(ParticleStore<D>& store, const std::vector<std::uint8_t>& marks, Pattern pattern,
                         double rsp_k, int max_level, const std::vector<Wall<D>>& walls, double time,
                         bool buffered, const DaughterDensityIn<D>& density) {
  constexpr unsigned children = kChildren<D>;
  const std::size_t n = store.size();
  auto splits = [&](std::size_t i) {
    return marks[i] != 0 && store.kind[i] == Kind::fluid && store.level[i] < max_level &&
           (!buffered || store.role[i] == Role::active || (store.role[i] == Role::buffer && marks[i] == 2));
  };
  // Offsets of the daughters, computed on the store as it is (RSP needs the neighbours), indexed by the
  // rank of the split particle.
  std::vector<std::uint32_t> rank_offsets;
  const std::vector<std::uint32_t> split_index =
      par::expansion_map(n, [&](std::size_t i) { return splits(i) ? 1u : 0u; }, &rank_offsets);
  const std::size_t count = split_index.size();
  SplitResult result;
  result.refined = count;
  if (count == 0) {
    // Still drop ghosts so the pass always leaves the same kind of store.
    store.compact([&](std::size_t i) { return store.kind[i] != Kind::ghost; });
    return result;
  }
  for (const std::uint32_t i : split_index) {  // a daughter's id must hold its generation and its path
    const ParticleId id = store.id[i];
    if (!has_room_for_daughters<D>(id)) {
      throw std::length_error("split: particle id " + std::to_string(id) + " has no room for a daughter's id (" +
                              std::to_string(kMaxGenerationsIn<D>) + " generations at most)");
    }
  }
  std::vector<OffsetsIn<D>> offsets(count);
  std::vector<std::uint8_t> shifted(count, 0);
  {
    std::optional<NeighbourQueryIn<D>> query;
    if (pattern == Pattern::rsp) query.emplace(store);
    par::parallel_for(count, [&](std::size_t r) {
      const std::size_t i = split_index[r];
      OffsetsIn<D> o = pattern == Pattern::aap
                      ? axis_aligned_pattern<D>(store.d[i])
                      : rotated_scaled_pattern(store.d[i], find_reference(store, *query, i, buffered), rsp_k);
      shifted[r] = keep_inside_walls(store.x[i], o, walls, daughter_wall_margin(store.d[i])) ? 1 : 0;
      offsets[r] = o;
    });
  }
  for (std::uint8_t s : shifted) result.shifted += s;

  std::vector<std::uint32_t> out_offsets;
  const std::vector<std::uint32_t> src = par::expansion_map(
      n,
      [&](std::size_t i) -> std::uint32_t {
        if (store.kind[i] == Kind::ghost) return 0;
        return splits(i) ? children + (buffered ? 1u : 0u) : 1u;
      },
      &out_offsets);
  store.gather(src);
  auto s = store.view();
  par::parallel_for(count, [&](std::size_t r) {
    const std::size_t i = split_index[r];  // index before the gather
    const std::size_t parent_at = out_offsets[i];
    const std::size_t first = parent_at + (buffered ? 1 : 0);
    const Vec<D> xi = s.x[first];
    const bool to_buffer = buffered && marks[i] == 2;
    if (buffered && s.role[parent_at] != Role::buffer) s.role[parent_at] = to_buffer ? Role::host : Role::shadow;
    // 1 / 2^D is exact, so m / 2^D is m times it (0.25 m in 2D, as the paper's m/4).
    const double m = (1.0 / static_cast<double>(children)) * s.m[first], h = 0.5 * s.h[first], d = 0.5 * s.d[first];
    const std::int32_t level = s.level[first] + 1;
    const ParticleId parent = s.id[first];
    // The parent's density, and the density gradient its last evaluation balanced (zero with the paper's rule).
    const double rho = s.rho[first], rhoh = s.rhoh[first];
    const Vec<D> grad_rho = daughter_density_gradient(density, rho, Vec<D>(s.a[first]));
    for (std::size_t a = 0; a < children; ++a) {
      const std::size_t k = first + a;
      s.x[k] = xi + offsets[r][a];
      s.tie[k] = offsets[r][a];
      if (density.rule == DaughterDensity::pressure_gradient) {
        const double change = grad_rho.dot(offsets[r][a]);
        s.rho[k] = rho + change;
        s.rhoh[k] = rhoh + change;
        s.p[k] = density.eos.pressure(s.rho[k]);
      }
      s.m[k] = m;
      s.h[k] = h;
      s.d[k] = d;
      s.level[k] = level;
      s.id[k] = daughter_id<D>(parent, static_cast<unsigned>(a));
      s.level_time[k] = time;
      s.origin[k] = Origin::fresh_split;
      // The parent's limits are not the daughters': until their first evaluation their bin is their level's
      // (Integrator::bin_for), as for a merged particle.
      s.stiffness[k] = 1.0;
      s.dt_limit[k] = 0.0;
      s.role[k] = to_buffer ? Role::buffer : Role::active;
    }
  });
  return result;
}

template SplitResult split_marked<2>(ParticleStore<2>&, const std::vector<std::uint8_t>&, Pattern, double, int,
                                     const std::vector<Wall<2>>&, double, bool,
                                     const DaughterDensityIn<2>&);
template SplitResult split_marked<3>(ParticleStore<3>&, const std::vector<std::uint8_t>&, Pattern, double, int,
                                     const std::vector<Wall<3>>&, double, bool,
                                     const DaughterDensityIn<3>&);

}  // namespace sph::refine
