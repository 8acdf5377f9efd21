// The same scene with and without each optional effect: an effect absent from the scene is not computed.
// The paper's dam break at 4x its particle count (cases/dam_break.json with d = 25/60 m), 200 steps from
// rest, one thread: all effects; without artificial viscosity; without ghost walls; without the
// Lennard-Jones wall; with dynamic AAP refinement added (v_threshold 10 m/s).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <string>
#include <vector>

#include "core/allocator_tuning.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"

#ifndef SPH_SOURCE_DIR
#error "SPH_SOURCE_DIR must name the repository root"
#endif

namespace {

using namespace sph;

const bool tuned = (tune_allocator(), true);

void BM_Scene_DamBreak(benchmark::State& state, std::vector<std::string> overrides) {
  omp_set_num_threads(1);
  overrides.push_back("fluid.0.spacing=0.4166666666666667");
  const scene::Scene sc = scene::load_scene(std::string(SPH_SOURCE_DIR) + "/cases/dam_break.json", overrides);
  std::size_t fluid = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Simulation sim = scene::build_simulation(sc);
    fluid = sim.diagnostics().fluid;
    state.ResumeTiming();
    for (int k = 0; k < 200; ++k) {
      sim.step();
      sim.run_stages();
    }
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * fluid * 200));
}

BENCHMARK_CAPTURE(BM_Scene_DamBreak, all_effects, std::vector<std::string>{})->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Scene_DamBreak, no_viscosity, std::vector<std::string>{"effects.artificial_viscosity=null"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Scene_DamBreak, no_ghost_walls, std::vector<std::string>{"effects.ghost_walls=null"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Scene_DamBreak, no_lennard_jones, std::vector<std::string>{"effects.lennard_jones_wall=null"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Scene_DamBreak, with_refinement,
                  std::vector<std::string>{"effects.refinement={\"criterion\": \"velocity\", \"v_threshold\": 10, "
                                           "\"pattern\": \"aap\", \"check_interval\": 100, \"max_level\": 1}"})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
