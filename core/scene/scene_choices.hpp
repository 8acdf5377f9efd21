#pragma once
// The one mapping between each scene enumeration and its names in scene files: the parser reads through it,
// the writer and messages name values through it (to_string), and docs/SCENES.md lists its names.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/scene/scene.hpp"

namespace sph::scene {

template <class E>
struct Choice {
  const char* name;
  E value;
};

/// Choices<E>::table: every value of E with its name, in the order messages and docs list them.
template <class E>
struct Choices;

template <>
struct Choices<Shape> {
  static constexpr std::array<Choice<Shape>, 2> table{{{"rectangle", Shape::rectangle}, {"circle", Shape::circle}}};
};
template <>
struct Choices<Outflow> {
  static constexpr std::array<Choice<Outflow>, 2> table{{{"stop", Outflow::stop}, {"remove", Outflow::remove}}};
};
template <>
struct Choices<Slip> {
  static constexpr std::array<Choice<Slip>, 2> table{{{"free-slip", Slip::free_slip}, {"no-slip", Slip::no_slip}}};
};
template <>
struct Choices<GhostPressure> {
  static constexpr std::array<Choice<GhostPressure>, 2> table{
      {{"hydrostatic", GhostPressure::hydrostatic}, {"mirrored", GhostPressure::mirrored}}};
};
template <>
struct Choices<Criterion> {
  static constexpr std::array<Choice<Criterion>, 3> table{{{"velocity", Criterion::velocity},
                                                           {"zone", Criterion::zone},
                                                           {"few_neighbours", Criterion::few_neighbours}}};
};
template <>
struct Choices<Pattern> {
  static constexpr std::array<Choice<Pattern>, 2> table{{{"aap", Pattern::aap}, {"rsp", Pattern::rsp}}};
};
template <>
struct Choices<LevelCoupling> {
  static constexpr std::array<Choice<LevelCoupling>, 2> table{
      {{"mixed", LevelCoupling::mixed}, {"buffered", LevelCoupling::buffered}}};
};
template <>
struct Choices<DaughterDensity> {
  static constexpr std::array<Choice<DaughterDensity>, 2> table{
      {{"parent", DaughterDensity::parent}, {"pressure_gradient", DaughterDensity::pressure_gradient}}};
};
template <>
struct Choices<MergeGroups> {
  static constexpr std::array<Choice<MergeGroups>, 2> table{{{"family", MergeGroups::family}, {"cell", MergeGroups::cell}}};
};
template <>
struct Choices<TimeStepping> {
  static constexpr std::array<Choice<TimeStepping>, 2> table{
      {{"global", TimeStepping::global}, {"per_level", TimeStepping::per_level}}};
};
template <>
struct Choices<TimePredictor> {
  static constexpr std::array<Choice<TimePredictor>, 2> table{
      {{"extrapolated", TimePredictor::extrapolated}, {"last_rate", TimePredictor::last_rate}}};
};
template <>
struct Choices<ProbeKind> {
  static constexpr std::array<Choice<ProbeKind>, 4> table{{{"water_height", ProbeKind::water_height},
                                                           {"surge_front", ProbeKind::surge_front},
                                                           {"surface_elevation", ProbeKind::surface_elevation},
                                                           {"pressure", ProbeKind::pressure}}};
};

/// The name of a value ("?" for a value outside the table).
template <class E>
constexpr const char* choice_name(E v) {
  for (const auto& c : Choices<E>::table) {
    if (c.value == v) return c.name;
  }
  return "?";
}

/// The value a name stands for (none for a name outside the table).
template <class E>
constexpr std::optional<E> choice_value(std::string_view name) {
  for (const auto& c : Choices<E>::table) {
    if (name == c.name) return c.value;
  }
  return std::nullopt;
}

/// Every name of E, in table order.
template <class E>
std::vector<std::string> choice_names() {
  std::vector<std::string> names;
  for (const auto& c : Choices<E>::table) names.emplace_back(c.name);
  return names;
}

}  // namespace sph::scene
