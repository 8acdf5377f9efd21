// The scene key registry (core/scene/scene_keys.hpp): each key declared once, its default inside its own range,
// its variants named by its object's discriminator, the enumerations' names in one table each, and
// docs/SCENES.md's key tables exactly what the registry produces.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/scene/scene_choices.hpp"
#include "core/scene/scene_keys.hpp"

namespace {

using namespace sph::scene;

const std::filesystem::path kRoot = std::filesystem::path(__FILE__).parent_path().parent_path();

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(SceneKeys, EveryPathIsDeclaredOnce) {
  const auto keys = all_keys();
  EXPECT_GE(keys.size(), 60u);
  std::set<std::string> paths;
  for (const KeyEntry& e : keys) EXPECT_TRUE(paths.insert(e.path).second) << "declared twice: " << e.path;
  EXPECT_TRUE(paths.count("time.cfl"));
  EXPECT_TRUE(paths.count("effects.artificial_viscosity.alpha"));
  EXPECT_TRUE(paths.count("fluid[i].spacing"));
  EXPECT_TRUE(paths.count("effects.refinement.coarsening.hold_time"));
  EXPECT_TRUE(paths.count("effects.refinement.zone.lo")) << "a box reached from two places is listed at both";
}

TEST(SceneKeys, EveryKeyIsDescribedWithATypeAndAMeaning) {
  for (const KeyEntry& e : all_keys()) {
    SCOPED_TRACE(e.path);
    EXPECT_FALSE(e.key->type_text.empty());
    EXPECT_FALSE(e.key->description.empty());
    EXPECT_EQ(e.key->description.find('\n'), std::string::npos) << "one line";
    if (e.key->type == KeyType::object || e.key->type == KeyType::array) {
      EXPECT_NE(e.key->section, nullptr);
    }
    if (e.key->type == KeyType::choice) {
      EXPECT_GE(e.key->choices.size(), 2u);
    }
    if (e.key->range) {
      EXPECT_TRUE(e.key->type == KeyType::number || e.key->type == KeyType::integer);
    }
  }
}

TEST(SceneKeys, EveryDefaultPassesItsOwnRange) {
  int checked = 0;
  for (const KeyEntry& e : all_keys()) {
    const KeyInfo& k = *e.key;
    if (k.presence == Presence::defaulted && k.type != KeyType::object) {
      EXPECT_FALSE(k.default_text.empty()) << e.path << ": a default the tables can show";
    }
    if (k.presence == Presence::required) {
      EXPECT_FALSE(k.default_number) << e.path;
    }
    if (!k.range || !k.default_number) continue;
    EXPECT_TRUE(k.range->contains(*k.default_number)) << e.path << ": default " << *k.default_number << " outside "
                                                      << k.range->text();
    ++checked;
  }
  EXPECT_GE(checked, 12);
}

TEST(SceneKeys, DefaultsAreTheSettingsStructsOwn) {
  // Read through the member binding from default-constructed structs: one place for each default.
  for (const KeyEntry& e : all_keys()) {
    if (e.path == "effects.artificial_viscosity.alpha") {
      EXPECT_EQ(e.key->default_number, sph::ViscositySettings{}.alpha);
    }
    if (e.path == "time.cfl") {
      EXPECT_EQ(e.key->default_number, Time{}.cfl);
    }
    if (e.path == "effects.refinement.check_interval") {
      EXPECT_EQ(e.key->default_number, sph::refine::RefinementSettings{}.check_interval);
    }
    if (e.path == "effects.refinement.pattern") {
      EXPECT_EQ(e.key->default_text, "`aap`");
    }
  }
}

TEST(SceneKeys, VariantKeysNameVariantsOfTheirDiscriminator) {
  for (const KeyEntry& e : all_keys()) {
    const SectionInfo& s = *e.owner;
    if (e.key->only_for.empty()) continue;
    SCOPED_TRACE(e.path);
    ASSERT_TRUE(s.polymorphic()) << "a key allowed for some variants only, in an object without variants";
    std::vector<std::string> variants;
    if (!s.discriminator.empty()) {
      for (const KeyInfo& k : s.keys) {
        if (k.name == s.discriminator) variants = k.choices;
      }
    } else {
      variants = choice_names<Criterion>();  // coarsening follows refinement's criterion
    }
    for (const auto& v : e.key->only_for) EXPECT_NE(std::find(variants.begin(), variants.end(), v), variants.end()) << v;
  }
}

template <class E>
void expect_names_round_trip() {
  std::set<std::string> seen;
  for (const auto& name : choice_names<E>()) {
    EXPECT_TRUE(seen.insert(name).second) << name;
    ASSERT_TRUE(choice_value<E>(name)) << name;
    EXPECT_EQ(choice_name(*choice_value<E>(name)), name);
  }
  EXPECT_FALSE(choice_value<E>("no such name"));
}

TEST(SceneKeys, EachEnumerationHasOneTableOfNames) {
  expect_names_round_trip<Shape>();
  expect_names_round_trip<sph::Outflow>();
  expect_names_round_trip<Slip>();
  expect_names_round_trip<sph::GhostPressure>();
  expect_names_round_trip<Criterion>();
  expect_names_round_trip<Pattern>();
  expect_names_round_trip<sph::TimeStepping>();
  expect_names_round_trip<ProbeKind>();
  EXPECT_STREQ(to_string(Slip::no_slip), "no-slip");
  EXPECT_STREQ(to_string(sph::TimeStepping::per_level), "per_level");
}

TEST(SceneKeys, RangesWordTheirRule) {
  EXPECT_EQ(Range::positive().rule(), "must be positive");
  EXPECT_EQ(Range::non_negative().rule(), "must not be negative");
  EXPECT_EQ(Range::at_least(1).rule(), "must be at least 1");
  EXPECT_EQ(Range::between(0.5, 3).rule(), "must be between 0.5 and 3");
  EXPECT_EQ(Range::above_up_to(0, 1).rule(), "must be in (0, 1]");
  EXPECT_EQ(Range::above_up_to(0, 1).text(), "0 < x <= 1");
  EXPECT_EQ(Range::between(1, 8).text(), "1 .. 8");
  EXPECT_EQ(Range::positive().text(), "> 0");
  EXPECT_TRUE(Range::above_up_to(0, 1).contains(1.0));
  EXPECT_FALSE(Range::above_up_to(0, 1).contains(0.0));
  EXPECT_TRUE(Range::non_negative().contains(0.0));
  EXPECT_FALSE(Range::positive().contains(0.0));
  EXPECT_FALSE(Range::between(1, 8).contains(9.0));
}

TEST(SceneKeys, ScenesMdTablesMatchTheRegistry) {
  const std::string doc = read_text(kRoot / "docs" / "SCENES.md");
  ASSERT_FALSE(doc.empty());
  EXPECT_TRUE(doc == sync_key_tables(doc))
      << "docs/SCENES.md's key tables differ from the registry: run 'sphrefine keys --sync docs/SCENES.md'";
}

TEST(SceneKeys, SyncReplacesOnlyTheTablesAndRefusesUnknownOrMissingMarkers) {
  std::string doc = "intro\n";
  for (const auto& [path, section] : documented_sections()) {
    doc += "prose before " + path + "\n<!-- keys: " + path + " -->\n| stale |\n<!-- end keys -->\nprose after\n";
  }
  const std::string synced = sync_key_tables(doc);
  EXPECT_EQ(synced.find("| stale |"), std::string::npos);
  EXPECT_NE(synced.find("prose before time\n<!-- keys: time -->\n| key | type |"), std::string::npos);
  EXPECT_NE(synced.find("| `cfl` | number |  | 0.2 | 0 < x <= 1 |"), std::string::npos) << synced;
  EXPECT_EQ(sync_key_tables(synced), synced);
  EXPECT_THROW((void)sync_key_tables(doc + "<!-- keys: tiem -->\n<!-- end keys -->\n"), std::runtime_error);
  EXPECT_THROW((void)sync_key_tables(doc + "<!-- keys: time -->\n"), std::runtime_error);
  EXPECT_THROW((void)sync_key_tables("intro\n"), std::runtime_error) << "every object needs its table";
}

TEST(SceneKeys, PolymorphicTablesSayForWhichVariant) {
  for (const auto& [path, section] : documented_sections()) {
    if (path != "fluid[i]") continue;
    const std::string t = key_table(*section);
    EXPECT_NE(t.find("| `radius` | `circle` | number | m | **required** | > 0 |"), std::string::npos) << t;
  }
}

}  // namespace
