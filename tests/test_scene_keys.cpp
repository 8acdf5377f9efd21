// The scene enumerations' names: one table each (core/scene/scene_choices.hpp), read both ways.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "core/scene/scene_choices.hpp"

namespace {

using namespace sph::scene;

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

}  // namespace
