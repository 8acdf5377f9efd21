#pragma once
// Scene documents for the scene tests (tests/test_scene_parser.cpp, tests/test_scene_coupling.cpp): a small valid
// scene with every section, and the error a document raises.
#include <string>

#include "core/scene/scene_error.hpp"
#include "core/scene/scene_parser.hpp"

namespace sph::test {

using scene::Json;

/// A small valid scene exercising every section; tests break one thing at a time.
inline Json full_scene() {
  return scene::parse_json_text(R"({
    "name": "full",
    "description": "every key",
    "container": { "lo": [0, 0], "hi": [20, 10], "open_top": false },
    "obstacles": [ { "lo": [14, 0], "hi": [15, 3] } ],
    "fluid": [
      { "shape": "rectangle", "lo": [0, 0], "hi": [5, 5], "spacing": 0.5, "hydrostatic": true, "surface": 5 },
      { "shape": "circle", "centre": [8, 7], "radius": 1.0, "spacing": 0.5, "level": 1, "velocity": [0, -1] }
    ],
    "h_factor": 1.3,
    "material": { "rho0": 1000, "gamma": 7, "mach_factor": 10, "reference_height": 5 },
    "effects": {
      "gravity": [0, -9.81],
      "artificial_viscosity": { "alpha": 0.05, "beta": 0.1 },
      "artificial_stress": { "epsilon": 0.3, "exponent": 3 },
      "density_diffusion": { "delta": 0.12 },
      "lennard_jones_wall": { "reference_height": 5, "r0_factor": 0.5 },
      "ghost_walls": "no-slip",
      "refinement": { "criterion": "zone", "zone": { "lo": [0, 0], "hi": [3, 3] }, "pattern": "rsp", "rsp_k": 0.5,
                      "check_interval": 10, "max_level": 2 }
    },
    "time": { "end": 1.5, "cfl": 0.25, "output_interval": 0.1, "dt_max": 0.01 },
    "probes": [
      { "type": "water_height", "name": "H", "x": 0, "band": 0.6 },
      { "type": "surge_front", "origin": 0 },
      { "type": "surface_elevation", "name": "eta", "x": 10, "datum": 5 },
      { "type": "pressure", "name": "p", "position": [1, 1] }
    ],
    "output": { "folder": "out/full", "frames": true, "frame_interval": 0.5, "fields": ["position", "velocity"] }
  })",
                         "full_scene");
}

/// The SceneError a document raises ("" when it is accepted).
inline std::string error_of(const Json& doc) {
  try {
    (void)scene::scene_from_json(doc);
  } catch (const scene::SceneError& e) {
    return e.what();
  }
  return "";
}

}  // namespace sph::test
