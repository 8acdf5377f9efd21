#include "core/refinement/buffer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "core/refinement/family.hpp"
#include "core/refinement/points.hpp"

namespace sph::refine {

template <int D>
void tie_buffers(ParticleStore<D>& store) {
  const std::size_t n = store.size();
  std::vector<std::pair<ParticleId, std::size_t>> hosts;  // fluid hosts and buffers (a buffer can host buffers)
  int top = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (store.kind[i] != Kind::fluid) continue;
    if (store.role[i] == Role::host || store.role[i] == Role::buffer) hosts.emplace_back(store.id[i], i);
    if (store.role[i] == Role::buffer) top = std::max(top, static_cast<int>(store.level[i]));
  }
  if (hosts.empty()) return;
  std::sort(hosts.begin(), hosts.end());
  auto view = store.view();
  for (int l = 1; l <= top; ++l) {
    par::parallel_for(n, [&](std::size_t i) {
      if (view.kind[i] != Kind::fluid || view.role[i] != Role::buffer || view.level[i] != l) return;
      const ParticleId parent = parent_id<D>(view.id[i]);
      const auto it = std::lower_bound(hosts.begin(), hosts.end(), std::make_pair(parent, std::size_t{0}));
      if (it == hosts.end() || it->first != parent) return;
      view.x[i] = view.x[it->second] + view.tie[i];
    });
  }
}

template <int D>
void flip_daughter(ParticleStore<D>& s, std::size_t host, std::size_t k, const DaughterDensityIn<D>& density) {
  s.v[k] = s.v[host];
  s.vh[k] = s.vh[host];
  s.v_open[k] = s.v_open[host];
  s.a[k] = s.a[host];
  s.full_a[k] = s.full_a[host];
  s.kick[k] = s.kick[host];
  s.jerk[k] = s.jerk[host];
  s.drho[k] = s.drho[host];
  s.full_drho[k] = s.full_drho[host];
  s.kick_rho[k] = s.kick_rho[host];
  s.density_jerk[k] = s.density_jerk[host];
  const double change = daughter_density_gradient<D>(density, s.rho[host], Vec<D>::Zero()).dot(s.tie[k]);
  s.rho[k] = s.rho[host] + change;
  s.rhoh[k] = s.rhoh[host] + change;
  s.rho_open[k] = s.rho_open[host] + change;
  s.p[k] = density.eos.pressure(s.rho[k]);
}

template <int D>
std::size_t prepare_buffered_marks(ParticleStore<D>& store, std::vector<std::uint8_t>& marks, int max_level,
                                   const DaughterDensityIn<D>& density) {
  const std::size_t n = store.size();
  const auto fluid = [&](std::size_t i) { return store.kind[i] == Kind::fluid; };
  std::unordered_set<ParticleId> parents;  // ids of the particles that have daughters
  for (std::size_t i = 0; i < n; ++i) {
    if (fluid(i) && has_parent(store.id[i])) parents.insert(parent_id<D>(store.id[i]));
  }
  // Fluid of two levels that a flow has mixed: an active particle of level l with an active particle of level l + 1
  // within kIntermixReach d_l of it shares its place with the finer level, so it is marked as if the zone covered it
  // (a host turns into a shadow below, a particle without daughters is split). Decided on the store as it came.
  std::vector<std::uint8_t> mixed(n, 0);
  for (int l = 0; l < max_level; ++l) {
    double reach = 0.0;
    detail::Points<D> finer;
    for (std::size_t i = 0; i < n; ++i) {
      if (!fluid(i)) continue;
      if (store.level[i] == l) reach = std::max(reach, kIntermixReach * store.d[i]);
      if (store.level[i] == l + 1 && !is_passive(store.role[i])) finer.add(store.x[i]);
    }
    if (!(reach > 0.0) || finer.empty()) continue;
    finer.sort(reach);
    for (std::size_t i = 0; i < n; ++i) {
      if (fluid(i) && store.level[i] == l && !is_passive(store.role[i]) &&
          finer.near(store.x[i], kIntermixReach * store.d[i])) {
        mixed[i] = 1;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) marks[i] = marks[i] || mixed[i];
  // A marked host: its zone now covers it. It turns into a shadow, and its daughters take over as active with its
  // state, as a split's daughters take their parent's (flip_daughter).
  std::unordered_map<ParticleId, std::size_t> flipped;  // host id -> index
  for (std::size_t i = 0; i < n; ++i) {
    if (marks[i] && fluid(i) && store.level[i] < max_level && store.role[i] == Role::host) {
      store.role[i] = Role::shadow;
      flipped.emplace(store.id[i], i);
    }
  }
  if (!flipped.empty()) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!(fluid(i) && store.role[i] == Role::buffer && has_parent(store.id[i]))) continue;
      const auto host = flipped.find(parent_id<D>(store.id[i]));
      if (host == flipped.end()) continue;
      // A daughter with buffer daughters of its own (a level-1 buffer particle hosting level 2) becomes their host.
      store.role[i] = parents.count(store.id[i]) != 0 ? Role::host : Role::active;
      store.origin[i] = Origin::fresh_split;  // its family does not merge at the next check
      flip_daughter(store, host->second, i, density);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (marks[i] && (!fluid(i) || store.role[i] != Role::active || parents.count(store.id[i]) != 0)) marks[i] = 0;
  }
  // Per level l: where level l + 1 is active, and where it is about to be (the parents marked at level l, whose
  // daughters will sit within half a diagonal of the pattern's side, at most d_l, from them: the reach grows by that,
  // so that the band a pass gives is not widened again at the next check, when the daughters are there).
  const double half_diagonal = 0.5 * std::sqrt(static_cast<double>(D));
  for (int l = 0; l < max_level; ++l) {
    double reach = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (fluid(i) && store.level[i] == l) reach = std::max(reach, (1.0 + half_diagonal) * store.d[i] + store.h[i]);
    }
    if (!(reach > 0.0)) continue;
    detail::Points<D> active, marked;
    for (std::size_t i = 0; i < n; ++i) {
      if (!fluid(i)) continue;
      if (store.level[i] == l + 1 && !is_passive(store.role[i])) active.add(store.x[i]);
      if (store.level[i] == l && marks[i] == 1) marked.add(store.x[i]);
    }
    if (active.empty() && marked.empty()) continue;
    active.sort(reach);
    marked.sort(reach);
    for (std::size_t i = 0; i < n; ++i) {
      if (!fluid(i) || store.level[i] != l || marks[i] != 0) continue;
      if (!(store.role[i] == Role::active || store.role[i] == Role::buffer) || parents.count(store.id[i]) != 0) continue;
      const double to_daughters = store.h[i] + store.d[i];
      if (active.near(store.x[i], to_daughters) || marked.near(store.x[i], to_daughters + half_diagonal * store.d[i])) {
        marks[i] = 2;
      }
    }
  }
  return flipped.size();
}

namespace {

/// Fluid particles that have a parent, as (parent id, sibling index, store index), sorted: a parent's daughters in a
/// row, in sibling order.
template <int D>
class Daughters {
 public:
  Daughters(const ParticleStore<D>& store, const std::vector<std::uint8_t>& gone) {
    for (std::size_t i = 0; i < store.size(); ++i) {
      if (store.kind[i] != Kind::fluid || gone[i] || !has_parent(store.id[i])) continue;
      rows_.push_back({parent_id<D>(store.id[i]), sibling_index<D>(store.id[i]), static_cast<std::uint32_t>(i)});
    }
    std::sort(rows_.begin(), rows_.end(), [](const Row& a, const Row& b) {
      return a.parent != b.parent ? a.parent < b.parent : a.sibling < b.sibling;
    });
  }
  /// The store indices of the daughters of `parent`, in sibling order.
  std::vector<std::uint32_t> of(ParticleId parent) const {
    auto it = std::lower_bound(rows_.begin(), rows_.end(), parent, [](const Row& r, ParticleId p) { return r.parent < p; });
    std::vector<std::uint32_t> out;
    for (; it != rows_.end() && it->parent == parent; ++it) out.push_back(it->index);
    return out;
  }

 private:
  struct Row {
    ParticleId parent;
    unsigned sibling;
    std::uint32_t index;
  };
  std::vector<Row> rows_;
};

}  // namespace

template <int D>
RetractResultIn<D> retract_buffered(ParticleStore<D>& store, const std::vector<std::uint8_t>& may,
                                    const Geometry<D>& geometry, double time, double horizon,
                                    const std::function<bool(const Vec<D>&, const Vec<D>&)>& would_split, int max_level) {
  constexpr unsigned children = kChildren<D>;
  RetractResultIn<D> result;
  const std::size_t n = store.size();
  std::vector<std::uint8_t> gone(n, 0);
  const auto fluid = [&](std::size_t i) { return store.kind[i] == Kind::fluid && !gone[i]; };
  const auto active = [&](std::size_t i) { return fluid(i) && !is_passive(store.role[i]); };

  // Shadows whose daughters may all merge.
  struct Family {
    std::uint32_t shadow = 0;
    std::array<std::uint32_t, children> members{};
    MergedStateIn<D> state;
    int verdict = 0;  // merge_verdict, or 4: mixed with the finer level
  };
  std::vector<Family> fam;
  {
    const Daughters<D> daughters(store, gone);
    for (std::size_t i = 0; i < n; ++i) {
      if (!fluid(i) || store.role[i] != Role::shadow) continue;
      const std::vector<std::uint32_t> d = daughters.of(store.id[i]);
      if (d.size() != children) continue;
      bool all = true;
      // Active daughters without daughters of their own (a host's buffer daughters made active keep any band they
      // hosted), so that no particle is left without its parent.
      for (const std::uint32_t a : d)
        all = all && store.role[a] == Role::active && may[a] && store.level[a] == store.level[i] + 1 &&
              daughters.of(store.id[a]).empty();
      if (!all) continue;
      Family f;
      f.shadow = static_cast<std::uint32_t>(i);
      std::copy(d.begin(), d.end(), f.members.begin());
      fam.push_back(f);
    }
  }
  const std::vector<Wall<D>> walls = geometry.walls();
  par::parallel_for(fam.size(), [&](std::size_t r) {
    Family& f = fam[r];
    f.state = merged_state(store, f.members);  // sibling order
    f.verdict = merge_verdict(f.state, store.d[f.shadow], geometry, walls, would_split);
  });
  // Not where the finer level stays mixed in, now or by the next check: an active particle of level l + 1 that does
  // not merge within kIntermixReach d_l of the merged place would have it split again at the next check
  // (prepare_buffered_marks), and so would one that could come that near before it: the reach grows by horizon
  // (|v_merged| + the fastest such particle's speed). (Each particle's own speed instead let a merged particle be split
  // at the next check in CoarseningFlips/buffered: speeds change within a check.) Those that merge are left out, to a
  // fixed point (a family kept back keeps its members in).
  std::vector<std::uint8_t> merging(n, 0);
  for (bool again = true; again;) {
    again = false;
    std::fill(merging.begin(), merging.end(), 0);
    for (const Family& f : fam)
      if (f.verdict == 0)
        for (const std::uint32_t a : f.members) merging[a] = 1;
    for (int l = 0; l < max_level; ++l) {
      detail::Points<D> finer;
      double fastest = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        if (!(active(i) && store.level[i] == l + 1 && !merging[i])) continue;
        finer.add(store.x[i]);
        fastest = std::max(fastest, store.v[i].norm());
      }
      if (finer.empty()) continue;
      const auto reach = [&](const Family& f) {
        return kIntermixReach * store.d[f.shadow] + horizon * (f.state.v.norm() + fastest);
      };
      double edge = 0.0;
      for (const Family& f : fam)
        if (f.verdict == 0 && store.level[f.shadow] == l) edge = std::max(edge, reach(f));
      if (!(edge > 0.0)) continue;
      finer.sort(edge);
      for (Family& f : fam) {
        if (f.verdict != 0 || store.level[f.shadow] != l) continue;
        if (finer.near(f.state.x, reach(f))) {
          f.verdict = 4;
          again = true;
        }
      }
    }
  }
  for (const Family& f : fam) {  // serial, in the shadows' order: the reported sums are deterministic
    switch (f.verdict) {
      case 0:
        ++result.merged;
        result.d_kinetic += f.state.d_kinetic;
        result.d_angular += f.state.d_angular;
        break;
      case 1: ++result.kept_off_walls; break;
      case 2: ++result.kept_by_criterion; break;
      case 3: ++result.kept_dispersed; break;
      default: ++result.kept_intermixed; break;
    }
  }
  // The merged shadows: a host where active fluid of level l + 1 that stays is within its daughters' support, else
  // plain active.
  std::vector<std::uint8_t> keep_band(fam.size(), 0);
  for (int l = 0; l < max_level; ++l) {
    detail::Points<D> staying;
    double reach = 0.0;
    for (const Family& f : fam)
      if (f.verdict == 0 && store.level[f.shadow] == l) reach = std::max(reach, store.h[f.shadow] + store.d[f.shadow]);
    if (!(reach > 0.0)) continue;
    for (std::size_t i = 0; i < n; ++i)
      if (active(i) && store.level[i] == l + 1 && !merging[i]) staying.add(store.x[i]);
    if (staying.empty()) continue;
    staying.sort(reach);
    for (std::size_t r = 0; r < fam.size(); ++r) {
      const Family& f = fam[r];
      if (f.verdict == 0 && store.level[f.shadow] == l)
        keep_band[r] = staying.near(f.state.x, store.h[f.shadow] + store.d[f.shadow]);
    }
  }
  auto s = store.view();
  for (std::size_t r = 0; r < fam.size(); ++r) {
    const Family& f = fam[r];
    if (f.verdict != 0) continue;
    const std::size_t k = f.shadow;
    start_merged(s, k, f.state, time);
    s.role[k] = keep_band[r] ? Role::host : Role::active;
    result.kept_as_buffers += keep_band[r];
    for (const std::uint32_t a : f.members) {
      if (keep_band[r]) {
        s.role[a] = Role::buffer;  // its state is fitted at the next evaluation
        s.tie[a] = s.x[a] - f.state.x;  // where it stands: nothing moves
      } else {
        gone[a] = 1;
      }
    }
  }
  // Bands no longer needed, finest level first (a band whose particles host a band of their own stays until that
  // one has gone).
  for (int l = max_level - 1; l >= 0; --l) {
    const Daughters<D> daughters(store, gone);
    double reach = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (fluid(i) && store.level[i] == l) reach = std::max(reach, kUnbufferReach * (store.h[i] + store.d[i]));
    if (!(reach > 0.0)) continue;
    detail::Points<D> finer;
    for (std::size_t i = 0; i < n; ++i)
      if (active(i) && store.level[i] == l + 1) finer.add(store.x[i]);
    finer.sort(reach);
    std::vector<std::uint32_t> lose;
    for (std::size_t i = 0; i < n; ++i) {
      if (!fluid(i) || store.level[i] != l || !(store.role[i] == Role::host || store.role[i] == Role::buffer)) continue;
      const std::vector<std::uint32_t> d = daughters.of(store.id[i]);
      if (d.empty()) continue;
      bool only_buffers = true;
      for (const std::uint32_t a : d) only_buffers = only_buffers && store.role[a] == Role::buffer && daughters.of(store.id[a]).empty();
      if (!only_buffers || finer.near(store.x[i], kUnbufferReach * (store.h[i] + store.d[i]))) continue;
      lose.push_back(static_cast<std::uint32_t>(i));
      for (const std::uint32_t a : d) gone[a] = 1;
    }
    for (const std::uint32_t i : lose) {
      if (store.role[i] == Role::host) store.role[i] = Role::active;
      ++result.unbuffered;
    }
  }
  if (result.merged > 0 || result.unbuffered > 0) {
    // Ghosts go too, as in the split pass: the solver rebuilds them for the new set.
    store.compact([&](std::size_t i) { return gone[i] == 0 && store.kind[i] != Kind::ghost; });
  }
  return result;
}

template <int D>
std::size_t keep_passive_inside_walls(ParticleStore<D>& store, const std::vector<Wall<D>>& walls) {
  auto view = store.view();
  return par::accumulate(
      view.n, std::size_t{0},
      [&](std::size_t& moved, std::size_t i) {
        if (view.kind[i] != Kind::fluid || !is_passive(view.role[i])) return;
        const double margin = passive_wall_margin(view.d[i]);
        bool any = false;
        for (const Wall<D>& w : walls) {
          const double dist = w.signed_distance(view.x[i]);
          if (dist >= margin || dist < -view.d[i] || !w.projects_onto(view.x[i])) continue;
          view.x[i] += (margin - dist) * w.n;
          any = true;
        }
        if (any) ++moved;
      },
      [](std::size_t a, std::size_t b) { return a + b; });
}

template std::size_t keep_passive_inside_walls<2>(ParticleStore<2>&, const std::vector<Wall<2>>&);
template std::size_t keep_passive_inside_walls<3>(ParticleStore<3>&, const std::vector<Wall<3>>&);
template void tie_buffers<2>(ParticleStore<2>&);
template void tie_buffers<3>(ParticleStore<3>&);
template std::size_t prepare_buffered_marks<2>(ParticleStore<2>&, std::vector<std::uint8_t>&, int,
                                                const DaughterDensityIn<2>&);
template std::size_t prepare_buffered_marks<3>(ParticleStore<3>&, std::vector<std::uint8_t>&, int,
                                                const DaughterDensityIn<3>&);
template void flip_daughter<2>(ParticleStore<2>&, std::size_t, std::size_t, const DaughterDensityIn<2>&);
template void flip_daughter<3>(ParticleStore<3>&, std::size_t, std::size_t, const DaughterDensityIn<3>&);
template RetractResultIn<2> retract_buffered<2>(ParticleStore<2>&, const std::vector<std::uint8_t>&, const Geometry<2>&,
                                                double, double, const std::function<bool(const Vec<2>&, const Vec<2>&)>&,
                                                int);
template RetractResultIn<3> retract_buffered<3>(ParticleStore<3>&, const std::vector<std::uint8_t>&, const Geometry<3>&,
                                                double, double, const std::function<bool(const Vec<3>&, const Vec<3>&)>&,
                                                int);

}  // namespace sph::refine
