#pragma once
// Scene files (JSON, docs/SCENES.md) -> Scene, with strict validation before anything runs: an unknown
// key, a wrong type, a missing required key, a non-physical value or an inconsistent geometry each
// raise one SceneError naming the key path and the rule. Nothing here touches the file system except
// reading the scene file.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene/scene.hpp"
#include "core/scene/scene_error.hpp"

namespace sph::scene {

/// The document type: keys keep their order (messages and written scenes follow the file).
using Json = nlohmann::ordered_json;

/// Parses JSON text (comments allowed); malformed text or a duplicate key is a SceneError whose path is
/// `source` (or the duplicate key's path).
Json parse_json_text(const std::string& text, const std::string& source);

/// Reads and parses a scene file.
Json read_json_file(const std::filesystem::path& file);

/// Applies one command-line override "key.path=value" (segments separated by '.', array elements as
/// "name[3]" or "name.3"). The value is read as JSON when it parses (numbers, true/false, arrays,
/// objects, quoted strings), as a plain string otherwise; "null" removes the key.
void apply_override(Json& doc, const std::string& assignment);

/// Structural parse (keys, types, required keys, enumerations) and then validate_scene().
Scene scene_from_json(const Json& doc);

/// The complete scene as JSON, every default written out; scene_from_json(scene_to_json(s)) == s.
Json scene_to_json(const Scene& s);

/// The value rules (ranges, geometry, resolution); throws SceneError on the first broken rule.
void validate_scene(const Scene& s);

/// read_json_file + overrides + scene_from_json; the name defaults to the file's stem.
Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

/// The names of the particle fields an output may list (the store's registry).
std::vector<std::string> particle_field_names();

}  // namespace sph::scene
