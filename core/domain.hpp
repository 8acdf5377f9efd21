#pragma once
// Domain decomposition across ranks (issue #19). Space is cut into decomposition cells on the lattice anchored by
// the container (grid_anchor), each at least as wide as the largest pair support 2 h_max, so every neighbour of a
// particle lies in its cell or the 3^D cells around it. Zoltan's RCB (par::Partition) gives every cell an owner
// from the cells' centres, weighted by their particles' force evaluations per step (2^bin each, so refined levels
// that step on their own weigh what they cost).
//
// A rank's store holds:
//   - its own fluid: the fluid particles in the cells it owns;
//   - every wall particle (they never move; the container's wall particles are few against the fluid, O(n^(D-1)/D));
//   - halos (Kind::halo): copies of the other ranks' fluid particles in the 3^D cells around its own, refreshed
//     before every force evaluation;
//   - the ghosts of its own fluid and of its halos (built by the step, as in one process).
// The pair sweep computes the rates of its own fluid only (a halo is not fluid). Since the grid is on the anchored
// lattice and each cell's particles are taken in id order, each own particle meets the same neighbours in the same
// order as in one process, and its rates have the same bits (tests/test_partition.cpp).
//
// exchange() is the one collective step: own fluid that left the rank's cells sent to their owner (migration), and
// the halos rebuilt; the old halos and what left are dropped by the step's own gather. Particles pass through the store's field registry, so every field
// travels.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "core/integrator.hpp"
#include "core/neighbour_cells.hpp"
#include "core/particle_store.hpp"
#include "core/refinement/family.hpp"
#include "core/refinement/merge_key.hpp"
#include "parallel/comm.hpp"
#include "parallel/partition.hpp"

namespace sph {

/// What one exchange moved (this rank), for the measurements of docs/PERFORMANCE.md.
struct ExchangeCounts {
  std::uint64_t migrated = 0;  // own fluid sent to another rank
  std::uint64_t halos = 0;     // halo copies received
  std::uint64_t bytes = 0;     // bytes sent
  double seconds = 0.0;        // wall time in exchange() (packing, messages, unpacking, waiting for the others)
};

/// One recut of the cells (Simulation::rebalance): the loads before and after (max / mean) and its wall time.
struct RebalanceRecord {
  std::uint64_t step = 0;
  double before = 1.0, after = 1.0, seconds = 0.0;
};

/// Every field of particle i appended to `out`, in registry order.
template <int D>
void pack_particle(const ParticleStore<D>& store, std::size_t i, std::vector<std::byte>& out) {
  store.for_each_field([&](const auto& f) { par::put(out, f[i]); });
}

/// Bytes one packed particle takes.
template <int D>
std::size_t packed_size() {
  static const std::size_t n = [] {
    std::size_t bytes = 0;
    const ParticleStore<D> empty;
    empty.for_each_field([&](const auto& f) { bytes += sizeof(typename std::decay_t<decltype(f)>::value_type); });
    return bytes;
  }();
  return n;
}

/// Appends the packed particles in `bytes` to the store (their ids as packed; the store's next id unchanged);
/// returns the index of the first.
template <int D>
std::size_t unpack_particles(ParticleStore<D>& store, const std::vector<std::byte>& bytes) {
  const std::size_t record = packed_size<D>();
  const std::size_t count = bytes.size() / record;
  const std::size_t first = store.size();
  store.resize(first + count);
  std::size_t at = 0;
  for (std::size_t k = 0; k < count; ++k) {
    store.for_each_field([&](auto& f) {
      using T = typename std::decay_t<decltype(f)>::value_type;
      f[first + k] = par::take<T>(bytes, at);
    });
  }
  return first;
}

/// The particles a file holds (fluid on every rank, wall particles from the root, which holds them all, as every
/// rank does), spread over the ranks in id order: rank r gets a contiguous run of ids, all below rank r + 1's, sorted
/// (a sample sort: each rank's evenly spaced samples of its sorted ids, gathered, give the splitters). Collective;
/// with one rank, the file's particles of the store in id order.
template <int D>
ParticleStore<D> share_in_id_order(const ParticleStore<D>& store, const par::Comm& comm) {
  std::vector<std::size_t> mine;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (store.kind[i] == Kind::fluid || (comm.root() && store.kind[i] == Kind::wall)) mine.push_back(i);
  }
  std::sort(mine.begin(), mine.end(), [&](std::size_t a, std::size_t b) { return store.id[a] < store.id[b]; });
  const auto ranks = static_cast<std::size_t>(comm.size());
  // Samples: up to 4 per rank and rank, evenly spaced in this rank's sorted ids.
  std::vector<ParticleId> samples;
  const std::size_t per = 4 * ranks;
  for (std::size_t k = 0; k < per && !mine.empty(); ++k) samples.push_back(store.id[mine[k * mine.size() / per]]);
  std::vector<ParticleId> pool = comm.all_gather_values(samples);
  std::sort(pool.begin(), pool.end());
  std::vector<ParticleId> splitters;  // rank r takes ids in [splitters[r - 1], splitters[r])
  for (std::size_t r = 1; r < ranks; ++r) splitters.push_back(pool.empty() ? 0 : pool[r * pool.size() / ranks]);
  std::vector<std::vector<std::byte>> out(ranks);
  for (const std::size_t i : mine) {
    const auto to = static_cast<std::size_t>(std::upper_bound(splitters.begin(), splitters.end(), store.id[i]) -
                                             splitters.begin());
    pack_particle(store, i, out[to]);
  }
  ParticleStore<D> share;
  share.set_next_id(store.next_id());
  unpack_particles(share, comm.exchange(out));
  std::vector<std::uint32_t> order(share.size());
  for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return share.id[a] < share.id[b]; });
  share.gather(order);
  return share;
}

template <int D>
class DomainT {
 public:
  /// `lo`, `hi`: the container; `reach`: the largest pair support the run will see (2 h_max of the set-up).
  DomainT(const par::Comm& comm, const Vec<D>& lo, const Vec<D>& hi, double reach)
      : comm_(comm), partition_(comm), edge_(reach * (1.0 + 1e-12)), anchor_(grid_anchor(Box{lo, hi})) {}

  const par::Comm& comm() const { return comm_; }

  /// Cuts the cells between the ranks by the weight of the fluid in them. Collective. With `replicated`, every rank
  /// holds the same particles (the set-up, a checkpoint read by all) and passes an equal share of the cells.
  void partition(const ParticleStore<D>& store, const Integrator& integ, bool replicated) {
    std::unordered_map<std::uint64_t, double> weight;
    for (std::size_t i = 0; i < store.size(); ++i) {
      if (store.kind[i] != Kind::fluid) continue;
      weight[key_of(store.x[i])] += static_cast<double>(1u << integ.bin(store.bin[i]));
    }
    std::vector<std::uint64_t> keys;
    keys.reserve(weight.size());
    for (const auto& [k, w] : weight) keys.push_back(k);
    std::sort(keys.begin(), keys.end());
    std::size_t first = 0, last = keys.size();
    if (replicated) {
      const auto r = static_cast<std::size_t>(comm_.rank()), p = static_cast<std::size_t>(comm_.size());
      first = keys.size() * r / p;
      last = keys.size() * (r + 1) / p;
    }
    std::vector<double> coords, weights;
    for (std::size_t k = first; k < last; ++k) {
      const Vec<D> c = centre_of(keys[k]);
      for (int a = 0; a < D; ++a) coords.push_back(c[a]);
      weights.push_back(weight[keys[k]]);
    }
    partition_.cut(D, coords, weights);
    owner_.clear();
    targets_.clear();
  }

  /// The rank owning the cell of x (this rank's for a non-finite position: the watchdog reports it where it is).
  int owner_of(const Vec<D>& x) const {
    if (!x.allFinite()) return comm_.rank();
    return owner_of_key(key_of(x));
  }

  /// Sends own fluid outside this rank's cells to its owner (with `replicated`, every rank already holds it: it is
  /// only dropped) and rebuilds the halos, appended to the store; what left and the old halos become ghosts, which
  /// the step's expansion drops (so build the neighbours right after). Collective.
  ExchangeCounts exchange(ParticleStore<D>& store, bool replicated = false) {
    const auto start = std::chrono::steady_clock::now();
    ExchangeCounts counts;
    const int me = comm_.rank();
    const auto ranks = static_cast<std::size_t>(comm_.size());
    std::vector<std::vector<std::byte>> out(ranks);
    const std::size_t n = store.size();
    // What leaves the store (fluid sent away, the old halos) becomes a ghost: the step's expansion, which drops the
    // ghosts in the gather it does anyway (Simulation::build_neighbours), drops it too, so the exchange needs no
    // compaction of its own (a gather of every field: it was most of the exchange's time).
    for (std::size_t i = 0; i < n; ++i) {
      const Kind k = store.kind[i];
      if (k == Kind::fluid) {
        const int o = owner_of(store.x[i]);
        if (o == me) continue;
        if (!replicated) {
          pack_particle(store, i, out[static_cast<std::size_t>(o)]);
          ++counts.migrated;
        }
        store.kind[i] = Kind::ghost;
      } else if (k == Kind::halo) {
        store.kind[i] = Kind::ghost;
      }
    }
    for (const auto& b : out) counts.bytes += b.size();
    unpack_particles(store, comm_.exchange(out));
    // Halos: each own fluid particle to the owners of the cells around its own (the ones just arrived included).
    for (auto& b : out) b.clear();
    for (std::size_t i = 0; i < store.size(); ++i) {
      if (store.kind[i] != Kind::fluid || !store.x[i].allFinite()) continue;
      for (const int r : targets_of(key_of(store.x[i]))) pack_particle(store, i, out[static_cast<std::size_t>(r)]);
    }
    for (const auto& b : out) counts.bytes += b.size();
    const std::size_t first = unpack_particles(store, comm_.exchange(out));
    for (std::size_t i = first; i < store.size(); ++i) store.kind[i] = Kind::halo;
    counts.halos = store.size() - first;
    counts.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return counts;
  }

  /// Coarsening across ranks, before the merge pass (core/refinement/merge_pass.hpp). The members of a merge group
  /// (core/refinement/merge_key.hpp: the 2^D daughters of one parent, or the candidates of one cell) can sit on
  /// different ranks. Each group that merges (at least 2^D mergeable candidates: own fluid with may[i] != 0) is
  /// brought together at its leader, the rank holding its first member in key order: the others lend it copies of
  /// their members, appended to the leader's store as fluid with may = 1 (the lenders keep the originals). Three
  /// messages: each rank sends the keys of its candidates to a rank fixed by the group (a hash): with families only
  /// those of families not whole here, with cells all (a cell's other candidates may be anywhere). That rank finds the
  /// groups that merge and tells each lender where to send; with cells it also tells every other rank holding a
  /// candidate of a group led elsewhere, which then sets may = 0 for it (that rank may hold 2^D of the cell, but not
  /// its first). Then the copies go. Returns what settle_families needs. Collective.
  struct Lent {
    std::size_t first = 0;                // store index of the first copy (the store's size when none came)
    std::vector<std::pair<ParticleId, int>> lenders;  // each copy's id and the rank that lent it, sorted by id
  };
  Lent lend_families(ParticleStore<D>& store, std::vector<std::uint8_t>& may, refine::MergeGroups groups,
                     const Vec<D>& anchor) const {
    constexpr unsigned children = refine::kChildren<D>;
    const bool cells = groups == refine::MergeGroups::cell;
    const auto ranks = static_cast<std::size_t>(comm_.size());
    struct Key {
      refine::MergeKey key;
      std::int32_t rank;      // the sender; in the answer, the group's leader
      std::int32_t selected;  // in the answer: 1 when this member goes to the leader
    };
    std::vector<Key> mine;
    std::vector<std::uint32_t> index;  // store index of mine[k]
    for (std::size_t i = 0; i < store.size(); ++i) {
      refine::MergeKey key;
      if (!may[i] || store.kind[i] != Kind::fluid || !refine::merge_key<D>(store, i, groups, anchor, key)) continue;
      mine.push_back({key, comm_.rank(), 0});
      index.push_back(static_cast<std::uint32_t>(i));
    }
    std::vector<std::uint32_t> order(mine.size());
    for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return mine[a].key < mine[b].key; });
    // 1. The keys, to each group's home rank.
    std::vector<std::vector<std::byte>> out(ranks);
    for (std::size_t k = 0; k < order.size();) {
      std::size_t e = k;
      while (e < order.size() && mine[order[e]].key.same_group(mine[order[k]].key)) ++e;
      if (cells || e - k < children) {
        for (std::size_t j = k; j < e; ++j) par::put(out[home_of(mine[order[j]].key)], mine[order[j]]);
      }
      k = e;
    }
    std::vector<std::byte> in = comm_.exchange(out);
    // 2. At home: the groups with at least 2^D candidates; their first 2^D go to the leader, the rank of the first.
    std::vector<Key> keys(in.size() / sizeof(Key));
    if (!keys.empty()) std::memcpy(static_cast<void*>(keys.data()), in.data(), in.size());
    std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) { return a.key < b.key; });
    for (auto& b : out) b.clear();
    for (std::size_t k = 0; k < keys.size();) {
      std::size_t e = k;
      while (e < keys.size() && keys[e].key.same_group(keys[k].key)) ++e;
      if (e - k >= children) {
        const std::int32_t leader = keys[k].rank;
        for (std::size_t j = k; j < e; ++j) {
          if (keys[j].rank == leader) continue;
          par::put(out[static_cast<std::size_t>(keys[j].rank)], Key{keys[j].key, leader, j < k + children ? 1 : 0});
        }
      }
      k = e;
    }
    in = comm_.exchange(out);
    // 3. The copies, to the leaders; a candidate of a group led elsewhere does not merge here.
    for (auto& b : out) b.clear();
    for (std::size_t at = 0; at < in.size();) {
      const Key want = par::take<Key>(in, at);
      const auto it = std::lower_bound(order.begin(), order.end(), want.key,
                                       [&](std::uint32_t k, const refine::MergeKey& w) { return mine[k].key < w; });
      if (want.selected) pack_particle(store, index[*it], out[static_cast<std::size_t>(want.rank)]);
      if (cells) may[index[*it]] = 0;
    }
    std::vector<std::size_t> from;
    Lent lent;
    lent.first = unpack_particles(store, comm_.exchange(out, &from));
    may.resize(store.size(), 1);
    std::size_t i = lent.first;
    for (std::size_t r = 0; r < from.size(); ++r) {
      for (std::size_t c = 0; c < from[r] / packed_size<D>(); ++c, ++i) lent.lenders.emplace_back(store.id[i], static_cast<int>(r));
    }
    std::sort(lent.lenders.begin(), lent.lenders.end());
    return lent;
  }

  /// After the merge pass: `merged` holds the ids of the lent copies whose group merged here. Each goes back to
  /// its lender, which removes its original (and its ghosts: the solver rebuilds them). Collective.
  void settle_families(ParticleStore<D>& store, const std::vector<ParticleId>& merged, const Lent& lent) const {
    std::vector<std::vector<std::byte>> out(static_cast<std::size_t>(comm_.size()));
    for (const ParticleId id : merged) {
      const auto it = std::lower_bound(lent.lenders.begin(), lent.lenders.end(), std::pair<ParticleId, int>{id, -1});
      par::put(out[static_cast<std::size_t>(it->second)], id);
    }
    const std::vector<ParticleId> gone = sorted_ids(comm_.exchange(out));
    if (!gone.empty()) {
      store.compact([&](std::size_t i) {
        return store.kind[i] != Kind::ghost &&
               !(store.kind[i] == Kind::fluid && std::binary_search(gone.begin(), gone.end(), store.id[i]));
      });
    }
  }

  /// The loads as the cut assigns the own fluid (each rank's weight by the owner of each particle's cell): max over
  /// ranks / mean (1: perfectly balanced). Right after an exchange, the ranks' own loads; right after a new cut,
  /// the loads the next exchange will make. Collective.
  double imbalance(const ParticleStore<D>& store, const Integrator& integ) const {
    std::vector<double> w(static_cast<std::size_t>(comm_.size()), 0.0);
    for (std::size_t i = 0; i < store.size(); ++i) {
      if (store.kind[i] == Kind::fluid)
        w[static_cast<std::size_t>(owner_of(store.x[i]))] += static_cast<double>(1u << integ.bin(store.bin[i]));
    }
    std::vector<double> total(w.size(), 0.0);
    const std::vector<double> all = comm_.all_gather_values(w);
    for (std::size_t k = 0; k < all.size(); ++k) total[k % w.size()] += all[k];
    double sum = 0.0, most = 0.0;
    for (const double x : total) {
      sum += x;
      most = std::max(most, x);
    }
    return sum > 0.0 ? most * static_cast<double>(total.size()) / sum : 1.0;
  }

 private:
  struct Box {
    Vec<D> lo, hi;
  };
  static constexpr int kBits = D == 2 ? 31 : 21;  // cell coordinate bits per axis
  static constexpr std::int64_t kMax = (std::int64_t{1} << kBits) - 1;

  /// The rank that matches a merge group's members across ranks (lend_families): a hash of the group, so the groups
  /// spread evenly over the ranks.
  std::size_t home_of(const refine::MergeKey& key) const {
    std::uint64_t h = 0;
    for (const std::uint64_t g : key.group) {
      std::uint64_t z = h + g + 0x9e3779b97f4a7c15ull;  // splitmix64's finaliser, chained over the words
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
      h = z ^ (z >> 31);
    }
    return static_cast<std::size_t>(h % static_cast<std::uint64_t>(comm_.size()));
  }
  static std::vector<ParticleId> sorted_ids(const std::vector<std::byte>& in) {
    std::vector<ParticleId> ids(in.size() / sizeof(ParticleId));
    if (!ids.empty()) std::memcpy(ids.data(), in.data(), in.size());
    std::sort(ids.begin(), ids.end());
    return ids;
  }

  std::uint64_t key_of(const Vec<D>& x) const {
    std::uint64_t key = 0;
    for (int a = 0; a < D; ++a) {
      const double c = std::floor((x[a] - anchor_[a]) / edge_);
      const std::int64_t ic = c < 0.0 ? 0 : (c > static_cast<double>(kMax) ? kMax : static_cast<std::int64_t>(c));
      key = (key << kBits) | static_cast<std::uint64_t>(ic);
    }
    return key;
  }
  std::array<std::int64_t, D> coords_of(std::uint64_t key) const {
    std::array<std::int64_t, D> c{};
    for (int a = D - 1; a >= 0; --a) {
      c[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(key & static_cast<std::uint64_t>(kMax));
      key >>= kBits;
    }
    return c;
  }
  std::uint64_t key_from(const std::array<std::int64_t, D>& c) const {
    std::uint64_t key = 0;
    for (int a = 0; a < D; ++a) key = (key << kBits) | static_cast<std::uint64_t>(c[static_cast<std::size_t>(a)]);
    return key;
  }
  Vec<D> centre_of(std::uint64_t key) const {
    const std::array<std::int64_t, D> c = coords_of(key);
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = anchor_[a] + (static_cast<double>(c[static_cast<std::size_t>(a)]) + 0.5) * edge_;
    return x;
  }
  int owner_of_key(std::uint64_t key) const {
    const auto it = owner_.find(key);
    if (it != owner_.end()) return it->second;
    const Vec<D> c = centre_of(key);
    std::array<double, D> p{};
    for (int a = 0; a < D; ++a) p[static_cast<std::size_t>(a)] = c[a];
    const int o = partition_.owner(p.data());
    owner_.emplace(key, o);
    return o;
  }
  /// The other ranks owning a cell in the 3^D block around the cell `key` (sorted, each once).
  const std::vector<int>& targets_of(std::uint64_t key) const {
    const auto it = targets_.find(key);
    if (it != targets_.end()) return it->second;
    std::vector<int> t;
    const std::array<std::int64_t, D> c = coords_of(key);
    constexpr int kAround = D == 2 ? 9 : 27;
    for (int k = 0; k < kAround; ++k) {
      std::array<std::int64_t, D> b = c;
      int rest = k;
      bool inside = true;
      for (int a = D - 1; a >= 0; --a) {
        auto& ba = b[static_cast<std::size_t>(a)];
        ba += rest % 3 - 1;
        rest /= 3;
        inside = inside && ba >= 0 && ba <= kMax;
      }
      if (!inside) continue;
      const int o = owner_of_key(key_from(b));
      if (o != comm_.rank()) t.push_back(o);
    }
    std::sort(t.begin(), t.end());
    t.erase(std::unique(t.begin(), t.end()), t.end());
    return targets_.emplace(key, std::move(t)).first->second;
  }

  const par::Comm& comm_;
  par::Partition partition_;
  double edge_;
  Vec<D> anchor_;
  // Caches of owner_of_key and targets_of (cleared by partition()).
  mutable std::unordered_map<std::uint64_t, int> owner_;
  mutable std::unordered_map<std::uint64_t, std::vector<int>> targets_;
};

}  // namespace sph
