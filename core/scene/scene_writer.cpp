// The scene's JSON writer: scene_to_json (declared in scene_parser.hpp), the inverse of scene_from_json for
// every accepted scene (tested by the round-trip tests and the fuzzer). It writes every key the registry
// (scene_keys.cpp) declares: defaults written out, optional keys when set, empty strings and arrays left out.
#include "core/scene/scene_parser.hpp"
#include "core/scene/scene_schema.hpp"

namespace sph::scene {

Json scene_to_json(const Scene& s) { return schema::write_section(schema::scene_section(), s); }

}  // namespace sph::scene
