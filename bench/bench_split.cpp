// The split pass (mark -> count -> scan -> gather -> write daughters) at N = 1e5 and 1e6 with 0 %, 1 %, 10 %
// and 100 % marked, against one whole time step of the same store (target: splitting 10 % of 1e6 costs
// less than one step). Args: {N, percent marked, threads}.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <random>

#include "core/allocator_tuning.hpp"
#include "core/case_builder.hpp"
#include "core/refinement/split_pass.hpp"

namespace {

using namespace sph;

const bool tuned = (tune_allocator(), true);

// A dam-break block with about n fluid particles, rates evaluated (the state a pass sees between steps).
Simulation block(std::size_t n) {
  DamBreakSpec spec;
  spec.spacing = spec.column_width / std::round(std::sqrt(static_cast<double>(n)));
  return make_dam_break(spec);
}

std::vector<std::uint8_t> marks_for(const ParticleStore<2>& s, int percent) {
  std::vector<std::uint8_t> m(s.size(), 0);
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> U(0, 99);
  for (std::size_t i = 0; i < s.size(); ++i) m[i] = (s.kind[i] == Kind::fluid && U(rng) < percent) ? 1 : 0;
  return m;
}

void BM_Split_Pass(benchmark::State& state, refine::Pattern pattern) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const auto percent = static_cast<int>(state.range(1));
  omp_set_num_threads(static_cast<int>(state.range(2)));
  Simulation sim = block(n);
  sim.remove_ghosts();
  const ParticleStore<2> original = sim.store();
  const auto marks = marks_for(original, percent);
  const auto walls = sim.settings().geometry.walls();
  ParticleStore<2> work;
  for (auto _ : state) {
    state.PauseTiming();
    work = original;
    state.ResumeTiming();
    const auto r = refine::split_marked(work, marks, pattern, 1.0, 1, walls);
    benchmark::DoNotOptimize(r.refined);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * original.size()));
}

void BM_Split_AAP(benchmark::State& state) { BM_Split_Pass(state, refine::Pattern::aap); }
void BM_Split_RSP(benchmark::State& state) { BM_Split_Pass(state, refine::Pattern::rsp); }

void BM_Step_SameStore(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  omp_set_num_threads(static_cast<int>(state.range(1)));
  Simulation sim = block(n);
  const std::size_t fluid = sim.diagnostics().fluid;
  for (auto _ : state) sim.step();
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * fluid));
}

void split_args(benchmark::internal::Benchmark* b) {
  for (int64_t n : {100000, 1000000})
    for (int64_t pct : {0, 1, 10, 100})
      for (int64_t t : {1, 2}) b->Args({n, pct, t});
}

BENCHMARK(BM_Split_AAP)->Apply(split_args)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Split_RSP)->Args({100000, 10, 2})->Args({1000000, 10, 1})->Args({1000000, 10, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Step_SameStore)->Args({100000, 1})->Args({100000, 2})->Args({1000000, 1})->Args({1000000, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
