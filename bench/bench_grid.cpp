// Cell grid and store reorder: the counting sort (CellGrid::build), the store gather through its order,
// both together, and a neighbour sweep; beside them a plain copy of the bytes the reorder moves, so the
// reorder can be read as a ratio to the memory-bandwidth limit.
//
// Particles: 2D jittered lattice, spacing d = 1, jitter +-0.1 d, h = 1.2 d, cell size 2h. "Shuffled" runs
// start from a randomly permuted store (the first sort after setup: random access); "Sorted" runs from a
// store already in cell order (the steady state between time steps). Args: {N, threads}; real time.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <vector>

#include "core/allocator_tuning.hpp"
#include "core/cell_grid.hpp"
#include "core/particle_store.hpp"
#include "parallel/parallel_for.hpp"

namespace {

using sph::CellGrid;
using sph::ParticleStore;
using Store = ParticleStore<2>;

const bool tuned = (sph::tune_allocator(), true);

constexpr double kSpacing = 1.0;
constexpr double kH = 1.2 * kSpacing;
constexpr double kCellSize = 2.0 * kH;

/// Sets the OpenMP thread count for one benchmark and restores it afterwards.
class ThreadCount {
 public:
  explicit ThreadCount(std::int64_t n) : saved_(omp_get_max_threads()) {
    omp_set_num_threads(static_cast<int>(n));
  }
  ~ThreadCount() { omp_set_num_threads(saved_); }
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;

 private:
  int saved_;
};

std::vector<std::uint32_t> inverse(const std::vector<std::uint32_t>& perm) {
  std::vector<std::uint32_t> inv(perm.size());
  for (std::size_t k = 0; k < perm.size(); ++k) inv[perm[k]] = static_cast<std::uint32_t>(k);
  return inv;
}

/// One problem size, built once and shared by every benchmark at that size.
struct Case {
  Store shuffled;                             // random memory order
  Store sorted;                               // cell order (shuffled gathered through shuffled_order)
  std::vector<std::uint32_t> shuffled_order;  // grid order of `shuffled`
  std::vector<std::uint32_t> unsort;          // inverse of shuffled_order: sorted -> shuffled
  std::vector<std::uint32_t> sorted_order;    // grid order of `sorted` (the identity)
};

const Case& get_case(std::size_t n) {
  static std::map<std::size_t, std::unique_ptr<Case>> cache;
  auto& slot = cache[n];
  if (slot) return *slot;
  slot = std::make_unique<Case>();
  Case& c = *slot;
  Store& s = c.shuffled;
  s.append(n);
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> jitter(-0.1 * kSpacing, 0.1 * kSpacing);
  for (std::size_t k = 0; k < n; ++k) {
    const double i = static_cast<double>(k % side);
    const double j = static_cast<double>(k / side);
    s.x[k] = sph::Vec<2>{i * kSpacing + jitter(rng), j * kSpacing + jitter(rng)};
    s.v[k] = sph::Vec<2>{0.01 * jitter(rng), 0.01 * jitter(rng)};
    s.rho[k] = 1000.0;
    s.m[k] = 1000.0 * kSpacing * kSpacing;
    s.h[k] = kH;
    s.d[k] = kSpacing;
  }
  std::vector<std::uint32_t> perm(n);
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), rng);
  s.gather(perm);

  CellGrid<2> grid;
  grid.build(s.x.data(), n, kCellSize);
  c.shuffled_order = grid.order();
  c.unsort = inverse(c.shuffled_order);
  c.sorted = c.shuffled;
  c.sorted.gather(c.shuffled_order);
  grid.build(c.sorted.x.data(), n, kCellSize);
  c.sorted_order = grid.order();
  return c;
}

std::size_t arg_n(const benchmark::State& state) {
  return static_cast<std::size_t>(state.range(0));
}

void set_rates(benchmark::State& state, std::size_t n, bool with_bytes) {
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
  if (with_bytes) {
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(n * Store::bytes_per_particle()));
  }
}

// --- Grid build (the counting sort) -------------------------------------------------------------------

void BM_Grid_BuildShuffled(benchmark::State& state) {
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const Case& c = get_case(n);
  CellGrid<2> grid;
  for (auto _ : state) {
    grid.build(c.shuffled.x.data(), n, kCellSize);
    benchmark::DoNotOptimize(grid.order().data());
    benchmark::ClobberMemory();
  }
  set_rates(state, n, false);
}

void BM_Grid_BuildSorted(benchmark::State& state) {
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const Case& c = get_case(n);
  CellGrid<2> grid;
  for (auto _ : state) {
    grid.build(c.sorted.x.data(), n, kCellSize);
    benchmark::DoNotOptimize(grid.order().data());
    benchmark::ClobberMemory();
  }
  set_rates(state, n, false);
}

// --- Store reorder (gather of every field through the grid order) --------------------------------------

void BM_Store_ReorderShuffled(benchmark::State& state) {
  // Alternates shuffled -> sorted (gather through the grid order) and back (through its inverse): both are
  // random-access permutations of the whole store, the cost of the first sort after setup.
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const Case& c = get_case(n);
  Store s = c.shuffled;
  s.gather(c.shuffled_order);  // warm the scratch buffers
  s.gather(c.unsort);
  bool is_sorted = false;
  for (auto _ : state) {
    s.gather(is_sorted ? c.unsort : c.shuffled_order);
    is_sorted = !is_sorted;
    benchmark::ClobberMemory();
  }
  set_rates(state, n, true);
}

void BM_Store_ReorderSorted(benchmark::State& state) {
  // The steady state: the store is already in cell order, the gather is through the identity.
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const Case& c = get_case(n);
  Store s = c.sorted;
  s.gather(c.sorted_order);
  for (auto _ : state) {
    s.gather(c.sorted_order);
    benchmark::ClobberMemory();
  }
  set_rates(state, n, true);
}

// --- Both: build + reorder, as a time step does it -----------------------------------------------------

void BM_GridStore_BuildAndReorderShuffled(benchmark::State& state) {
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const Case& c = get_case(n);
  Store s = c.shuffled;
  s.gather(c.shuffled_order);
  s.gather(c.unsort);
  CellGrid<2> grid;
  for (auto _ : state) {
    grid.build(s.x.data(), n, kCellSize);
    s.gather(grid.order());
    state.PauseTiming();
    s.gather(c.unsort);  // back to the shuffled store, untimed
    state.ResumeTiming();
  }
  set_rates(state, n, true);
}

void BM_GridStore_BuildAndReorderSorted(benchmark::State& state) {
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const Case& c = get_case(n);
  Store s = c.sorted;
  s.gather(c.sorted_order);
  CellGrid<2> grid;
  for (auto _ : state) {
    grid.build(s.x.data(), n, kCellSize);
    s.gather(grid.order());
    benchmark::ClobberMemory();
  }
  set_rates(state, n, true);
}

// --- Neighbour sweep ----------------------------------------------------------------------------------

void BM_Grid_NeighbourSweep(benchmark::State& state) {
  // Counts the directed pairs (i, j), r < h_i + h_j, over all particles of the sorted store, in parallel.
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const Case& c = get_case(n);
  CellGrid<2> grid;
  grid.build(c.sorted.x.data(), n, kCellSize);
  const sph::Vec<2>* x = c.sorted.x.data();
  const double* h = c.sorted.h.data();
  std::uint64_t pairs = 0;
  for (auto _ : state) {
    pairs = sph::par::sum(n, std::uint64_t{0}, [&](std::size_t i) {
      std::uint64_t count = 0;
      grid.for_each_neighbour(i, x, h, [&](std::uint32_t, double) { ++count; });
      return count;
    });
    benchmark::DoNotOptimize(pairs);
  }
  set_rates(state, n, false);
  state.counters["pairs/s"] = benchmark::Counter(
      static_cast<double>(pairs) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["pairs/particle"] = static_cast<double>(pairs) / static_cast<double>(n);
}

// --- Memory-bandwidth reference -------------------------------------------------------------------------

void BM_Copy_ReorderBytes(benchmark::State& state) {
  // Copies bytes_per_particle() * N bytes (what a reorder reads and writes), split into one contiguous block
  // per thread like the gathers' static schedule.
  const ThreadCount tc(state.range(1));
  const std::size_t n = arg_n(state);
  const std::size_t bytes = n * Store::bytes_per_particle();
  std::vector<char> src(bytes, 1);
  std::vector<char> dst(bytes, 0);
  const auto threads = static_cast<std::size_t>(state.range(1));
  for (auto _ : state) {
    sph::par::parallel_for(threads, [&](std::size_t t) {
      const std::size_t begin = bytes * t / threads;
      const std::size_t end = bytes * (t + 1) / threads;
      std::memcpy(dst.data() + begin, src.data() + begin, end - begin);
    });
    benchmark::ClobberMemory();
  }
  set_rates(state, n, true);
}

void Sizes(benchmark::internal::Benchmark* b) {
  b->ArgsProduct({{10000, 100000, 1000000}, {1, 2}})
      ->ArgNames({"N", "threads"})
      ->UseRealTime()
      ->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Grid_BuildShuffled)->Apply(Sizes);
BENCHMARK(BM_Grid_BuildSorted)->Apply(Sizes);
BENCHMARK(BM_Store_ReorderShuffled)->Apply(Sizes);
BENCHMARK(BM_Store_ReorderSorted)->Apply(Sizes);
BENCHMARK(BM_GridStore_BuildAndReorderShuffled)->Apply(Sizes);
BENCHMARK(BM_GridStore_BuildAndReorderSorted)->Apply(Sizes);
BENCHMARK(BM_Grid_NeighbourSweep)->Apply(Sizes);
BENCHMARK(BM_Copy_ReorderBytes)->Apply(Sizes);

}  // namespace

BENCHMARK_MAIN();
