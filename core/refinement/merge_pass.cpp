#include "core/refinement/merge_pass.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/refinement/family.hpp"
#include "core/refinement/merge_key.hpp"
#include "parallel/parallel_for.hpp"

namespace sph::refine {

namespace {

template <int D>
struct FamilyOutcome {
  std::array<std::uint32_t, kChildren<D>> members{};  // store indices in sibling order
  std::uint32_t keeper = 0;                // the lowest store index: the merged particle goes there
  int verdict = 0;                         // merge_verdict
  MergedStateIn<D> state;
};

}  // namespace

template <int D>
MergeResultIn<D> merge_families(ParticleStore<D>& store, const std::vector<std::uint8_t>& may_merge,
                                const Geometry<D>& geometry, double time,
                                const std::function<bool(const Vec<D>&, const Vec<D>&)>& would_split,
                                std::size_t copies_from, MergeGroups groups) {
  constexpr unsigned children = kChildren<D>;
  MergeResultIn<D> result;
  const std::size_t n = store.size();
  copies_from = std::min(copies_from, n);
  // Lent copies leave whatever happens: with no merge, by dropping the store's tail (nothing else moves).
  const auto drop_copies = [&] {
    if (copies_from < n) store.resize(copies_from);
  };
  // Candidates sorted by their merge key (core/refinement/merge_key.hpp): a group's candidates in a row, in key
  // order. Keys are unique among live particles, so the order is fixed by the data.
  const Vec<D> anchor = geometry.container.lo;
  std::vector<std::pair<MergeKey, std::uint32_t>> cand;
  for (std::size_t i = 0; i < n; ++i) {
    MergeKey key;
    if (!may_merge[i] || store.kind[i] != Kind::fluid || !merge_key<D>(store, i, groups, anchor, key)) continue;
    cand.emplace_back(key, static_cast<std::uint32_t>(i));
  }
  std::sort(cand.begin(), cand.end());
  std::vector<FamilyOutcome<D>> fam;
  for (std::size_t k = 0; k < cand.size();) {
    std::size_t e = k + 1;
    while (e < cand.size() && cand[e].first.same_group(cand[k].first)) ++e;
    if (e - k >= children) {  // the group's first 2^D (a family has no more)
      FamilyOutcome<D> f;
      for (unsigned a = 0; a < children; ++a) f.members[a] = cand[k + a].second;
      f.keeper = *std::min_element(f.members.begin(), f.members.end());
      fam.push_back(f);
    }
    k = e;
  }
  if (fam.empty()) {
    drop_copies();
    return result;
  }

  const std::vector<Wall<D>> walls = geometry.walls();
  par::parallel_for(fam.size(), [&](std::size_t r) {
    FamilyOutcome<D>& f = fam[r];
    f.state = merged_state(store, f.members);  // sibling order: a fixed summation order
    f.verdict = merge_verdict(f.state, 2.0 * store.d[f.members[0]], geometry, walls, would_split);
  });

  std::vector<std::uint8_t> drop(n, 0);
  for (const FamilyOutcome<D>& f : fam) {  // serial, in family order: the reported sums are deterministic
    if (f.verdict == 1) {
      ++result.kept_off_walls;
      continue;
    }
    if (f.verdict == 2) {
      ++result.kept_by_criterion;
      continue;
    }
    if (f.verdict == 3) {
      ++result.kept_dispersed;
      continue;
    }
    ++result.merged;
    result.d_kinetic += f.state.d_kinetic;
    result.d_angular += f.state.d_angular;
    bool lent = false;
    for (const std::uint32_t i : f.members) {
      drop[i] = i != f.keeper;
      if (i >= copies_from) {
        result.merged_copies.push_back(store.id[i]);
        lent = true;
      }
    }
    result.merged_with_copies += lent;
  }
  if (result.merged == 0) {
    drop_copies();
    return result;
  }
  for (std::size_t i = copies_from; i < n; ++i) drop[i] = 1;

  auto s = store.view();
  par::parallel_for(fam.size(), [&](std::size_t r) {
    const FamilyOutcome<D>& f = fam[r];
    if (f.verdict != 0) return;
    const std::size_t k = f.keeper;
    // The four daughters of one parent give it its id back (sibling order: members[0] is daughter 0). Any other
    // group takes the id of the member of the lowest generation (then the lowest id): ids stay unique, since that
    // member leaves, and a particle and its descendants are never alive together.
    ParticleId merged_id = parent_id<D>(s.id[f.members[0]]);
    bool siblings = has_parent(s.id[f.members[0]]);
    for (const std::uint32_t i : f.members) siblings = siblings && has_parent(s.id[i]) && parent_id<D>(s.id[i]) == merged_id;
    if (!siblings) {
      merged_id = s.id[f.members[0]];
      for (const std::uint32_t i : f.members) {
        const ParticleId id = s.id[i];
        if (generation(id) < generation(merged_id) || (generation(id) == generation(merged_id) && id < merged_id)) merged_id = id;
      }
    }
    start_merged(s, k, f.state, time);
    s.h[k] = 2.0 * s.h[f.members[0]];  // powers of two: the parent's h and d exactly
    s.d[k] = 2.0 * s.d[f.members[0]];
    s.level[k] = s.level[f.members[0]] - 1;
    s.id[k] = merged_id;
  });
  // Ghosts go too, as in the split pass: the solver rebuilds them for the new set.
  store.compact([&](std::size_t i) { return drop[i] == 0 && store.kind[i] != Kind::ghost; });
  return result;
}

template MergeResultIn<2> merge_families<2>(ParticleStore<2>&, const std::vector<std::uint8_t>&, const Geometry<2>&,
                                            double, const std::function<bool(const Vec<2>&, const Vec<2>&)>&,
                                            std::size_t, MergeGroups);
template MergeResultIn<3> merge_families<3>(ParticleStore<3>&, const std::vector<std::uint8_t>&, const Geometry<3>&,
                                            double, const std::function<bool(const Vec<3>&, const Vec<3>&)>&,
                                            std::size_t, MergeGroups);

}  // namespace sph::refine
