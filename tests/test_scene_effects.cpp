// Scene keys reach the solver settings: the ghost pressure choice, and an absent effect stays absent.
#include <gtest/gtest.h>

#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"

namespace {

using namespace sph;

const char* kTank = R"({
  "name": "tank",
  "container": { "lo": [0, 0], "hi": [4, 3] },
  "fluid": [ { "shape": "rectangle", "lo": [0, 0], "hi": [4, 1], "spacing": 0.25, "hydrostatic": true } ],
  "material": { "rho0": 1000, "c0": 20 },
  "effects": { "gravity": [0, -9.81], "ghost_walls": "free-slip" GHOST },
  "time": { "end": 0.01 }
})";

Simulation build(const std::string& ghost) {
  std::string text = kTank;
  text.replace(text.find("GHOST"), 5, ghost);
  return scene::build_simulation(scene::scene_from_json(scene::parse_json_text(text, "tank")));
}

TEST(SceneEffects, GhostPressureKeyChoosesTheGhostPressure) {
  EXPECT_EQ(build("").settings().ghost_pressure, GhostPressure::hydrostatic);
  EXPECT_EQ(build(R"(, "ghost_pressure": "mirrored")").settings().ghost_pressure, GhostPressure::mirrored);
  EXPECT_EQ(build(R"(, "ghost_pressure": "hydrostatic")").settings().ghost_pressure, GhostPressure::hydrostatic);
}

TEST(SceneEffects, AbsentEffectsAreAbsentFromTheSettingsAndTheSweep) {
  const Simulation sim = build("");
  EXPECT_FALSE(sim.settings().viscosity.has_value());
  EXPECT_FALSE(sim.settings().lennard_jones.has_value());
  EXPECT_STREQ(sim.sweep_name(), "continuity+pressure");
  EXPECT_EQ(sim.diagnostics().walls, 0u);
}

}  // namespace
