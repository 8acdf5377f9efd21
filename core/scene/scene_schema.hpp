#pragma once
// Internal to core/scene: the registry's binding of each key to the struct member it fills, and the three
// walks over it: read_section (JSON -> struct: unknown keys, types, required keys, choices), write_section
// (struct -> JSON) and check_section (the per-key ranges). The declarations themselves are in scene_keys.cpp.
//
// Defaults live in the structs' member initialisers (scene.hpp, solver_settings.hpp, refinement_settings.hpp):
// the solver and the tests construct those settings without a scene, so their defaults must stay there. The
// reader starts from a default-constructed struct and leaves an absent key's member as it is; the tables read
// the default through the same binding from a default-constructed struct. Nothing else holds a default.
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/scene/scene_choices.hpp"
#include "core/scene/scene_keys.hpp"
#include "core/scene/scene_parser.hpp"
#include "core/scene/scene_rules.hpp"

namespace sph::scene::schema {

/// "an object", "a string", ... for messages.
const char* type_name(const Json& j);
/// Refuses a key of `j` not allowed for the variant, suggesting the nearest allowed name.
void refuse_unknown_keys(const SectionInfo& section, const Json& j, const std::string& path, const std::string& variant);
/// "number", "integer", "boolean", "string" for the tables.
const char* type_word(KeyType t);
double read_number(const Json& v, const std::string& path);
std::string read_string(const Json& v, const std::string& path);
void check_range(const KeyInfo& key, double x, const std::string& path);

// ---- values: how one JSON value reads into and writes from a member of type V ---------------------------------

template <class V, class = void>
struct Value;

template <>
struct Value<double> {
  static constexpr KeyType type = KeyType::number;
  static double read(const Json& v, const std::string& path) { return read_number(v, path); }
  static Json write(double x) { return x; }
  static std::string show(double x) { return detail::num(x); }
};

template <>
struct Value<int> {
  static constexpr KeyType type = KeyType::integer;
  static int read(const Json& v, const std::string& path) {
    if (!v.is_number_integer()) detail::fail(path, std::string("must be an integer (got ") + type_name(v) + ")");
    const auto x = v.get<long long>();
    if (x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max()) {
      detail::fail(path, "integer out of range");
    }
    return static_cast<int>(x);
  }
  static Json write(int x) { return x; }
  static std::string show(int x) { return std::to_string(x); }
};

template <>
struct Value<bool> {
  static constexpr KeyType type = KeyType::boolean;
  static bool read(const Json& v, const std::string& path) {
    if (!v.is_boolean()) detail::fail(path, std::string("must be true or false (got ") + type_name(v) + ")");
    return v.get<bool>();
  }
  static Json write(bool x) { return x; }
  static std::string show(bool x) { return x ? "true" : "false"; }
};

template <>
struct Value<std::string> {
  static constexpr KeyType type = KeyType::string;
  static std::string read(const Json& v, const std::string& path) { return read_string(v, path); }
  static Json write(const std::string& x) { return x; }
  static std::string show(const std::string& x) { return "`\"" + x + "\"`"; }
};

/// A point or vector: an array of two numbers [x, y] in a 2D scene, three [x, y, z] in a 3D one. The reader
/// takes either; that every vector has the scene's dimension (its container's) is the validator's rule, checked
/// through for_each_vector. An empty AnyVec is a vector left at its default (zero): it is not written.
template <>
struct Value<AnyVec> {
  static constexpr KeyType type = KeyType::vector;
  static std::string axes() { return "[x, y] or [x, y, z]"; }
  static AnyVec read(const Json& v, const std::string& path) {
    if (!v.is_array() || v.size() < 2 || v.size() > 3) {
      detail::fail(path, "must be an array of two numbers [x, y] (2D) or three [x, y, z] (3D) (got " +
                             (v.is_array() ? "an array of " + std::to_string(v.size()) : std::string(type_name(v))) +
                             ")");
    }
    AnyVec x(static_cast<Eigen::Index>(v.size()));
    for (std::size_t k = 0; k < v.size(); ++k) x[static_cast<Eigen::Index>(k)] = read_number(v[k], detail::element(path, k));
    return x;
  }
  static Json write(const AnyVec& x) {
    Json a = Json::array();
    for (Eigen::Index k = 0; k < x.size(); ++k) a.push_back(x[k]);
    return a;
  }
  static std::string show(const AnyVec& x) {
    if (x.size() == 0) return "zero";
    std::string s = "[";
    for (Eigen::Index k = 0; k < x.size(); ++k) s += (k ? ", " : "") + detail::num(x[k]);
    return s + "]";
  }
};

/// An enumeration named in scene files through its one table (scene_choices.hpp).
template <class E>
struct Value<E, std::enable_if_t<std::is_enum_v<E>>> {
  static constexpr KeyType type = KeyType::choice;
  static E read(const Json& v, const std::string& path) {
    const std::string s = read_string(v, path);
    if (const auto e = choice_value<E>(s)) return *e;
    detail::fail(path, "must be one of: " + detail::list(choice_names<E>()) + " (got '" + s + "')");
  }
  static Json write(E x) { return choice_name(x); }
  static std::string show(E x) { return std::string("`") + choice_name(x) + "`"; }
};

template <class V>
struct is_optional : std::false_type {};
template <class V>
struct is_optional<std::optional<V>> : std::true_type {};

// ---- keys and sections ----------------------------------------------------------------------------------------

/// Visits one vector of a scene with its key path (for_each_vector).
using VectorVisitor = std::function<void(const std::string& path, const AnyVec& v)>;

/// What one key does to a struct T: read its JSON value into T, write it out of T, check its range in T.
template <class T>
struct Binding {
  std::function<void(const Json&, const std::string&, T&)> read;     // the key is present
  std::function<void(const T&, Json&, const std::string&)> write;    // adds the key to the object if it is set
  std::function<std::optional<double>(const T&)> number;            // a number's or integer's value, if set
  std::function<void(const T&, const std::string&)> check;           // an object's or array's own keys
  std::function<void(const T&, const std::string&, const VectorVisitor&)> vectors;  // the vectors it holds
};

template <class T>
struct Key {
  KeyInfo info;
  Binding<T> bind;

  Key&& unit(std::string u) && { info.unit = std::move(u); return std::move(*this); }
  Key&& required() && {
    info.presence = Presence::required;
    info.default_text.clear();
    info.default_number.reset();
    return std::move(*this);
  }
  Key&& range(Range r) && { info.range = r; return std::move(*this); }
  Key&& only_for(std::vector<std::string> v) && { info.only_for = std::move(v); return std::move(*this); }
  Key&& note(std::string n) && { info.note = std::move(n); return std::move(*this); }
  /// The default as the tables show it, when it is not a plain value of the struct (derived or set elsewhere).
  Key&& default_text(std::string d) && { info.default_text = std::move(d); return std::move(*this); }
  Key&& type_text(std::string t) && { info.type_text = std::move(t); return std::move(*this); }
  Key&& means(std::string d) && { info.description = std::move(d); return std::move(*this); }
};

template <class T>
struct Section {
  SectionInfo info;
  std::vector<Binding<T>> bindings;
  std::function<std::string(const T&)> variant;  // the variant a value is, from its discriminator

  Section& add(Key<T>&& k) {
    info.keys.push_back(std::move(k.info));
    bindings.push_back(std::move(k.bind));
    return *this;
  }
  std::size_t index(const std::string& name) const {
    for (std::size_t i = 0; i < info.keys.size(); ++i) {
      if (info.keys[i].name == name) return i;
    }
    return info.keys.size();
  }
};

template <class T>
void read_section(const Section<T>& s, const Json& j, const std::string& path, T& out, std::string variant = "") {
  if (!j.is_object()) detail::fail(path, std::string("must be an object (got ") + type_name(j) + ")");
  const std::size_t disc = s.index(s.info.discriminator);
  if (disc < s.info.keys.size()) {
    const KeyInfo& k = s.info.keys[disc];
    if (j.contains(k.name)) {
      s.bindings[disc].read(j.at(k.name), detail::join(path, k.name), out);
    } else if (k.presence == Presence::required) {
      detail::fail(detail::join(path, k.name), "missing required key (one of: " + detail::list(k.choices) + ")");
    }
    variant = s.variant(out);
  }
  refuse_unknown_keys(s.info, j, path, variant);
  for (std::size_t i = 0; i < s.info.keys.size(); ++i) {
    const KeyInfo& k = s.info.keys[i];
    if (i == disc || !k.allowed_for(variant)) continue;
    if (j.contains(k.name)) {
      s.bindings[i].read(j.at(k.name), detail::join(path, k.name), out);
    } else if (k.presence == Presence::required) {
      detail::fail(detail::join(path, k.name), "missing required key");
    }
  }
}

template <class T>
Json write_section(const Section<T>& s, const T& t, std::string variant = "") {
  if (s.variant && !s.info.discriminator.empty()) variant = s.variant(t);
  Json o = Json::object();
  for (std::size_t i = 0; i < s.info.keys.size(); ++i) {
    if (s.info.keys[i].allowed_for(variant)) s.bindings[i].write(t, o, s.info.keys[i].name);
  }
  return o;
}

template <class T>
void check_section(const Section<T>& s, const T& t, const std::string& path, std::string variant = "") {
  if (s.variant && !s.info.discriminator.empty()) variant = s.variant(t);
  for (std::size_t i = 0; i < s.info.keys.size(); ++i) {
    const KeyInfo& k = s.info.keys[i];
    if (!k.allowed_for(variant)) continue;
    const Binding<T>& b = s.bindings[i];
    if (k.range && b.number) {
      if (const auto x = b.number(t)) check_range(k, *x, detail::join(path, k.name));
    }
    if (b.check) b.check(t, detail::join(path, k.name));
  }
}

/// Visits every vector (AnyVec) the section's keys hold in t, set or defaulted, nested objects and arrays included.
template <class T>
void for_each_vector(const Section<T>& s, const T& t, const std::string& path, const VectorVisitor& visit,
                     std::string variant = "") {
  if (s.variant && !s.info.discriminator.empty()) variant = s.variant(t);
  for (std::size_t i = 0; i < s.info.keys.size(); ++i) {
    const KeyInfo& k = s.info.keys[i];
    if (k.allowed_for(variant) && s.bindings[i].vectors) s.bindings[i].vectors(t, detail::join(path, k.name), visit);
  }
}

// ---- the key builders -----------------------------------------------------------------------------------------

/// A member reached by an accessor: `[](auto& f) -> auto& { return f.rect.lo; }`, or a pointer to member.
template <class T, class V>
auto member(V T::*m) {
  return [m](auto& t) -> auto& { return t.*m; };
}

template <class T, class F>
using MemberType = std::remove_cvref_t<decltype(std::declval<F>()(std::declval<T&>()))>;

/// A value key: number, integer, boolean, string, vector or choice, or std::optional of one (may be absent).
template <class T, class F>
Key<T> value(const char* name, F access) {
  using M = MemberType<T, F>;
  constexpr bool optional = is_optional<M>::value;
  using V = typename std::conditional_t<optional, M, std::optional<M>>::value_type;
  Key<T> k;
  k.info.name = name;
  k.info.type = Value<V>::type;
  k.info.type_text = type_word(Value<V>::type);
  if constexpr (Value<V>::type == KeyType::vector) k.info.type_text = Value<V>::axes();
  if constexpr (Value<V>::type == KeyType::choice) k.info.choices = choice_names<V>();
  if constexpr (optional) {
    k.info.presence = Presence::optional;
  } else {
    const T defaults{};
    const V& d = access(defaults);
    k.info.default_text = Value<V>::show(d);
    if constexpr (std::is_arithmetic_v<V> && !std::is_same_v<V, bool>) k.info.default_number = static_cast<double>(d);
  }
  k.bind.read = [access](const Json& j, const std::string& path, T& t) { access(t) = Value<V>::read(j, path); };
  k.bind.write = [access](const T& t, Json& o, const std::string& key) {
    const M& m = access(t);
    if constexpr (optional) {
      if (m) o[key] = Value<V>::write(*m);
    } else if constexpr (std::is_same_v<V, std::string>) {
      if (!m.empty()) o[key] = m;  // "" is what an absent string key reads as
    } else if constexpr (std::is_same_v<V, AnyVec>) {
      if (m.size() > 0) o[key] = Value<V>::write(m);  // empty is what an absent vector key reads as (zero)
    } else {
      o[key] = Value<V>::write(m);
    }
  };
  if constexpr (std::is_same_v<V, AnyVec>) {
    k.bind.vectors = [access](const T& t, const std::string& path, const VectorVisitor& visit) {
      const M& m = access(t);
      if constexpr (optional) {
        if (m) visit(path, *m);
      } else {
        visit(path, m);
      }
    };
  }
  if constexpr (std::is_arithmetic_v<V> && !std::is_same_v<V, bool>) {
    k.bind.number = [access](const T& t) -> std::optional<double> {
      const M& m = access(t);
      if constexpr (optional) {
        return m ? std::optional<double>(static_cast<double>(*m)) : std::nullopt;
      } else {
        return static_cast<double>(m);
      }
    };
  }
  return k;
}

/// An object key: a member of struct type S (absent: S's defaults), or std::optional<S> (absent: not set).
/// `variant` gives a section without discriminator its variant from the enclosing struct.
template <class T, class S, class F>
Key<T> object(const char* name, F access, const Section<S>& (*section)(),
              std::function<std::string(const T&)> variant = {}) {
  using M = MemberType<T, F>;
  constexpr bool optional = is_optional<M>::value;
  Key<T> k;
  k.info.name = name;
  k.info.type = KeyType::object;
  k.info.type_text = "object";
  k.info.presence = optional ? Presence::optional : Presence::defaulted;
  k.info.section = &section().info;
  auto variant_of = [variant](const T& t) { return variant ? variant(t) : std::string(); };
  k.bind.read = [access, section, variant_of](const Json& j, const std::string& path, T& t) {
    S s{};
    read_section(section(), j, path, s, variant_of(t));
    access(t) = std::move(s);
  };
  k.bind.write = [access, section, variant_of](const T& t, Json& o, const std::string& key) {
    const M& m = access(t);
    if constexpr (optional) {
      if (m) o[key] = write_section(section(), *m, variant_of(t));
    } else {
      o[key] = write_section(section(), m, variant_of(t));
    }
  };
  k.bind.check = [access, section, variant_of](const T& t, const std::string& path) {
    const M& m = access(t);
    if constexpr (optional) {
      if (m) check_section(section(), *m, path, variant_of(t));
    } else {
      check_section(section(), m, path, variant_of(t));
    }
  };
  k.bind.vectors = [access, section, variant_of](const T& t, const std::string& path, const VectorVisitor& visit) {
    const M& m = access(t);
    if constexpr (optional) {
      if (m) for_each_vector(section(), *m, path, visit, variant_of(t));
    } else {
      for_each_vector(section(), m, path, visit, variant_of(t));
    }
  };
  return k;
}

/// An array of objects (std::vector<S>); `noun` names the elements in messages ("an array of regions").
template <class T, class S, class F>
Key<T> array(const char* name, F access, const Section<S>& (*section)(), const std::string& noun) {
  Key<T> k;
  k.info.name = name;
  k.info.type = KeyType::array;
  k.info.type_text = "array of " + noun;
  k.info.default_text = "`[]`";
  k.info.section = &section().info;
  k.bind.read = [access, section, noun](const Json& j, const std::string& path, T& t) {
    if (!j.is_array()) detail::fail(path, "must be an array of " + noun + " (got " + type_name(j) + ")");
    auto& v = access(t);
    v.clear();
    for (std::size_t i = 0; i < j.size(); ++i) {
      S s{};
      read_section(section(), j[i], detail::element(path, i), s);
      v.push_back(std::move(s));
    }
  };
  k.bind.write = [access, section](const T& t, Json& o, const std::string& key) {
    if (access(t).empty()) return;  // [] is what an absent array key reads as
    Json a = Json::array();
    for (const S& s : access(t)) a.push_back(write_section(section(), s));
    o[key] = a;
  };
  k.bind.check = [access, section](const T& t, const std::string& path) {
    const auto& v = access(t);
    for (std::size_t i = 0; i < v.size(); ++i) check_section(section(), v[i], detail::element(path, i));
  };
  k.bind.vectors = [access, section](const T& t, const std::string& path, const VectorVisitor& visit) {
    const auto& v = access(t);
    for (std::size_t i = 0; i < v.size(); ++i) for_each_vector(section(), v[i], detail::element(path, i), visit);
  };
  return k;
}

/// An array of strings (std::vector<std::string>).
template <class T, class F>
Key<T> strings(const char* name, F access, const std::string& noun) {
  Key<T> k;
  k.info.name = name;
  k.info.type = KeyType::strings;
  k.info.type_text = "array of strings";
  k.info.default_text = "`[]`";
  k.bind.read = [access, noun](const Json& j, const std::string& path, T& t) {
    if (!j.is_array()) detail::fail(path, "must be an array of " + noun + " (got " + type_name(j) + ")");
    auto& v = access(t);
    v.clear();
    for (std::size_t i = 0; i < j.size(); ++i) v.push_back(read_string(j[i], detail::element(path, i)));
  };
  k.bind.write = [access](const T& t, Json& o, const std::string& key) {
    if (!access(t).empty()) o[key] = access(t);
  };
  return k;
}

}  // namespace sph::scene::schema

namespace sph::scene::schema {

/// The registry's root: the scene file's top-level object, bound to Scene (scene_keys.cpp).
const Section<Scene>& scene_section();
/// A box {lo, hi}: obstacles, refinement zones, static refinement's box (scene_keys.cpp).
const Section<Rect>& box_section();
/// The effects object (scene_keys_effects.cpp).
const Section<Effects>& effects_section();

}  // namespace sph::scene::schema
