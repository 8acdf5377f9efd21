// The peer comparison of ../shared/ANCHORS.md: DualSPHysics 5.4's own 2D dam break (a 1 m x 2 m column in a
// 4 m x 3 m tank) at its three particle counts and simulated windows, timed as a whole solver run with no
// output. Our settings as close as our physics allows: h/d = sqrt(2) (its neighbour count) or our default
// 1.2, c0 = 20 sqrt(g H), artificial viscosity alpha = 0.02, CFL 0.2, hydrostatic start; walls are ghost
// (free-slip) + Lennard-Jones particles instead of its dynamic boundary particles; double precision.
// Args: {dp index 0..2, threads, h/d x 1000}. Reports fluid particle-steps/s and pair interactions/s.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>

#include "core/allocator_tuning.hpp"
#include "core/case_builder.hpp"

namespace {

using namespace sph;

const bool tuned = (tune_allocator(), true);

struct PeerCase {
  double dp;
  double window;  // simulated seconds from rest
};
constexpr PeerCase kCases[] = {{1.0 / 45, 0.4}, {1.0 / 122, 0.1}, {1.0 / 354, 0.008}};

/// Times whole runs from rest over `window` simulated seconds, the simulation built by make() outside the timing,
/// and reports fluid particle-steps/s, pair interactions/s and pairs per particle-step.
template <class Make>
void time_window(benchmark::State& state, Make make, double window) {
  std::uint64_t steps = 0;
  std::size_t fluid = 0, walls = 0;
  double pairs = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto sim = make();
    sim.set_clock(0.0, 0, sim.dt());
    const auto d = sim.diagnostics();
    fluid = d.fluid;
    walls = d.walls;
    pairs = 0;
    state.ResumeTiming();
    while (sim.time() < window) {
      const StepInfo info = sim.step(window - sim.time());
      pairs += static_cast<double>(info.limits.pairs);
    }
    steps = sim.step_count();
  }
  state.counters["fluid"] = static_cast<double>(fluid);
  state.counters["walls"] = static_cast<double>(walls);
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["particle_steps_per_s"] =
      benchmark::Counter(static_cast<double>(fluid * steps) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
  state.counters["pairs_per_s"] =
      benchmark::Counter(pairs * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["pairs_per_particle"] = pairs / static_cast<double>(fluid * steps);
}

void BM_Peer_DamBreak(benchmark::State& state) {
  const PeerCase c = kCases[state.range(0)];
  omp_set_num_threads(static_cast<int>(state.range(1)));
  DamBreakSpec spec;
  spec.column_width = 1.0;
  spec.column_height = 2.0;
  spec.tank_width = 4.0;
  spec.tank_height = 3.0;
  spec.spacing = c.dp;
  spec.h_factor = static_cast<double>(state.range(2)) / 1000.0;
  spec.mach_factor = 20.0 / std::sqrt(2.0);  // c0 = mach sqrt(2 g H) = 20 sqrt(g H)
  time_window(state, [&] { return make_dam_break(spec); }, c.window);
}

void peer_args(benchmark::internal::Benchmark* b) {
  for (int64_t k : {0, 1, 2})
    for (int64_t t : {1, 2})
      for (int64_t hf : {1414, 1200}) b->Args({k, t, hf});
}

BENCHMARK(BM_Peer_DamBreak)->Apply(peer_args)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)
    ->Unit(benchmark::kSecond)->UseRealTime();

// DualSPHysics' own 3D dam break, its example CaseDambreak (../shared/ANCHORS.md): a 0.4 x 0.67 x 0.3 m block
// of water at the end of a 1.6 x 0.67 x 0.4 m tank, a 0.12 x 0.12 x 0.45 m column at x = 0.9 m, y = 0.24 m;
// h = sqrt(3) dp (its coefh = 1) or our default 1.2 dp; c0 = 20 sqrt(g H); density diffusion 0.1; artificial
// viscosity 0.02; from rest over its windows. Walls: ghosts and Lennard-Jones particles at dp / 2, as our 2D
// dam break. Args: {dp index 0..2, threads, h/d x 1000}.
struct Peer3Case {
  double dp;
  double window;
};
constexpr Peer3Case kCases3[] = {{0.0135, 0.05}, {0.0085, 0.01}, {0.005, 0.001}};

void BM_Peer_DamBreak3D(benchmark::State& state) {
  const Peer3Case c = kCases3[state.range(0)];
  omp_set_num_threads(static_cast<int>(state.range(1)));
  DamBreak3Spec spec;
  spec.spacing = c.dp;
  spec.h_factor = static_cast<double>(state.range(2)) / 1000.0;
  time_window(state, [&] { return make_dam_break(spec); }, c.window);
}

void peer3_args(benchmark::internal::Benchmark* b) {
  for (int64_t k : {0, 1, 2})
    for (int64_t t : {1, 2})
      for (int64_t hf : {1732, 1200}) b->Args({k, t, hf});
}

BENCHMARK(BM_Peer_DamBreak3D)->Apply(peer3_args)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true)
    ->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
