// Scene files -> Scene: JSON text (comments, duplicate keys), --set overrides, and the structural parse, which is
// the key registry's (scene_keys.cpp, read through scene_schema.hpp), followed by validate_scene.
#include "core/scene/scene_parser.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include "core/scene/scene_rules.hpp"
#include "core/scene/scene_schema.hpp"

namespace sph::scene {

using detail::element;
using detail::fail;
using detail::join;

// ---- JSON text ------------------------------------------------------------------------------------------------

Json parse_json_text(const std::string& text, const std::string& source) {
  // The parser callback tracks the key path so that a duplicate key (which JSON parsers silently
  // resolve to one of the values) is refused by name.
  struct Frame {
    bool array = false;
    std::string key;
    std::size_t index = 0;
    bool started = false;
    std::vector<std::string> keys;
  };
  std::vector<Frame> stack;
  auto path_to = [&](std::size_t depth) {
    std::string p;
    for (std::size_t k = 0; k < depth; ++k) p = stack[k].array ? element(p, stack[k].index) : join(p, stack[k].key);
    return p;
  };
  auto element_begins = [&] {
    if (!stack.empty() && stack.back().array) {
      if (stack.back().started) ++stack.back().index;
      stack.back().started = true;
    }
  };
  const Json::parser_callback_t callback = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
        element_begins();
        stack.push_back(Frame{});
        break;
      case Json::parse_event_t::array_start:
        element_begins();
        stack.push_back(Frame{true, "", 0, false, {}});
        break;
      case Json::parse_event_t::key: {
        Frame& f = stack.back();
        const auto key = parsed.get<std::string>();
        if (std::find(f.keys.begin(), f.keys.end(), key) != f.keys.end()) {
          f.key = key;
          fail(path_to(stack.size()), "duplicate key");
        }
        f.keys.push_back(key);
        f.key = key;
        break;
      }
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!stack.empty()) stack.pop_back();
        break;
      case Json::parse_event_t::value:
        element_begins();
        break;
    }
    return true;
  };
  try {
    return Json::parse(text, callback, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const Json::exception& e) {
    // Syntax errors, and also numbers that do not fit a double (out_of_range, e.g. 1e400): both are malformed
    // text, named with the key path reached so far.
    std::string what = e.what();
    if (what.rfind("[json.exception.", 0) == 0) what = what.substr(what.find(']') + 2);
    const std::string at = path_to(stack.size());
    fail(source, "malformed JSON: " + what + (at.empty() ? std::string() : " (in " + at + ")"));
  }
}

Json read_json_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) fail(file.string(), "is a directory, not a scene file");
  if (!std::filesystem::is_regular_file(file, ec)) fail(file.string(), "no such scene file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file.string(), "cannot read the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_json_text(text.str(), file.string());
}

void apply_override(Json& doc, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) fail("--set", "expected key.path=value (got '" + assignment + "')");
  const std::string key_path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  const std::string where = "--set " + key_path;

  // Split "a.b[2].c" / "a.b.2.c" into segments.
  std::vector<std::string> segments;
  std::string cur;
  for (std::size_t i = 0; i < key_path.size(); ++i) {
    const char c = key_path[i];
    if (c == '.') {
      segments.push_back(cur);
      cur.clear();
    } else if (c == '[') {
      const std::size_t close = key_path.find(']', i);
      if (close == std::string::npos) fail(where, "unbalanced '['");
      segments.push_back(cur);
      cur = key_path.substr(i + 1, close - i - 1);
      i = close;
    } else {
      cur += c;
    }
  }
  segments.push_back(cur);
  segments.erase(std::remove(segments.begin(), segments.end(), std::string()), segments.end());
  if (segments.empty()) fail(where, "empty key path");

  Json value;
  try {
    value = Json::parse(text);
  } catch (const Json::parse_error&) {
    value = text;  // a bare word: a string
  }

  auto is_index = [](const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  Json* node = &doc;
  std::string walked;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const std::string& seg = segments[k];
    const bool last = k + 1 == segments.size();
    if (node->is_array()) {
      if (!is_index(seg)) fail(where, (walked.empty() ? "(root)" : walked) + " is an array: '" + seg + "' is not an index");
      const std::size_t i = std::stoul(seg);
      if (i >= node->size()) {
        fail(where, "index " + seg + " is out of range (" + walked + " has " + std::to_string(node->size()) + " elements)");
      }
      walked = element(walked, i);
      if (last) {
        if (value.is_null()) {
          node->erase(i);
        } else {
          (*node)[i] = value;
        }
        return;
      }
      node = &(*node)[i];
    } else {
      if (!node->is_object()) fail(where, (walked.empty() ? "(root)" : walked) + " is not an object");
      walked = join(walked, seg);
      if (last) {
        if (value.is_null()) {
          node->erase(seg);
        } else {
          (*node)[seg] = value;
        }
        return;
      }
      if (!node->contains(seg)) (*node)[seg] = Json::object();
      node = &(*node)[seg];
    }
  }
}

// ---- Scene <-> JSON -------------------------------------------------------------------------------------------

Scene scene_from_json(const Json& doc) {
  Scene s;
  schema::read_section(schema::scene_section(), doc, "", s);
  // Default probe names (kind and index) before validation, so that they are checked for uniqueness too.
  for (std::size_t i = 0; i < s.probes.size(); ++i) {
    if (!doc.at("probes")[i].contains("name")) s.probes[i].name = std::string(to_string(s.probes[i].kind)) + "_" + std::to_string(i);
  }
  validate_scene(s);
  return s;
}

Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  Json doc = read_json_file(file);
  for (const auto& o : overrides) apply_override(doc, o);
  if (doc.is_object() && !doc.contains("name")) {
    std::string stem = file.stem().string();
    for (char& c : stem) {
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) c = '_';
    }
    doc["name"] = stem.empty() ? std::string("scene") : stem;
  }
  return scene_from_json(doc);
}

}  // namespace sph::scene
