#pragma once
// The scene's key registry, as data: every key of a scene file is declared once (core/scene/scene_keys.cpp) with
// its type, unit, default, allowed range or choices and a one-line meaning, bound to the Scene member it fills.
// The parser, the per-key checks of the validator, the JSON writer and the key tables of docs/SCENES.md all
// come from that one declaration. This header is the registry's read-only view (the docs, `sphrefine keys`
// and the tests use it); the binding to the Scene structs is internal (scene_schema.hpp).
#include <optional>
#include <string>
#include <vector>

namespace sph::scene {

enum class KeyType { number, integer, boolean, string, vector, choice, object, array, strings };

/// An interval of allowed values for a number or integer key; an open end excludes its bound.
struct Range {
  double lo = 0.0;
  double hi = 0.0;
  bool has_lo = false;
  bool has_hi = false;
  bool lo_open = false;
  bool hi_open = false;

  static Range positive();                            // (0, inf)
  static Range non_negative();                        // [0, inf)
  static Range at_least(double lo);                   // [lo, inf)
  static Range between(double lo, double hi);         // [lo, hi]
  static Range above_up_to(double lo, double hi);     // (lo, hi]

  bool contains(double x) const;
  /// The rule a value outside breaks: "must be positive", "must be in (0, 1]", "must be between 1 and 8".
  std::string rule() const;
  /// The range for a table: "> 0", "0 < x <= 1", "1 .. 8".
  std::string text() const;
};

/// Whether a key must be given, has a default (the bound struct member's initial value), or may be absent
/// (an optional member: absent means not set / not computed).
enum class Presence { required, defaulted, optional };

struct SectionInfo;

struct KeyInfo {
  std::string name;
  KeyType type = KeyType::number;
  std::string type_text;     // as the tables name it: "number", "[x, y]", "box", "array of regions"
  std::string unit;          // SI unit, "" for none
  Presence presence = Presence::defaulted;
  std::string default_text;  // the default as the tables show it (read from the struct, or how it is derived)
  std::optional<double> default_number;  // a number's or integer's default, read from the struct
  std::optional<Range> range;
  std::vector<std::string> choices;  // a choice's names (scene_choices.hpp)
  std::string note;          // what else is allowed, checked across keys by the validator (tables only)
  std::string description;   // one line
  std::vector<std::string> only_for;  // the variants of the object's discriminator that allow it; empty: all
  const SectionInfo* section = nullptr;  // an object's keys, or an array element's

  bool allowed_for(const std::string& variant) const;
};

/// The keys of one JSON object. A polymorphic object has a discriminator key (a fluid region's "shape", a
/// probe's "type", refinement's "criterion") or takes its variant from the enclosing object (coarsening
/// follows refinement's criterion); its keys may be allowed for some variants only.
struct SectionInfo {
  std::string discriminator;  // "" when the variant comes from outside or there is none
  std::string phrase;         // how messages name a variant: "a {}", "a {} probe", "criterion {}"
  std::vector<KeyInfo> keys;

  /// The names allowed for a variant ("" for a section without variants), in declaration order.
  std::vector<std::string> allowed(const std::string& variant) const;
  /// "a rectangle", "criterion velocity" ("" for no variant).
  std::string describe(const std::string& variant) const;
  bool polymorphic() const { return !phrase.empty(); }
};

/// The root of the registry: the scene file's top-level object.
const SectionInfo& scene_keys();

/// One key with its path in the document, arrays' elements written "[i]": "fluid[i].spacing".
struct KeyEntry {
  std::string path;
  const KeyInfo* key = nullptr;
  const SectionInfo* owner = nullptr;
};
/// Every key of the registry, depth first in declaration order. A section reached twice (the box of
/// obstacles, refinement zones and static refinement) is listed at each place.
std::vector<KeyEntry> all_keys();

/// The objects that get a table in docs/SCENES.md, by path ("(top level)", "container", "fluid[i]", ...):
/// every section once, at the first path that reaches it.
std::vector<std::pair<std::string, const SectionInfo*>> documented_sections();

/// The Markdown table of one documented section.
std::string key_table(const SectionInfo& section);

/// Every table, each between its markers "<!-- keys: PATH -->" and "<!-- end keys -->".
std::string key_tables_markdown();

/// `markdown` with the text between every pair of markers replaced by the registry's table for that path.
/// Throws std::runtime_error for a marker naming no documented section, an unclosed marker, or a documented
/// section with no marker.
std::string sync_key_tables(const std::string& markdown);

}  // namespace sph::scene
