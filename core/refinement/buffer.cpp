#include "core/refinement/buffer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_set>
#include <utility>

#include "core/refinement/family.hpp"

namespace sph::refine {

namespace {

/// Points sorted into the project's cell grid (one layer, cells of edge `edge`): near(x, reach) is true when a point
/// lies within reach <= edge of x.
template <int D>
class Points {
 public:
  void add(const Vec<D>& x) { x_.push_back(x); }
  bool empty() const { return x_.empty(); }
  void sort(double edge) {
    if (x_.empty()) return;
    // A query around p with "smoothing length" h reaches h + max_h: max_h = edge / 2, and near() asks h = reach - max_h.
    grid_.build(x_.data(), x_.size(), edge, 0.5 * edge);
    half_edge_ = 0.5 * edge;
  }
  bool near(const Vec<D>& x, double reach) const {
    if (x_.empty()) return false;
    bool found = false;
    const auto& order = grid_.order();
    grid_.for_each_support_run(x, reach - half_edge_, [&](std::uint32_t b, std::uint32_t e) {
      for (std::uint32_t k = b; k < e && !found; ++k) found = (x_[order[k]] - x).squaredNorm() < reach * reach;
    });
    return found;
  }

 private:
  std::vector<Vec<D>> x_;
  CellGrid<D> grid_;
  double half_edge_ = 0.0;
};

}  // namespace

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
std::size_t prepare_buffered_marks(ParticleStore<D>& store, std::vector<std::uint8_t>& marks, int max_level) {
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
    Points<D> finer;
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
  // A marked host: its zone now covers it. It turns into a shadow, and its daughters take over as active.
  std::unordered_set<ParticleId> flipped;
  for (std::size_t i = 0; i < n; ++i) {
    if (marks[i] && fluid(i) && store.level[i] < max_level && store.role[i] == Role::host) {
      store.role[i] = Role::shadow;
      flipped.insert(store.id[i]);
    }
  }
  if (!flipped.empty()) {
    for (std::size_t i = 0; i < n; ++i) {
      if (fluid(i) && store.role[i] == Role::buffer && has_parent(store.id[i]) &&
          flipped.count(parent_id<D>(store.id[i])) != 0) {
        store.role[i] = Role::active;
      }
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
    Points<D> active, marked;
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

template void tie_buffers<2>(ParticleStore<2>&);
template void tie_buffers<3>(ParticleStore<3>&);
template std::size_t prepare_buffered_marks<2>(ParticleStore<2>&, std::vector<std::uint8_t>&, int);
template std::size_t prepare_buffered_marks<3>(ParticleStore<3>&, std::vector<std::uint8_t>&, int);

}  // namespace sph::refine
