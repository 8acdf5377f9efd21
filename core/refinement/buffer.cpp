#include "core/refinement/buffer.hpp"

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "core/refinement/family.hpp"

namespace sph::refine {

namespace {

/// Points hashed into cubic cells of edge `edge`: near(x, reach) is true when a point lies within reach <= edge of x.
template <int D>
class PointCells {
 public:
  explicit PointCells(double edge) : edge_(edge) {}
  void add(const Vec<D>& x) { cells_[key(cell(x))].push_back(x); }
  bool empty() const { return cells_.empty(); }
  bool near(const Vec<D>& x, double reach) const {
    const std::array<std::int64_t, D> c = cell(x);
    constexpr int kAround = D == 2 ? 9 : 27;
    for (int k = 0; k < kAround; ++k) {
      std::array<std::int64_t, D> b = c;
      int rest = k;
      for (int a = 0; a < D; ++a) {
        b[static_cast<std::size_t>(a)] += rest % 3 - 1;
        rest /= 3;
      }
      const auto it = cells_.find(key(b));
      if (it == cells_.end()) continue;
      for (const Vec<D>& y : it->second) {
        if ((y - x).squaredNorm() < reach * reach) return true;
      }
    }
    return false;
  }

 private:
  std::array<std::int64_t, D> cell(const Vec<D>& x) const {
    std::array<std::int64_t, D> c{};
    for (int a = 0; a < D; ++a) c[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(std::floor(x[a] / edge_));
    return c;
  }
  static std::uint64_t key(const std::array<std::int64_t, D>& c) {
    std::uint64_t k = 1469598103934665603ull;  // FNV-1a over the coordinates
    for (const std::int64_t v : c) {
      k ^= static_cast<std::uint64_t>(v);
      k *= 1099511628211ull;
    }
    return k;
  }
  double edge_;
  // Cells that hash alike share a list; near() tests distances, so that only costs time.
  std::unordered_map<std::uint64_t, std::vector<Vec<D>>> cells_;
};

}  // namespace

template <int D>
std::size_t prepare_buffered_marks(ParticleStore<D>& store, std::vector<std::uint8_t>& marks, int max_level) {
  const std::size_t n = store.size();
  const auto fluid = [&](std::size_t i) { return store.kind[i] == Kind::fluid; };
  std::unordered_set<ParticleId> parents;  // ids of the particles that have daughters
  for (std::size_t i = 0; i < n; ++i) {
    if (fluid(i) && has_parent(store.id[i])) parents.insert(parent_id<D>(store.id[i]));
  }
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
    PointCells<D> active(reach), marked(reach);
    for (std::size_t i = 0; i < n; ++i) {
      if (!fluid(i)) continue;
      if (store.level[i] == l + 1 && !is_passive(store.role[i])) active.add(store.x[i]);
      if (store.level[i] == l && marks[i] == 1) marked.add(store.x[i]);
    }
    if (active.empty() && marked.empty()) continue;
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

template std::size_t prepare_buffered_marks<2>(ParticleStore<2>&, std::vector<std::uint8_t>&, int);
template std::size_t prepare_buffered_marks<3>(ParticleStore<3>&, std::vector<std::uint8_t>&, int);

}  // namespace sph::refine
