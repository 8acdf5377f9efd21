// The registry's non-template parts: ranges and their wording, the unknown-key refusal with its suggestion,
// and the scalar readers every key shares.
#include "core/scene/scene_schema.hpp"

#include <algorithm>
#include <cmath>

namespace sph::scene {

using detail::fail;
using detail::num;

// ---- Range ----------------------------------------------------------------------------------------------------

Range Range::positive() { return Range{0.0, 0.0, true, false, true, false}; }
Range Range::non_negative() { return Range{0.0, 0.0, true, false, false, false}; }
Range Range::at_least(double lo) { return Range{lo, 0.0, true, false, false, false}; }
Range Range::between(double lo, double hi) { return Range{lo, hi, true, true, false, false}; }
Range Range::above_up_to(double lo, double hi) { return Range{lo, hi, true, true, true, false}; }

bool Range::contains(double x) const {
  if (has_lo && !(lo_open ? x > lo : x >= lo)) return false;
  if (has_hi && !(hi_open ? x < hi : x <= hi)) return false;
  return true;
}

std::string Range::rule() const {
  if (has_lo && !has_hi) {
    if (lo == 0.0) return lo_open ? "must be positive" : "must not be negative";
    return (lo_open ? "must be above " : "must be at least ") + num(lo);
  }
  if (!has_lo) return (hi_open ? "must be below " : "must be at most ") + num(hi);
  if (!lo_open && !hi_open) return "must be between " + num(lo) + " and " + num(hi);
  return std::string("must be in ") + (lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
}

std::string Range::text() const {
  if (has_lo && !has_hi) return (lo_open ? "> " : ">= ") + num(lo);
  if (!has_lo) return (hi_open ? "< " : "<= ") + num(hi);
  if (!lo_open && !hi_open) return num(lo) + " .. " + num(hi);
  return num(lo) + (lo_open ? " < x " : " <= x ") + (hi_open ? "< " : "<= ") + num(hi);
}

// ---- KeyInfo, SectionInfo -------------------------------------------------------------------------------------

bool KeyInfo::allowed_for(const std::string& variant) const {
  return only_for.empty() || std::find(only_for.begin(), only_for.end(), variant) != only_for.end();
}

std::vector<std::string> SectionInfo::allowed(const std::string& variant) const {
  std::vector<std::string> names;
  for (const KeyInfo& k : keys) {
    if (k.allowed_for(variant)) names.push_back(k.name);
  }
  return names;
}

std::string SectionInfo::describe(const std::string& variant) const {
  if (phrase.empty() || variant.empty()) return "";
  std::string out = phrase;
  const std::size_t at = out.find("{}");
  return at == std::string::npos ? out : out.replace(at, 2, variant);
}

namespace schema {

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

}  // namespace

const char* type_name(const Json& j) {
  switch (j.type()) {
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return "a string";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned: return "an integer";
    case Json::value_t::number_float: return "a number";
    case Json::value_t::null: return "null";
    default: return "an unsupported value";
  }
}

const char* type_word(KeyType t) {
  switch (t) {
    case KeyType::number: return "number";
    case KeyType::integer: return "integer";
    case KeyType::boolean: return "boolean";
    case KeyType::string:
    case KeyType::choice: return "string";
    case KeyType::vector: return "vector";
    case KeyType::object: return "object";
    case KeyType::array: return "array";
    case KeyType::strings: return "array of strings";
  }
  return "?";
}

void refuse_unknown_keys(const SectionInfo& section, const Json& j, const std::string& path, const std::string& variant) {
  const std::vector<std::string> allowed = section.allowed(variant);
  for (const auto& item : j.items()) {
    const std::string& key = item.key();
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string rule = "unknown key";
    std::string best;
    std::size_t best_d = 3;
    for (const auto& a : allowed) {
      const std::size_t d = edit_distance(key, a);
      if (d < best_d) best_d = d, best = a;
    }
    if (!best.empty()) rule += " (did you mean '" + best + "'?)";
    const std::string what = section.describe(variant);
    rule += "; allowed" + (what.empty() ? std::string() : " for " + what) + ": " + detail::list(allowed);
    fail(detail::join(path, key), rule);
  }
}

double read_number(const Json& v, const std::string& path) {
  if (!v.is_number()) fail(path, std::string("must be a number (got ") + type_name(v) + ")");
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(path, "must be a finite number");
  return x;
}

std::string read_string(const Json& v, const std::string& path) {
  if (!v.is_string()) fail(path, std::string("must be a string (got ") + type_name(v) + ")");
  return v.get<std::string>();
}

void check_range(const KeyInfo& key, double x, const std::string& path) {
  if (key.range && !key.range->contains(x)) fail(path, key.range->rule() + " (got " + num(x) + ")");
}

}  // namespace schema

}  // namespace sph::scene
