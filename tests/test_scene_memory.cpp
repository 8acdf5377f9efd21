// The memory a run needs, estimated from the scene before anything is allocated: the particle estimates
// bound what the case files really build (fluid, ghosts, walls), the estimate covers the store after steps,
// and a scene is refused exactly when its estimate exceeds the memory available (a parameter here; the
// program passes what the machine has).
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "core/particle_store.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"

#include "tests/support/io_helpers.hpp"

namespace {

using namespace sph;
using namespace sph::scene;

const std::filesystem::path kCases = std::filesystem::path(__FILE__).parent_path().parent_path() / "cases";
constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;

TEST(SceneMemory, ParticleEstimatesBoundWhatEveryCaseBuilds) {
  int n = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(kCases)) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    const Scene s = load_scene(entry.path());
    struct Counts {
      std::size_t fluid, ghosts, walls;
    };
    const Counts d = with_dimension(s, [&](auto dim) {
      const auto diag = build_simulation<decltype(dim)::value>(s).diagnostics();
      return Counts{diag.fluid, diag.ghosts, diag.walls};
    });
    EXPECT_LE(static_cast<double>(d.fluid), estimated_fluid_particles(s));
    EXPECT_GE(static_cast<double>(d.fluid), 0.7 * estimated_fluid_particles(s)) << "the circles' estimate is an upper one";
    EXPECT_LE(static_cast<double>(d.ghosts), estimated_ghost_particles(s));
    EXPECT_LE(static_cast<double>(d.walls), estimated_wall_particles(s));
    EXPECT_EQ(s.effects.ghost_walls.has_value(), d.ghosts > 0);
    EXPECT_EQ(s.effects.lennard_jones_wall.has_value(), d.walls > 0);
    EXPECT_LE(static_cast<double>(d.fluid + d.ghosts + d.walls), estimated_memory(s, 1).particles);
    ++n;
  }
  EXPECT_GE(n, 10);
}

TEST(SceneMemory, GhostBoundFollowsTheWettedWalls) {
  // A thin sheet on the floor of a long tank: with h_factor 3 every particle in the six lowest rows is within
  // 2h of the floor, so ghosts are most of the fluid; the bound from the walls' lengths stays within 10 %.
  const Scene s = scene_from_json(parse_json_text(R"({
    "container": { "lo": [0, 0], "hi": [20, 1] },
    "fluid": [ { "shape": "rectangle", "lo": [0, 0], "hi": [20, 0.03], "spacing": 0.01 } ],
    "h_factor": 3,
    "material": { "rho0": 1000, "c0": 10 },
    "effects": { "ghost_walls": "free-slip", "static_refinement": {} },
    "time": { "end": 0.01 }
  })", "sheet"));
  const Diagnostics d = build_simulation(s).diagnostics();
  EXPECT_EQ(d.fluid, 24000u);
  EXPECT_GT(d.ghosts, 24000u);  // the floor's six rows and the ends' columns and corners
  EXPECT_GE(estimated_ghost_particles(s), static_cast<double>(d.ghosts));
  EXPECT_LE(estimated_ghost_particles(s), 1.1 * static_cast<double>(d.ghosts));
}

TEST(SceneMemory, TheEstimateCoversTheStoreAfterSteps) {
  const Scene s = load_scene(kCases / "dam_break.json", {"fluid[0].spacing=0.2"});
  Simulation sim = build_simulation(s);
  for (int k = 0; k < 3; ++k) sim.step();
  const MemoryEstimate m = estimated_memory(s, 1);
  EXPECT_LE(static_cast<double>(sim.store().size()), m.particles);
  // The store's fields and their gather scratch; the estimate adds the rollback copy and the workspaces.
  EXPECT_LE(static_cast<double>(sim.store().bytes()), m.bytes);
  EXPECT_GE(m.bytes, m.particles * 3.0 * ParticleStore<2>::bytes_per_particle());
}

TEST(SceneMemory, RefusesWhatDoesNotFitAndAcceptsWhatDoes) {
  // The paper's dam at a spacing 185 times finer: 31 million fluid particles, under the 5e7-particle cap.
  const Scene big = load_scene(kCases / "dam_break.json", {"fluid[0].spacing=0.0045"});
  const MemoryEstimate need = estimated_memory(big, 2);
  EXPECT_GT(need.particles, 3.0e7);
  EXPECT_LT(need.particles, 3.2e7);
  const double each = need.bytes / need.particles;
  EXPECT_GT(each, 3.0 * ParticleStore<2>::bytes_per_particle());
  EXPECT_LT(each, 3.0 * ParticleStore<2>::bytes_per_particle() + 100.0);

  const std::string refusal = memory_refusal(need, 8.0 * kGiB);
  EXPECT_TRUE(std::regex_match(refusal, std::regex(R"(the scene needs about \d\d\.\d GiB \(31,\d\d\d,\d\d\d particles at ~\d\d\d B each\) but 8\.0 GiB are available)")))
      << refusal;
  EXPECT_EQ(memory_refusal(need, 1024.0 * kGiB), "");
  EXPECT_EQ(memory_refusal(need, need.bytes), "") << "exactly enough is enough";

  // The paper's own dam needs a few MiB: refused only when almost nothing is available.
  const MemoryEstimate small = estimated_memory(load_scene(kCases / "dam_break.json"), 2);
  EXPECT_LT(small.bytes, 16.0 * 1024 * 1024);
  EXPECT_EQ(memory_refusal(small, 1.0 * kGiB), "");
  EXPECT_EQ(memory_refusal(small, 1024.0 * 1024).rfind("the scene needs about ", 0), 0u);
  EXPECT_NE(memory_refusal(small, 1024.0 * 1024).find(" but 1 MiB are available"), std::string::npos)
      << memory_refusal(small, 1024.0 * 1024);
}

TEST(SceneMemory, TextGroupsDigitsAndPicksUnits) {
  EXPECT_EQ(to_string(MemoryEstimate{31096143.0, 31096143.0 * 454.0}), "about 13.1 GiB (31,096,143 particles at ~454 B each)");
  EXPECT_EQ(to_string(MemoryEstimate{1000.0, 1.4e6}), "about 1 MiB (1,000 particles at ~1.4 kB each)");
  EXPECT_EQ(memory_text(22.8 * kGiB), "22.8 GiB");
  EXPECT_EQ(memory_text(512.0 * 1024 * 1024), "512 MiB");
}

}  // namespace
