#include "core/refinement/merge_pass.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/refinement/family.hpp"
#include "core/refinement/merge_key.hpp"
#include "parallel/parallel_for.hpp"

namespace sph::refine {

namespace {

/// True when x is in the fluid domain and at least `margin` from every wall it projects onto.
template <int D>
bool clear_of_walls(const Vec<D>& x, const Geometry<D>& geometry, const std::vector<Wall<D>>& walls, double margin) {
  if (!geometry.in_fluid_domain(x)) return false;
  for (const Wall<D>& w : walls) {
    const double dist = w.signed_distance(x);
    if (dist > -margin && dist < margin && w.projects_onto(x, margin)) return false;
  }
  return true;
}

template <int D>
struct FamilyOutcome {
  std::array<std::uint32_t, kChildren<D>> members{};  // store indices in sibling order
  std::uint32_t keeper = 0;                // the lowest store index: the merged particle goes there
  int verdict = 0;                         // 0 merged, 1 off walls, 2 would split again, 3 dispersed
  double d_kinetic = 0.0;
  Angular<D> d_angular = zero_angular<D>();
  // The merged state.
  Vec<D> x = Vec<D>::Zero(), v = Vec<D>::Zero(), vh = Vec<D>::Zero();
  double m = 0, rho = 0, rhoh = 0;
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
    double m = 0.0, vol = 0.0, volh = 0.0, ke = 0.0;
    Angular<D> lz = zero_angular<D>();
    Vec<D> mx = Vec<D>::Zero(), mv = Vec<D>::Zero(), mvh = Vec<D>::Zero();
    for (const std::uint32_t i : f.members) {  // sibling order: a fixed summation order
      const double mi = store.m[i];
      m += mi;
      mx += mi * store.x[i];
      mv += mi * store.v[i];
      mvh += mi * store.vh[i];
      vol += mi / store.rho[i];
      volh += mi / store.rhoh[i];
      ke += 0.5 * mi * store.v[i].squaredNorm();
      lz += mi * cross<D>(store.x[i], store.v[i]);
    }
    f.m = m;
    f.x = mx / m;
    f.v = mv / m;
    f.vh = mvh / m;
    f.rho = m / vol;
    f.rhoh = m / volh;
    const double d_merged = 2.0 * store.d[f.members[0]];
    // The merged particle stands for the square of side d_merged centred on it: a member outside that square
    // has drifted into another particle's place, and the merged particle would land among other particles.
    double spread = 0.0;
    for (const std::uint32_t i : f.members) spread = std::max(spread, (store.x[i] - f.x).cwiseAbs().maxCoeff());
    // It must also sit as far from a wall as the set-up puts a particle of its spacing, d_merged / 2 (less
    // rounding: a family split from such a particle merges back), where the Lennard-Jones wall force of a
    // particle of that spacing (r0 = d / 2 by default) starts; closer, it would start inside that force's range.
    if (spread > 0.5 * d_merged) {
      f.verdict = 3;
    } else if (!clear_of_walls(f.x, geometry, walls, 0.5 * d_merged * (1.0 - 1e-12))) {
      f.verdict = 1;
    } else if (would_split && would_split(f.x, f.v)) {
      f.verdict = 2;
    }
    f.d_kinetic = 0.5 * m * f.v.squaredNorm() - ke;
    f.d_angular = m * cross<D>(f.x, f.v) - lz;
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
    result.d_kinetic += f.d_kinetic;
    result.d_angular += f.d_angular;
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
    s.x[k] = f.x;
    s.v[k] = f.v;
    s.vh[k] = f.vh;
    s.m[k] = f.m;
    s.rho[k] = f.rho;
    s.rhoh[k] = f.rhoh;
    s.h[k] = 2.0 * s.h[f.members[0]];  // powers of two: the parent's h and d exactly
    s.d[k] = 2.0 * s.d[f.members[0]];
    s.level[k] = s.level[f.members[0]] - 1;
    s.id[k] = merged_id;
    s.level_time[k] = time;
    s.origin[k] = Origin::fresh_merge;
    s.tie[k].setZero();  // it took no place beside a parent (and a member's would depend on which one holds it)
    s.a[k].setZero();  // the rates are re-evaluated after the pass
    s.drho[k] = 0.0;
    s.full_a[k].setZero();
    s.full_drho[k] = 0.0;
    s.kick[k].setZero();
    s.kick_rho[k] = 0.0;
    s.jerk[k].setZero();  // no history of its own: its first step predicts from its first rates alone
    s.density_jerk[k] = 0.0;
    // Its limits are not known until then: its bin is its level's (Integrator::bin_for).
    s.stiffness[k] = 1.0;
    s.dt_limit[k] = 0.0;
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
