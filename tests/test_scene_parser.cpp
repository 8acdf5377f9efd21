// Scene files: a round trip (JSON -> Scene -> JSON -> Scene) is the identity, every case file validates,
// and each kind of bad input is refused with one "scene error: <key.path>: <rule>" naming the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <filesystem>
#include <string>
#include <vector>

#include "core/scene/scene_keys.hpp"
#include "core/scene/scene_parser.hpp"
#include "tests/support/scene_documents.hpp"

namespace {

using namespace sph::scene;
using sph::test::error_of;
using sph::test::full_scene;

const std::filesystem::path kCases = std::filesystem::path(__FILE__).parent_path().parent_path() / "cases";

std::string detail_num(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

TEST(SceneParser, FullSceneParsesWithEveryValue) {
  const Scene s = scene_from_json(full_scene());
  EXPECT_EQ(s.name, "full");
  EXPECT_FALSE(s.container.open_top);
  ASSERT_EQ(s.fluid.size(), 2u);
  EXPECT_EQ(s.fluid[1].shape, Shape::circle);
  EXPECT_EQ(s.fluid[1].level, 1);
  EXPECT_DOUBLE_EQ(s.fluid[1].lattice_spacing(), 0.25);
  EXPECT_EQ(s.effects.ghost_walls, Slip::no_slip);
  ASSERT_TRUE(s.effects.artificial_stress);
  EXPECT_EQ(s.effects.artificial_stress->epsilon, 0.3);
  EXPECT_EQ(s.effects.artificial_stress->exponent, 3);
  ASSERT_TRUE(s.effects.density_diffusion);
  EXPECT_EQ(s.effects.density_diffusion->delta, 0.12);
  ASSERT_TRUE(s.effects.refinement);
  EXPECT_EQ(s.effects.refinement->criterion, Criterion::zone);
  EXPECT_EQ(s.effects.refinement->pattern, Pattern::rsp);
  EXPECT_FALSE(s.effects.static_refinement);
  EXPECT_EQ(s.probes[1].name, "surge_front_1");  // default name: kind and index
  EXPECT_DOUBLE_EQ(sound_speed(s), 10.0 * std::sqrt(2.0 * 9.81 * 5.0));
  EXPECT_DOUBLE_EQ(lennard_jones_strength(s), 5.0 * 9.81 * 5.0);
  EXPECT_EQ(finest_level(s), 2);
  EXPECT_DOUBLE_EQ(finest_spacing(s), 0.125);
  EXPECT_DOUBLE_EQ(wall_spacing(s), 0.0625);
}

TEST(SceneParser, RoundTripIsIdentity) {
  const Scene s = scene_from_json(full_scene());
  const Json j = scene_to_json(s);
  const Scene again = scene_from_json(j);
  EXPECT_EQ(again, s);
  EXPECT_EQ(scene_to_json(again), j);
  // And through text.
  EXPECT_EQ(scene_from_json(parse_json_text(j.dump(2), "text")), s);
}

TEST(SceneParser, OutflowIsStopOrRemoveAndRemoveNeedsAnOpenTop) {
  Json doc = full_scene();
  EXPECT_EQ(scene_from_json(doc).container.outflow, sph::Outflow::stop) << "the default";
  doc["container"]["open_top"] = true;
  doc["container"]["outflow"] = "remove";
  const Scene s = scene_from_json(doc);
  EXPECT_EQ(s.container.outflow, sph::Outflow::remove);
  const Json j = scene_to_json(s);
  EXPECT_EQ(j.at("container").at("outflow"), "remove") << "the writer keeps it";
  EXPECT_EQ(scene_from_json(j), s);
  EXPECT_EQ(scene_from_json(parse_json_text(j.dump(2), "text")), s);
  doc["container"]["outflow"] = "drain";
  EXPECT_EQ(error_of(doc), "scene error: container.outflow: must be one of: stop, remove (got 'drain')");
  doc["container"]["outflow"] = 1;
  EXPECT_EQ(error_of(doc), "scene error: container.outflow: must be a string (got an integer)");
  doc["container"]["outflow"] = "remove";
  doc["container"]["open_top"] = false;
  EXPECT_EQ(error_of(doc), "scene error: container.outflow: \"remove\" needs an open top (open_top: true): a closed "
                           "container has no opening to leave through");
  doc["container"]["outflow"] = "stop";
  EXPECT_EQ(error_of(doc), "");
}

TEST(SceneParser, EveryCaseFileValidatesAndRoundTrips) {
  int n = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(kCases)) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    const Scene s = load_scene(entry.path());
    EXPECT_EQ(scene_from_json(scene_to_json(s)), s);
    ++n;
  }
  EXPECT_GE(n, 10);
}

TEST(SceneParser, AbsentEffectsStayAbsent) {
  Json doc = full_scene();
  doc.erase("effects");
  doc["material"] = Json{{"rho0", 1000}, {"c0", 30}};
  doc["fluid"][0].erase("hydrostatic");
  doc["fluid"][0].erase("surface");
  const Scene s = scene_from_json(doc);
  EXPECT_FALSE(s.effects.gravity);
  EXPECT_FALSE(s.effects.artificial_viscosity);
  EXPECT_FALSE(s.effects.artificial_stress);
  EXPECT_FALSE(s.effects.density_diffusion);
  EXPECT_FALSE(s.effects.lennard_jones_wall);
  EXPECT_FALSE(s.effects.ghost_walls);
  EXPECT_FALSE(s.effects.refinement);
}

TEST(SceneParser, UnknownKeyNamesThePathAndSuggests) {
  Json doc = full_scene();
  doc["fluid"][0]["spacng"] = 0.5;
  EXPECT_EQ(error_of(doc).rfind("scene error: fluid[0].spacng: unknown key (did you mean 'spacing'?)", 0), 0u) << error_of(doc);
  doc = full_scene();
  doc["effects"]["gravty"] = Json::array({0, -9.81});
  EXPECT_NE(error_of(doc).find("scene error: effects.gravty: unknown key (did you mean 'gravity'?)"), std::string::npos);
  doc = full_scene();
  doc["tme"] = 1;
  EXPECT_NE(error_of(doc).find("scene error: tme: unknown key (did you mean 'time'?)"), std::string::npos);
}

TEST(SceneParser, KeyOfAnotherShapeIsUnknown) {
  Json doc = full_scene();
  doc["fluid"][0]["radius"] = 1.0;
  EXPECT_NE(error_of(doc).find("scene error: fluid[0].radius: unknown key"), std::string::npos);
  EXPECT_NE(error_of(doc).find("for a rectangle"), std::string::npos);
}

TEST(SceneParser, WrongTypeIsRefused) {
  Json doc = full_scene();
  doc["time"]["end"] = "long";
  EXPECT_EQ(error_of(doc), "scene error: time.end: must be a number (got a string)");
  doc = full_scene();
  doc["container"]["open_top"] = 1;
  EXPECT_EQ(error_of(doc), "scene error: container.open_top: must be true or false (got an integer)");
  doc = full_scene();
  doc["fluid"][1]["centre"] = Json::array({1, 2, 3, 4});
  EXPECT_EQ(error_of(doc), "scene error: fluid[1].centre: must be an array of two numbers [x, y] (2D) or three [x, y, z] "
                           "(3D) (got an array of 4)");
  doc = full_scene();
  doc["fluid"][1]["centre"] = Json::array({1, 2, 3});
  EXPECT_EQ(error_of(doc), "scene error: fluid[1].centre: has 3 numbers, but the scene is 2D (container.lo has 2): write "
                           "two numbers [x, y]");
  doc = full_scene();
  doc["effects"]["refinement"]["max_level"] = 1.5;
  EXPECT_EQ(error_of(doc), "scene error: effects.refinement.max_level: must be an integer (got a number)");
  doc = full_scene();
  doc["effects"]["ghost_walls"] = "slippery";
  EXPECT_EQ(error_of(doc), "scene error: effects.ghost_walls: must be one of: free-slip, no-slip (got 'slippery')");
}

TEST(SceneParser, MissingRequiredKeyIsRefused) {
  Json doc = full_scene();
  doc["time"].erase("end");
  EXPECT_EQ(error_of(doc), "scene error: time.end: missing required key");
  doc = full_scene();
  doc.erase("container");
  EXPECT_EQ(error_of(doc), "scene error: container: missing required key");
  doc = full_scene();
  doc["fluid"][0].erase("spacing");
  EXPECT_EQ(error_of(doc), "scene error: fluid[0].spacing: missing required key");
  doc = full_scene();
  doc["material"] = Json{{"rho0", 1000}};
  EXPECT_NE(error_of(doc).find("scene error: material.c0: missing required key"), std::string::npos);
}

TEST(SceneParser, NonPhysicalValuesAreRefused) {
  struct Case {
    const char* path;
    Json value;
    const char* expected;
  };
  const Case cases[] = {
      {"/fluid/0/spacing", 0.0, "scene error: fluid[0].spacing: must be positive (got 0)"},
      {"/fluid/1/spacing", -0.5, "scene error: fluid[1].spacing: must be positive (got -0.5)"},
      {"/material/rho0", -1000.0, "scene error: material.rho0: must be positive (got -1000)"},
      {"/time/end", -1.0, "scene error: time.end: must be positive (got -1)"},
      {"/time/cfl", 2.0, "scene error: time.cfl: must be in (0, 1] (got 2)"},
      {"/h_factor", 0.1, "scene error: h_factor: must be between 0.5 and 3 (got 0.1)"},
      {"/fluid/1/radius", 0.0, "scene error: fluid[1].radius: must be positive (got 0)"},
      {"/effects/artificial_viscosity/alpha", -0.1, "scene error: effects.artificial_viscosity.alpha: must not be negative (got -0.1)"},
      {"/effects/artificial_stress/epsilon", 0.0, "scene error: effects.artificial_stress.epsilon: must be in (0, 1] (got 0)"},
      {"/effects/artificial_stress/exponent", 0, "scene error: effects.artificial_stress.exponent: must be between 1 and 16 (got 0)"},
      {"/effects/artificial_stress/exponent", 2.5, "scene error: effects.artificial_stress.exponent: must be an integer (got a number)"},
      {"/effects/density_diffusion/delta", -0.1, "scene error: effects.density_diffusion.delta: must be in (0, 1] (got -0.1)"},
      {"/effects/refinement/check_interval", 0, "scene error: effects.refinement.check_interval: must be at least 1 (got 0)"},
      {"/time/dt_max", 1e-12, "scene error: time.dt_max: would take more than 1e9 steps to reach time.end"},
      {"/time/output_interval", 0.0, "scene error: time.output_interval: must be positive (got 0)"},
  };
  for (const Case& c : cases) {
    Json doc = full_scene();
    doc[Json::json_pointer(c.path)] = c.value;
    EXPECT_EQ(error_of(doc), c.expected) << c.path;
  }
  Json doc = full_scene();
  doc["material"] = Json{{"rho0", 1000}, {"c0", 0}};
  EXPECT_EQ(error_of(doc), "scene error: material.c0: must be positive (got 0)");
}

/// Scenes that together hold every ranged key: full_scene() and two variants with the keys it leaves out (the
/// per-key ranges are checked before the rules across keys, so these need only parse).
std::vector<Json> scenes_with_every_key() {
  Json other = full_scene();
  other["material"] = Json{{"rho0", 1000}, {"c0", 30}, {"reference_speed", 3}};
  other["effects"]["lennard_jones_wall"] = Json{{"strength", 100}, {"spacing", 0.05}};
  other["effects"]["refinement"] = Json{{"v_threshold", 5}, {"max_level", 2}, {"coarsening", Json{{"hold_time", 1}}}};
  other["time"]["bin_jump"] = 1;
  other["effects"]["static_refinement"] = Json{{"rsp_k", 1}};
  Json few = full_scene();
  few["effects"]["refinement"] = Json{{"criterion", "few_neighbours"}, {"min_neighbours", 6}, {"max_level", 2}};
  return {full_scene(), other, few};
}

/// Every key the registry gives a range is refused just outside it, naming the key and the range: the
/// validator's per-key checks come from the registry.
TEST(SceneParser, EveryRangedKeyIsRefusedOutsideItsRange) {
  int ranged = 0, tested = 0;
  for (const KeyEntry& e : all_keys()) {
    if (!e.key->range) continue;
    ++ranged;
    bool found = false;
    for (const Json& base : scenes_with_every_key()) {
      for (const char* index : {"0", "1", "2", "3"}) {
        std::string path = e.path;
        for (std::size_t at = path.find("[i]"); at != std::string::npos; at = path.find("[i]")) {
          path.replace(at, 3, std::string("[") + index + "]");
        }
        std::string pointer = "/" + path;
        for (char& c : pointer) c = (c == '.' || c == '[') ? '/' : c;
        pointer.erase(std::remove(pointer.begin(), pointer.end(), ']'), pointer.end());
        if (!base.contains(Json::json_pointer(pointer))) continue;
        Json doc = base;
        const Range& r = *e.key->range;
        const double bad = r.has_lo ? (r.lo_open ? r.lo : r.lo - 1.0) : r.hi + 1.0;
        if (e.key->type == KeyType::integer) {
          doc[Json::json_pointer(pointer)] = static_cast<int>(bad);
        } else {
          doc[Json::json_pointer(pointer)] = bad;
        }
        EXPECT_EQ(error_of(doc), "scene error: " + path + ": " + r.rule() + " (got " + detail_num(bad) + ")");
        found = true;
        break;
      }
      if (found) break;
    }
    EXPECT_TRUE(found) << e.path << " is in none of the test scenes";
    tested += found ? 1 : 0;
  }
  EXPECT_EQ(tested, ranged);
  EXPECT_GE(ranged, 30);
}

TEST(SceneParser, MisplacedKeysNameWhatTheyAreAllowedFor) {
  Json doc = full_scene();
  doc["fluid"][0]["spacng"] = 0.5;
  EXPECT_EQ(error_of(doc), "scene error: fluid[0].spacng: unknown key (did you mean 'spacing'?); allowed for a rectangle: "
                           "shape, lo, hi, spacing, level, velocity, hydrostatic, surface");
  doc = full_scene();
  doc["probes"][3]["x"] = 1;
  EXPECT_EQ(error_of(doc), "scene error: probes[3].x: unknown key; allowed for a pressure probe: type, name, position");
  doc = full_scene();
  doc["effects"]["refinement"]["coarsening"] = Json{{"min_neighbours", 20}};
  EXPECT_EQ(error_of(doc), "scene error: effects.refinement.coarsening.min_neighbours: unknown key; allowed for criterion "
                           "zone: hold_time, groups");
  doc = full_scene();
  doc["effects"]["refinement"]["v_threshold"] = 3;
  EXPECT_EQ(error_of(doc).rfind("scene error: effects.refinement.v_threshold: unknown key; allowed for criterion zone: ", 0),
            0u)
      << error_of(doc);
  doc = full_scene();
  doc["fluid"][1].erase("shape");
  EXPECT_EQ(error_of(doc), "scene error: fluid[1].shape: missing required key (one of: rectangle, circle)");
  doc = full_scene();
  doc["time"]["stepping"] = "sometimes";
  EXPECT_EQ(error_of(doc), "scene error: time.stepping: must be one of: global, per_level (got 'sometimes')");
}

TEST(SceneParser, CoarseningDefaultsFollowTheSplitTest) {
  Json doc = full_scene();
  doc["effects"]["refinement"] = Json{{"v_threshold", 8}, {"coarsening", Json::object()}, {"max_level", 2}};
  Scene s = scene_from_json(doc);
  ASSERT_TRUE(s.effects.refinement->coarsening);
  EXPECT_EQ(s.effects.refinement->coarsening->v_threshold, 4.0);
  EXPECT_EQ(s.effects.refinement->coarsening->hold_time, sph::refine::CoarseningSettings{}.hold_time);
  EXPECT_EQ(s.effects.refinement->coarsening->groups, sph::refine::MergeGroups::family) << "the daughters of one parent";
  EXPECT_EQ(scene_from_json(scene_to_json(s)), s);
  doc["effects"]["refinement"]["coarsening"] = Json{{"groups", "cell"}};
  s = scene_from_json(doc);
  EXPECT_EQ(s.effects.refinement->coarsening->groups, sph::refine::MergeGroups::cell);
  EXPECT_EQ(scene_from_json(scene_to_json(s)), s);
  doc["effects"]["refinement"]["coarsening"] = Json{{"groups", "neighbours"}};
  EXPECT_EQ(error_of(doc), "scene error: effects.refinement.coarsening.groups: must be one of: family, cell (got 'neighbours')");
  doc["effects"]["refinement"] = Json{{"criterion", "few_neighbours"}, {"min_neighbours", 6}, {"coarsening", Json::object()},
                                      {"max_level", 2}};
  s = scene_from_json(doc);
  EXPECT_EQ(s.effects.refinement->coarsening->min_neighbours, 12);
  EXPECT_EQ(s.effects.refinement->coarsening->v_threshold, sph::refine::CoarseningSettings{}.v_threshold)
      << "a key the criterion does not allow keeps the struct's value";
  EXPECT_EQ(scene_from_json(scene_to_json(s)), s);
}

TEST(SceneParser, WriterWritesDefaultsAndLeavesAbsentKeysOut) {
  Json doc = full_scene();
  doc["effects"].erase("density_diffusion");
  doc.erase("description");
  const Json j = scene_to_json(scene_from_json(doc));
  EXPECT_EQ(j.at("time").at("stepping"), "global");
  EXPECT_EQ(j.at("effects").at("ghost_pressure"), "hydrostatic");
  EXPECT_EQ(j.at("fluid")[1].at("hydrostatic"), false);
  EXPECT_FALSE(j.at("effects").contains("density_diffusion"));
  EXPECT_FALSE(j.contains("description"));
  EXPECT_FALSE(j.at("fluid")[1].contains("lo")) << "a circle writes no rectangle keys";
  EXPECT_FALSE(j.at("probes")[1].contains("origin") && !doc.at("probes")[1].contains("origin"));
}

TEST(SceneParser, RegionOutsideTheContainerIsRefused) {
  Json doc = full_scene();
  doc["fluid"][0]["hi"] = Json::array({25, 5});
  EXPECT_EQ(error_of(doc), "scene error: fluid[0]: the rectangle reaches outside the container");
  doc = full_scene();
  doc["fluid"][1]["centre"] = Json::array({19.5, 7});
  EXPECT_EQ(error_of(doc), "scene error: fluid[1]: the circle reaches outside the container");
}

TEST(SceneParser, RegionInsideAnObstacleIsRefused) {
  Json doc = full_scene();
  doc["fluid"][0]["lo"] = Json::array({13, 0});
  doc["fluid"][0]["hi"] = Json::array({16, 2});
  EXPECT_EQ(error_of(doc),
            "scene error: fluid[0]: overlaps obstacles[0] (fluid must start outside every obstacle)");
}

/// A rectangle region (level 0, spacing 0.5) as JSON.
Json rectangle(double x0, double y0, double x1, double y1, double spacing = 0.5) {
  return Json{{"shape", "rectangle"}, {"lo", Json::array({x0, y0})}, {"hi", Json::array({x1, y1})}, {"spacing", spacing}};
}
Json circle(double x, double y, double radius) {
  return Json{{"shape", "circle"}, {"centre", Json::array({x, y})}, {"radius", radius}, {"spacing", 0.5}};
}

TEST(SceneParser, OverlappingFluidRegionsAreRefused) {
  // full_scene: fluid[0] the rectangle [0, 0] .. [5, 5], fluid[1] the circle at [8, 7] radius 1.
  auto with_region = [](const Json& region) {
    Json doc = full_scene();
    doc["fluid"].push_back(region);
    return doc;
  };
  // Rectangle and rectangle: the message names both regions, with their extents.
  EXPECT_EQ(error_of(with_region(rectangle(4, 4, 6, 6))),
            "scene error: fluid[2]: overlaps fluid[0] (fluid[2]: rectangle [4, 4] .. [6, 6]; fluid[0]: rectangle [0, 0] .. "
            "[5, 5]); fluid regions must not overlap, or the common part would hold the particles of both");
  EXPECT_NE(error_of(with_region(rectangle(1, 1, 2, 2))).find("fluid[2]: overlaps fluid[0]"), std::string::npos)
      << "a rectangle inside another";
  // Circle and rectangle, either order.
  EXPECT_EQ(error_of(with_region(circle(5.5, 4, 1))).rfind("scene error: fluid[2]: overlaps fluid[0] (fluid[2]: circle at "
                                                          "[5.5, 4] radius 1; fluid[0]: rectangle [0, 0] .. [5, 5])", 0),
            0u)
      << error_of(with_region(circle(5.5, 4, 1)));
  EXPECT_EQ(error_of(with_region(rectangle(7, 5, 9, 6.5))).rfind("scene error: fluid[2]: overlaps fluid[1] (", 0), 0u)
      << error_of(with_region(rectangle(7, 5, 9, 6.5)));
  EXPECT_EQ(error_of(with_region(circle(2.5, 2.5, 0.5))).rfind("scene error: fluid[2]: overlaps fluid[0] (", 0), 0u)
      << "a circle inside a rectangle";
  // Circle and circle, overlapping or touching (both lattices would hold the point of contact [9, 7]).
  EXPECT_EQ(error_of(with_region(circle(9.5, 7, 1))).rfind("scene error: fluid[2]: overlaps or touches fluid[1] (", 0), 0u)
      << error_of(with_region(circle(9.5, 7, 1)));
  EXPECT_NE(error_of(with_region(circle(10, 7, 1))).find("circles must not touch"), std::string::npos)
      << error_of(with_region(circle(10, 7, 1)));

  // Regions that only touch are accepted: rectangles sharing an edge (same or different spacing) or a corner,
  // a circle touching a rectangle's side or corner, circles apart.
  for (const Json& region : {rectangle(5, 0, 7, 5), rectangle(0, 5, 5, 6, 0.25), rectangle(5, 5, 6, 6), circle(6, 4, 1),
                             circle(5.5, 5.5, std::sqrt(0.5)), rectangle(7, 5, 9, 6), circle(10.5, 7, 1)}) {
    EXPECT_EQ(error_of(with_region(region)), "") << region.dump();
  }
  // Coordinates given as decimals: 0.1 + 0.2 is not exactly 0.3, still only touching.
  Json doc = with_region(rectangle(0.1 + 0.2, 5, 4, 6));
  doc["fluid"].push_back(rectangle(0, 5, 0.3, 6, 0.1));
  EXPECT_EQ(error_of(doc), "");
}

TEST(SceneParser, UnresolvableRefinementLevelIsRefused) {
  // Explicit wall spacing 0.25 m: level 2 (d = 0.125 m, r0 = 0.0625 m) would slip between wall particles.
  Json doc = full_scene();
  doc["effects"]["lennard_jones_wall"]["spacing"] = 0.25;
  const std::string e = error_of(doc);
  EXPECT_EQ(e.rfind("scene error: effects.lennard_jones_wall.spacing: the walls cannot resolve level 2", 0), 0u) << e;
  // Lowering max_level to what the walls resolve (level 0, d = 0.5, r0 = 0.25) is accepted... but the circle
  // starts at level 1, so max_level must also exceed the starting level: a separate rule.
  doc["effects"]["refinement"]["max_level"] = 1;
  EXPECT_EQ(error_of(doc).rfind("scene error: effects.refinement.max_level: must exceed the particles' starting level 1", 0), 0u)
      << error_of(doc);
  doc["effects"]["refinement"]["max_level"] = 2;
  doc["effects"]["lennard_jones_wall"].erase("spacing");
  doc["effects"]["lennard_jones_wall"]["r0_factor"] = 0.25;  // r0 = d/4 < default wall spacing d/2
  EXPECT_EQ(error_of(doc).rfind("scene error: effects.lennard_jones_wall.r0_factor: the walls cannot resolve level 2", 0), 0u)
      << error_of(doc);
  doc["effects"]["refinement"]["max_level"] = 9;
  EXPECT_EQ(error_of(doc), "scene error: effects.refinement.max_level: must be between 1 and 8 (got 9)");
}

TEST(SceneParser, MalformedJsonIsRefused) {
  try {
    (void)parse_json_text(R"({ "name": "x", "time": { "end": 1, } )", "broken.json");
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.path(), "broken.json");
    EXPECT_EQ(std::string(e.what()).rfind("scene error: broken.json: malformed JSON: ", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)parse_json_text("", "empty.json"), SceneError);
  // A number past the range of a double is malformed text too (nlohmann reports it as out_of_range, not as a
  // parse error: found by the fuzzer), named with the key it was read for.
  try {
    (void)parse_json_text(R"({ "time": { "end": 5.1e30802 } })", "huge.json");
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("scene error: huge.json: malformed JSON: number overflow", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("(in time.end)"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)parse_json_text("[1, 2", "cut.json"), SceneError);
}

TEST(SceneParser, DuplicateKeyIsRefusedByPath) {
  try {
    (void)parse_json_text(R"({ "fluid": [ {"a": 1}, {"spacing": 1, "spacing": 2} ] })", "dup.json");
    FAIL() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(), "scene error: fluid[1].spacing: duplicate key");
  }
}

TEST(SceneParser, NotAnObjectIsRefused) {
  EXPECT_EQ(error_of(Json::array()), "scene error: (root): must be an object (got an array)");
  Json doc = full_scene();
  doc["fluid"] = Json::object();
  EXPECT_EQ(error_of(doc), "scene error: fluid: must be an array of regions (got an object)");
  doc["fluid"] = Json::array();
  EXPECT_EQ(error_of(doc), "scene error: fluid: at least one fluid region is required");
}

TEST(SceneParser, HydrostaticNeedsGravityDownwards) {
  Json doc = full_scene();
  doc["effects"]["gravity"] = Json::array({1, -9.81});
  EXPECT_EQ(error_of(doc), "scene error: fluid[0].hydrostatic: needs gravity pointing along -y ([0, -g])");
  doc["effects"].erase("gravity");
  doc["material"] = Json{{"rho0", 1000}, {"c0", 30}};
  doc["effects"]["lennard_jones_wall"] = Json{{"strength", 100}};
  EXPECT_EQ(error_of(doc), "scene error: fluid[0].hydrostatic: needs effects.gravity");
}

TEST(SceneParser, ProbeAndOutputRules) {
  Json doc = full_scene();
  doc["probes"][0]["name"] = "eta";
  EXPECT_EQ(error_of(doc), "scene error: probes[2].name: duplicate probe name 'eta'");
  doc = full_scene();
  doc["probes"][3]["position"] = Json::array({30, 1});
  EXPECT_EQ(error_of(doc), "scene error: probes[3].position: must lie inside the container");
  doc = full_scene();
  doc["output"]["fields"][1] = "velocty";
  EXPECT_EQ(error_of(doc).rfind("scene error: output.fields[1]: unknown field 'velocty'", 0), 0u);
}

TEST(SceneParser, OverridesEditTheDocumentBeforeValidation) {
  Json doc = full_scene();
  apply_override(doc, "time.end=3");
  apply_override(doc, "effects.ghost_walls=free-slip");     // a bare word is a string
  apply_override(doc, "fluid[1].velocity=[1, 2]");
  apply_override(doc, "fluid.0.spacing=0.25");
  apply_override(doc, "effects.refinement=null");          // null removes the key
  apply_override(doc, "output.frames=false");
  const Scene s = scene_from_json(doc);
  EXPECT_DOUBLE_EQ(s.time.end, 3.0);
  EXPECT_EQ(s.effects.ghost_walls, Slip::free_slip);
  EXPECT_EQ(s.fluid[1].velocity, sph::AnyVec(sph::Vec<2>(1, 2)));
  EXPECT_DOUBLE_EQ(s.fluid[0].spacing, 0.25);
  EXPECT_FALSE(s.effects.refinement);
  EXPECT_FALSE(s.output.frames);

  // A typo through --set is caught like one in the file.
  apply_override(doc, "time.edn=3");
  EXPECT_NE(error_of(doc).find("scene error: time.edn: unknown key (did you mean 'end'?)"), std::string::npos);

  auto override_error = [](const std::string& a) {
    Json d = full_scene();
    try {
      apply_override(d, a);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(override_error("time.end"), "scene error: --set: expected key.path=value (got 'time.end')");
  EXPECT_EQ(override_error("fluid[7].spacing=1"), "scene error: --set fluid[7].spacing: index 7 is out of range (fluid has 2 elements)");
  EXPECT_EQ(override_error("time.end.x=1"), "scene error: --set time.end.x: time.end is not an object");
}

TEST(SceneParser, ADirectoryIsNotASceneFile) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  try {
    (void)load_scene(dir);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(e.what(), "scene error: " + dir.string() + ": is a directory, not a scene file");
    EXPECT_EQ(e.exit_code(), 2);
  }
}

TEST(SceneParser, MissingFileIsASceneError) {
  try {
    (void)load_scene("/nonexistent/scene.json");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(), "scene error: /nonexistent/scene.json: no such scene file");
    EXPECT_EQ(e.exit_code(), 2);
  }
}

}  // namespace
