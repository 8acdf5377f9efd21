// Buffered levels in a flow (issue #15): the dam break runs to its end and each refinement pass keeps the total
// energy. The buffered coupling's units (the band, the fit, the ties, the flips, the still tank) are in
// test_buffered_levels.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "core/scene/runner.hpp"
#include "core/scene/scene_parser.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;

// Issue #15 in a flow: the dam break (cases/dam_break_aap.json) with buffered levels, in the right-hand corner (a zone
// the flow runs into and out of, up the wall and back over the floor) and with the case's own velocity criterion,
// AAP and RSP. Fine particles carried out among coarse ones give the coarse ones their place (kIntermixReach); without
// that the corner run stopped at 3.22 s on a density error where two fine lattices overlapped (docs/METHOD.md,
// "Buffered levels"). Each run completes with the watchdog on and keeps its mass, and each refinement pass changes
// the total energy (kinetic, potential, elastic; passive particles are not counted) by at most 1e-6 of E(0), issue
// #15's target, measured just before and just after the pass: splits and flips give the daughters their parent's
// velocity and its density carried along a pressure gradient, so only the second-order elastic change and a wall
// rule's shift remain. (With coarsening, merges remove the families' motion about their centres of mass, which the
// pass log reports; that run checks no energy.) Under the sanitizer preset, the first 0.3 s.
struct FlowCase {
  const char* name;
  const char* refinement;  // the override of effects.refinement
  bool passes_keep_energy = true;
};

class BufferedFlow : public ::testing::TestWithParam<FlowCase> {};

TEST_P(BufferedFlow, DamBreakRunsToTheEndAndEachPassKeepsTheEnergy) {
  const std::filesystem::path root = std::filesystem::path(__FILE__).parent_path().parent_path();
  scene::Scene sc = scene::load_scene(root / "cases" / "dam_break_aap.json", {GetParam().refinement});
  if (test::short_runs()) sc.time.end = 0.3;
  sc.output.frames = false;
  scene::RunnerT<2> runner(sc, scene::RunOptions{});
  Simulation& sim = runner.simulation();
  const Diagnostics start = sim.diagnostics();  // the set-up's
  const double m0 = start.mass;
  const int interval = 100;  // the scenes' check interval, with one global step: a pass follows every 100th step
  int passes = 0;
  double largest = 0.0;
  ASSERT_NO_THROW({
    while (sim.time() < sc.time.end) {
      sim.step();
      if (sim.step_count() % interval != 0) {
        sim.run_stages();
        continue;
      }
      const Diagnostics before = sim.diagnostics();
      sim.run_stages();
      const Diagnostics after = sim.diagnostics();
      if (after.per_level == before.per_level && after.total_energy() == before.total_energy()) continue;
      ++passes;
      largest = std::max(largest, std::abs(after.total_energy() - before.total_energy()));
    }
  });
  RecordProperty("largest_pass_energy_change_over_E0", std::to_string(largest / start.total_energy()));
  EXPECT_GE(sim.time(), sc.time.end);
  // Passive particles are not counted: the active fluid keeps the set-up's mass. Its sum is exact and a daughter's
  // mass is an exact quarter of its parent's; adding the mass that left through the open top rounds once (1e-16).
  const Diagnostics end = sim.diagnostics();
  EXPECT_DOUBLE_EQ(end.mass + end.removed_mass, m0);  // within 4 ulps
  EXPECT_GT(passes, 0);
  if (GetParam().passes_keep_energy) {
    EXPECT_LE(largest, 1e-6 * start.total_energy());
  }
  if (!test::short_runs()) {
    EXPECT_GT(end.per_level.size() > 1 ? end.per_level[1] : 0u, 100u);  // it was refined
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BufferedFlow,
    ::testing::Values(FlowCase{"corner_zone", R"(effects.refinement={"criterion": "zone", "zone": {"lo": [44, 0], )"
                                              R"("hi": [50, 6]}, "pattern": "aap", "check_interval": 100, )"
                                              R"("max_level": 1, "coupling": "buffered"})"},
                      FlowCase{"corner_zone_rsp", R"(effects.refinement={"criterion": "zone", "zone": {"lo": [44, 0], )"
                                                  R"("hi": [50, 6]}, "pattern": "rsp", "check_interval": 100, )"
                                                  R"("max_level": 1, "coupling": "buffered"})"},
                      FlowCase{"velocity", "effects.refinement.coupling=buffered"},
                      FlowCase{"velocity_rsp", R"(effects.refinement={"criterion": "velocity", "v_threshold": 10, )"
                                               R"("pattern": "rsp", "check_interval": 100, "max_level": 1, )"
                                               R"("coupling": "buffered"})"},
                      // With coarsening (retract_buffered; merge threshold 5 m/s, hold 0.5 s: the defaults).
                      FlowCase{"velocity_coarsening",
                               R"(effects.refinement={"criterion": "velocity", )"
                               R"("v_threshold": 10, "pattern": "aap", "check_interval": 100, )"
                               R"("max_level": 1, "coupling": "buffered", "coarsening": {}})",
                               false}),
    [](const auto& p) { return std::string(p.param.name); });

}  // namespace
