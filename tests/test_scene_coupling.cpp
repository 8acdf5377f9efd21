// effects.refinement.coupling in scene files: "buffered" is accepted where buffered levels are built, round-trips,
// and is refused with a message naming the key where they are not (core/scene/scene_validator.cpp); and the daughters'
// density rule, whose default follows the coupling.
#include <gtest/gtest.h>

#include <string>

#include "core/scene/scene_parser.hpp"
#include "tests/support/scene_documents.hpp"

namespace {

using namespace sph::scene;
using sph::test::error_of;
using sph::test::full_scene;

TEST(SceneCoupling, BufferedIsRefusedWhereItIsNotBuiltYet) {
  Json doc = full_scene();
  doc["fluid"][1]["level"] = 0;  // one starting level: with buffered levels, levels meet only through splits
  doc["effects"]["refinement"]["coupling"] = "buffered";
  ASSERT_EQ(error_of(doc), "");
  const Scene s = scene_from_json(doc);
  EXPECT_EQ(s.effects.refinement->coupling, sph::LevelCoupling::buffered);
  EXPECT_EQ(scene_from_json(scene_to_json(s)), s);
  const std::string refused = "scene error: effects.refinement.coupling: \"buffered\" ";
  Json coarsening = doc;  // a shadow takes its own family's place back (retract_buffered)
  coarsening["effects"]["refinement"]["coarsening"] = Json::object();
  EXPECT_EQ(error_of(coarsening), "");
  coarsening["effects"]["refinement"]["coarsening"]["groups"] = "cell";
  EXPECT_EQ(error_of(coarsening).rfind("scene error: effects.refinement.coarsening.groups: \"buffered\" merges", 0), 0u)
      << error_of(coarsening);
  Json per_level = doc;  // each level in its own time bins: no pair crosses levels, so no impulse is shared across bins
  per_level["time"]["stepping"] = "per_level";
  EXPECT_EQ(error_of(per_level), "");
  Json velocity = doc;  // the paper's criterion: buffered levels follow it (the dam break and the drop complete)
  velocity["effects"]["refinement"] = Json{{"v_threshold", 5}, {"coupling", "buffered"}};
  EXPECT_EQ(error_of(velocity), "");
  EXPECT_EQ(scene_from_json(velocity).effects.refinement->coupling, sph::LevelCoupling::buffered);
  Json few = doc;
  few["effects"]["refinement"] = Json{{"criterion", "few_neighbours"}, {"min_neighbours", 8}, {"coupling", "buffered"}};
  EXPECT_EQ(
      error_of(few).rfind("scene error: effects.refinement.coupling: unknown key; allowed for criterion few_neighbours", 0),
      0u)
      << error_of(few);
  Json two_levels = doc;
  two_levels["fluid"][1]["level"] = 1;
  EXPECT_EQ(error_of(two_levels).rfind(refused + "needs every fluid region at one starting level", 0), 0u)
      << error_of(two_levels);
  Json with_static = doc;
  with_static["effects"]["static_refinement"] = Json::object();
  with_static["effects"]["refinement"]["max_level"] = 3;
  EXPECT_EQ(error_of(with_static).rfind(refused + "cannot follow effects.static_refinement", 0), 0u)
      << error_of(with_static);
  doc["effects"]["refinement"]["coupling"] = "apr";
  EXPECT_EQ(error_of(doc), "scene error: effects.refinement.coupling: must be one of: mixed, buffered (got 'apr')");
}

// effects.refinement.daughter_density: absent, it follows the coupling (pressure_gradient with buffered, the paper's
// parent copy with mixed); given, it holds for either coupling and round-trips; other names are refused.
TEST(SceneCoupling, DaughterDensityFollowsTheCouplingUnlessGiven) {
  Json doc = full_scene();
  doc["fluid"][1]["level"] = 0;
  const auto rule = [](const Json& d) { return scene_from_json(d).effects.refinement->daughter_density_rule(); };
  EXPECT_EQ(rule(doc), sph::refine::DaughterDensity::parent);
  Json buffered = doc;
  buffered["effects"]["refinement"]["coupling"] = "buffered";
  EXPECT_EQ(rule(buffered), sph::refine::DaughterDensity::pressure_gradient);
  buffered["effects"]["refinement"]["daughter_density"] = "parent";
  EXPECT_EQ(rule(buffered), sph::refine::DaughterDensity::parent);
  doc["effects"]["refinement"]["daughter_density"] = "pressure_gradient";
  EXPECT_EQ(rule(doc), sph::refine::DaughterDensity::pressure_gradient);
  const Scene s = scene_from_json(doc);
  EXPECT_EQ(scene_from_json(scene_to_json(s)), s);
  doc["effects"]["refinement"]["daughter_density"] = "mean";
  EXPECT_EQ(error_of(doc),
            "scene error: effects.refinement.daughter_density: must be one of: parent, pressure_gradient (got 'mean')");
}

}  // namespace
