// The registry's key tables for docs/SCENES.md (`sphrefine keys --markdown`, `--sync`) and its list of every
// key path. The tables sit between marker comments in the document; the prose around them is hand-written.
#include <stdexcept>

#include "core/scene/scene_keys.hpp"

namespace sph::scene {

namespace {

constexpr const char* kRootPath = "(top level)";
constexpr const char* kBegin = "<!-- keys: ";
constexpr const char* kBeginEnd = " -->";
constexpr const char* kEnd = "<!-- end keys -->";

std::string join(const std::string& path, const std::string& name) { return path.empty() ? name : path + "." + name; }

/// Where an object's keys are: "effects.refinement", or an array's elements: "fluid[i]".
std::string inner_path(const std::string& path, const KeyInfo& k) {
  return join(path, k.type == KeyType::array ? k.name + "[i]" : k.name);
}

void collect(const SectionInfo& s, const std::string& path, std::vector<KeyEntry>& out) {
  for (const KeyInfo& k : s.keys) {
    out.push_back(KeyEntry{join(path, k.name), &k, &s});
    if (k.section) collect(*k.section, inner_path(path, k), out);
  }
}

std::string code_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "`" : ", `") + n + "`";
  return out;
}

std::string default_cell(const KeyInfo& k) {
  if (k.presence == Presence::required) return "**required**";
  if (k.presence == Presence::optional && k.default_text.empty()) return "absent";
  return k.default_text;
}

std::string allowed_cell(const KeyInfo& k) {
  std::string out;
  if (k.range) out = k.range->text();
  if (!k.choices.empty()) out = code_list(k.choices);
  if (!k.note.empty()) out += (out.empty() ? "" : "; ") + k.note;
  return out;
}

/// '|' inside a cell would end it.
std::string cell(std::string text) {
  for (std::size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) text.replace(at, 1, "\\|");
  return text;
}

}  // namespace

std::vector<KeyEntry> all_keys() {
  std::vector<KeyEntry> out;
  collect(scene_keys(), "", out);
  return out;
}

std::vector<std::pair<std::string, const SectionInfo*>> documented_sections() {
  std::vector<std::pair<std::string, const SectionInfo*>> out{{kRootPath, &scene_keys()}};
  for (const KeyEntry& e : all_keys()) {
    const SectionInfo* s = e.key->section;
    if (!s) continue;
    bool seen = false;
    for (const auto& [path, section] : out) seen = seen || section == s;
    if (!seen) out.emplace_back(e.key->type == KeyType::array ? e.path + "[i]" : e.path, s);
  }
  return out;
}

std::string key_table(const SectionInfo& s) {
  const bool variants = s.polymorphic();
  std::string out = variants ? "| key | for | type | unit | default | allowed | meaning |\n|---|---|---|---|---|---|---|\n"
                             : "| key | type | unit | default | allowed | meaning |\n|---|---|---|---|---|---|\n";
  for (const KeyInfo& k : s.keys) {
    out += "| `" + k.name + "` | ";
    if (variants) out += (k.only_for.empty() ? std::string("all") : code_list(k.only_for)) + " | ";
    out += cell(k.type_text) + " | " + cell(k.unit) + " | " + cell(default_cell(k)) + " | " + cell(allowed_cell(k)) +
           " | " + cell(k.description) + " |\n";
  }
  return out;
}

std::string key_tables_markdown() {
  std::string out;
  for (const auto& [path, section] : documented_sections()) {
    out += kBegin + path + kBeginEnd + "\n" + key_table(*section) + kEnd + "\n\n";
  }
  return out;
}

std::string sync_key_tables(const std::string& markdown) {
  const auto sections = documented_sections();
  std::vector<bool> placed(sections.size(), false);
  std::string out;
  std::size_t at = 0;
  for (std::size_t begin = markdown.find(kBegin); begin != std::string::npos; begin = markdown.find(kBegin, at)) {
    const std::size_t name_at = begin + std::string(kBegin).size();
    const std::size_t name_end = markdown.find(kBeginEnd, name_at);
    const std::size_t end = markdown.find(kEnd, name_at);
    if (name_end == std::string::npos || end == std::string::npos || name_end > end) {
      throw std::runtime_error("a '" + std::string(kBegin) + "' marker without its '" + kEnd + "'");
    }
    const std::string path = markdown.substr(name_at, name_end - name_at);
    std::size_t k = 0;
    while (k < sections.size() && sections[k].first != path) ++k;
    if (k == sections.size()) throw std::runtime_error("the marker names no scene object: '" + path + "'");
    placed[k] = true;
    const std::size_t body = name_end + std::string(kBeginEnd).size() + 1;  // after the marker's line
    out += markdown.substr(at, body - at) + key_table(*sections[k].second);
    at = end;
  }
  out += markdown.substr(at);
  for (std::size_t k = 0; k < sections.size(); ++k) {
    if (!placed[k]) throw std::runtime_error("no table for '" + sections[k].first + "' (add its markers)");
  }
  return out;
}

}  // namespace sph::scene
