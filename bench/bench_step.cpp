// One whole step (ghosts + grid + sweep + integrate) of a dam-break block at N = 1e4, 1e5, 1e6 fluid
// particles, 1 and 2 threads, in fluid particle-steps per second; and the cost of each effect: the pair
// sweep alone with and without viscosity and with and without the Lennard-Jones wall, and a step with and
// without ghost walls. Args: {N, threads}.
#include <benchmark/benchmark.h>
#include <omp.h>
#include <sys/resource.h>

#include <cmath>

#include "core/allocator_tuning.hpp"
#include "core/case_builder.hpp"

namespace {

using namespace sph;

const bool tuned = (tune_allocator(), true);

DamBreakSpec block(std::size_t n) {
  DamBreakSpec spec;
  spec.spacing = spec.column_width / std::round(std::sqrt(static_cast<double>(n)));
  return spec;
}

void BM_Step_DamBreak(benchmark::State& state, bool ghosts) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  DamBreakSpec spec = block(static_cast<std::size_t>(state.range(0)));
  spec.ghosts = ghosts;
  Simulation sim = make_dam_break(spec);
  const std::size_t fluid = sim.diagnostics().fluid;
  for (int k = 0; k < 3; ++k) sim.step();  // warm-up: the step's workspaces and the rollback copy reach size
  for (auto _ : state) sim.step();
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * fluid));
  state.counters["pairs_per_particle"] = static_cast<double>(sim.last_limits().pairs) / static_cast<double>(fluid);
  state.counters["fluid"] = static_cast<double>(fluid);
  state.counters["store_bytes_per_particle"] =
      static_cast<double>(sim.store().bytes()) / static_cast<double>(fluid);
  // Peak resident set of the process so far, per fluid particle: meaningful when a process runs one N
  // (scripts/bench runs each N in its own process).
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_bytes_per_particle"] =
      static_cast<double>(usage.ru_maxrss) * 1024.0 / static_cast<double>(fluid);
}

void BM_Step_WithGhosts(benchmark::State& state) { BM_Step_DamBreak(state, true); }
void BM_Step_WithoutGhosts(benchmark::State& state) { BM_Step_DamBreak(state, false); }

// The sweep alone on a prepared store, for each effect set, with the loop the activity selects (the single-rate one
// by default).
void BM_Sweep(benchmark::State& state, bool viscosity, bool lennard_jones, const Activity& act = {}) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  DamBreakSpec spec = block(static_cast<std::size_t>(state.range(0)));
  spec.viscosity = viscosity;
  spec.lennard_jones = lennard_jones;
  Simulation sim = make_dam_break(spec);
  for (int k = 0; k < 20; ++k) sim.step();  // a moving state, so that viscosity does work
  const auto sweep = make_sweep(sim.settings());
  const std::size_t fluid = sim.diagnostics().fluid;
  for (auto _ : state) benchmark::DoNotOptimize(sweep->run(sim.store().view(), sim.grid(), act));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * fluid));
}

// The last evaluation of a step with time bins (Activity::rebin, every step of a per-level run): each pair once
// at weight 1 and then added at this step's and at the next step's weight, against the plain sweep of the same
// store and effects (BM_Sweep_ViscosityAndLennardJones). Issue #16: what a per-level run's closing evaluations
// cost per pair over a single-rate run's.
void BM_Sweep_Rebin(benchmark::State& state) {
  Activity act;
  act.rebin = true;
  BM_Sweep(state, true, true, act);
}

// The binned loop of a per-level run's inner evaluations (every particle due, in bin 0 of a store allowed two bins)
// against the single-rate loop on the same store and effects (BM_Sweep_ViscosityAndLennardJones): what the binned
// loop costs per pair on its own, with the same pairs and sums (issue #16).
void BM_Sweep_Binned(benchmark::State& state) {
  Activity act;
  act.bin_cap = 1;
  BM_Sweep(state, true, true, act);
}

void BM_Sweep_PressureOnly(benchmark::State& s) { BM_Sweep(s, false, false); }
void BM_Sweep_Viscosity(benchmark::State& s) { BM_Sweep(s, true, false); }
void BM_Sweep_LennardJones(benchmark::State& s) { BM_Sweep(s, false, true); }
void BM_Sweep_ViscosityAndLennardJones(benchmark::State& s) { BM_Sweep(s, true, true); }

// A still tank in 2D and 3D at N fluid particles (h = 1.2 d, ghost walls): the cost of a step per particle and per
// pair interaction, for the dimensions' ratio (issue #18: at most 1.5x per pair) and for how the 3D step scales
// with N (flat within 20 % from 1e4 to 1e6).
template <int D>
SimulationT<D> tank(std::size_t n);

template <>
SimulationT<2> tank<2>(std::size_t n) {
  TankSpec spec;  // 25 m x 10 m
  spec.spacing = std::sqrt(spec.width * spec.depth / static_cast<double>(n));
  return make_still_tank(spec);
}

template <>
SimulationT<3> tank<3>(std::size_t n) {
  Tank3Spec spec;  // 1 m x 0.4 m x 0.5 m of water
  spec.spacing = std::cbrt(spec.length * spec.width * spec.depth / static_cast<double>(n));
  return make_still_tank(spec);
}

template <int D>
void BM_Step_Tank(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  SimulationT<D> sim = tank<D>(static_cast<std::size_t>(state.range(0)));
  const std::size_t fluid = sim.diagnostics().fluid;
  for (int k = 0; k < 3; ++k) sim.step();
  double pairs = 0.0;
  for (auto _ : state) pairs += static_cast<double>(sim.step().limits.pairs);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * fluid));
  state.counters["fluid"] = static_cast<double>(fluid);
  state.counters["pairs_per_particle"] = pairs / static_cast<double>(fluid * state.iterations());
  state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsRate);
}

BENCHMARK_TEMPLATE(BM_Step_Tank, 2)->Args({10000, 1})->Args({100000, 1})->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Step_Tank, 3)->Args({10000, 1})->Args({100000, 1})->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// The diagnostics (exact sums, par::ExactSum) against a step of the same tank: written at every output row, so
// their cost is one row's, not one step's.
template <int D>
void BM_Diagnostics_Tank(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  SimulationT<D> sim = tank<D>(static_cast<std::size_t>(state.range(0)));
  sim.step();
  double sink = 0.0;
  for (auto _ : state) sink += sim.diagnostics().kinetic;
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * sim.store().size()));
}

BENCHMARK_TEMPLATE(BM_Diagnostics_Tank, 2)->Args({100000, 1})->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_TEMPLATE(BM_Diagnostics_Tank, 3)->Args({100000, 1})->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void sizes(benchmark::internal::Benchmark* b) {
  for (int64_t n : {1000, 10000, 100000, 1000000, 4000000})
    for (int64_t t : {1, 2}) b->Args({n, t});
}

BENCHMARK(BM_Step_WithGhosts)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Step_WithoutGhosts)->Args({100000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Sweep_PressureOnly)->Args({100000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Sweep_Viscosity)->Args({100000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Sweep_LennardJones)->Args({100000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Sweep_ViscosityAndLennardJones)->Args({100000, 1})->Args({100000, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Sweep_Binned)->Args({100000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Sweep_Rebin)->Args({100000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
