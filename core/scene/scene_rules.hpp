#pragma once
// Internal to core/scene: the helpers the parser and the validator share to name a key path and to refuse a
// value. Not part of the library's interface.
#include <sstream>
#include <string>
#include <vector>

#include "core/scene/scene_error.hpp"

namespace sph::scene::detail {

/// The deepest refinement level a scene may ask for (a region's level, refinement.max_level).
inline constexpr int kMaxLevel = 8;

[[noreturn]] inline void fail(const std::string& path, const std::string& rule) { throw SceneError(path, rule); }

inline std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
inline std::string element(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

inline std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

inline std::string num(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

}  // namespace sph::scene::detail
