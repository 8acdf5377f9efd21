// sphrefine keys: the scene key registry (core/scene/scene_keys.hpp) as a list, as docs/SCENES.md's tables,
// or written into / checked against a Markdown file between its "<!-- keys: PATH -->" markers.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "app/commands.hpp"
#include "core/scene/scene_keys.hpp"

namespace sph::app {

namespace {

const char* presence_text(scene::Presence p) {
  switch (p) {
    case scene::Presence::required: return "required";
    case scene::Presence::defaulted: return "default";
    case scene::Presence::optional: return "optional";
  }
  return "?";
}

/// One line per key: path, type (unit), default (or required / optional), range or names, the variants it is
/// allowed for.
void print_list() {
  for (const scene::KeyEntry& e : scene::all_keys()) {
    const scene::KeyInfo& k = *e.key;
    std::string line = e.path + "  " + k.type_text;
    if (!k.unit.empty()) line += " (" + k.unit + ")";
    line += "  " + std::string(presence_text(k.presence));
    if (k.presence != scene::Presence::required && !k.default_text.empty()) line += " " + k.default_text;
    if (k.range) line += "  " + k.range->text();
    if (!k.choices.empty()) {
      line += "  one of";
      for (const auto& c : k.choices) line += " " + c;
    }
    if (!k.only_for.empty()) {
      line += "  for";
      for (const auto& v : k.only_for) line += " " + v;
    }
    std::printf("%s\n", line.c_str());
  }
}

}  // namespace

int keys_command(const KeysArguments& args) {
  if (args.file.empty()) {
    if (args.markdown) {
      std::printf("%s", scene::key_tables_markdown().c_str());
    } else {
      print_list();
    }
    return 0;
  }
  std::ifstream in(args.file, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "error: cannot read %s\n", args.file.c_str());
    return kExitUsage;
  }
  std::ostringstream text;
  text << in.rdbuf();
  std::string synced;
  try {
    synced = scene::sync_key_tables(text.str());
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "error: %s: %s\n", args.file.c_str(), e.what());
    return kExitUsage;
  }
  if (synced == text.str()) {
    std::printf("%s: the key tables match the registry\n", args.file.c_str());
    return 0;
  }
  if (args.check) {
    std::fprintf(stderr, "%s: the key tables differ from the registry; run 'sphrefine keys --sync %s'\n",
                 args.file.c_str(), args.file.c_str());
    return kExitFailure;
  }
  std::ofstream out(args.file, std::ios::binary | std::ios::trunc);
  out << synced;
  if (!out) {
    std::fprintf(stderr, "error: cannot write %s\n", args.file.c_str());
    return kExitFailure;
  }
  std::printf("%s: key tables rewritten from the registry\n", args.file.c_str());
  return 0;
}

}  // namespace sph::app
