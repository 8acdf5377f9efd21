// Thread-count independence of whole steps with enough particles that every chunked stage (the sweep's
// reduction, the scans of the ghost expansion, the diagnostics) really splits across threads: the store
// after 100 dam-break steps (every field, ghosts and wall particles included, in store order) and the
// clock are bitwise identical at 1 and 2 threads. (test_solver's 576-particle dam break fits in one chunk
// of par::kChunk = 4096 items, where the chunked stages run on one thread whatever the thread count.)
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <type_traits>

#include "core/case_builder.hpp"
#include "parallel/parallel_for.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;

struct RunResult {
  ParticleStore<2> store;
  double time = 0.0, dt = 0.0;
  std::size_t pairs = 0;
};

RunResult run_dam_break(int threads, int steps) {
  omp_set_num_threads(threads);
  EXPECT_EQ(omp_get_max_threads(), threads);
  DamBreakSpec spec;
  spec.column_width = spec.column_height = 14.0;
  spec.tank_width = 28.0;
  spec.tank_height = 30.0;
  spec.spacing = 14.0 / 80.0;  // 6400 fluid particles, plus ghosts and wall particles
  Simulation sim = make_dam_break(spec);
  for (int k = 0; k < steps; ++k) sim.step();
  RunResult r;
  r.store = sim.store();
  r.time = sim.time();
  r.dt = sim.dt();
  r.pairs = sim.last_limits().pairs;
  return r;
}

TEST(Determinism, MultiChunkDamBreakIsBitwiseIdenticalAtOneAndTwoThreads) {
  const int threads = omp_get_max_threads();
  const int steps = test::short_runs() ? 30 : 100;  // shorter under the sanitizer preset
  const RunResult one = run_dam_break(1, steps);
  const RunResult two = run_dam_break(2, steps);
  omp_set_num_threads(threads);

  ASSERT_GT(one.store.size(), par::kChunk) << "too few particles for two chunks";
  EXPECT_EQ(one.time, two.time);
  EXPECT_EQ(one.dt, two.dt);
  EXPECT_EQ(one.pairs, two.pairs);
  EXPECT_EQ(one.store.next_id(), two.store.next_id());
  ASSERT_EQ(one.store.size(), two.store.size());
  EXPECT_TRUE(test::all_finite(one.store));
  one.store.for_each_field([&](const auto& f1) {
    two.store.for_each_field([&](const auto& f2) {
      if constexpr (std::is_same_v<std::decay_t<decltype(f1)>, std::decay_t<decltype(f2)>>) {
        if (f1.name() != f2.name()) return;
        std::size_t differing = 0;
        for (std::size_t i = 0; i < f1.size(); ++i) differing += f1[i] == f2[i] ? 0 : 1;
        EXPECT_EQ(differing, 0u) << "field " << std::string(f1.name());
      }
    });
  });
  // The run moved: the front (initially at 14 - d/2 = 13.9125 m) has advanced.
  double front = 0.0;
  for (std::size_t i = 0; i < one.store.size(); ++i)
    if (one.store.kind[i] == Kind::fluid) front = std::max(front, one.store.x[i][0]);
  if (!test::short_runs()) {
    EXPECT_GT(front, 13.92);
  }
}

}  // namespace
