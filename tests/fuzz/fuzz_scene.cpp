// libFuzzer target for the scene parser (the asan preset builds it with clang: -fsanitize=fuzzer plus ASan
// and UBSan). Every input is a scene file's text. What must hold for any input:
//   - parsing and validation either accept it or throw SceneError (one message naming the key); any other
//     exception, a crash, a leak or undefined behaviour is a finding;
//   - an accepted scene round-trips: scene_from_json(scene_to_json(s)) == s;
//   - an accepted scene that is small enough (estimated_particles <= kMaxRunParticles) is built and run for
//     a few steps, so that odd but valid scenes reach the solver too; a watchdog stop (SimulationFailure) is
//     a valid outcome of an odd scene, anything else is a finding.
// scripts/fuzz runs it for a bounded time with the scene files of cases/ as the seed corpus.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "core/simulation.hpp"
#include "core/watchdog.hpp"

namespace {

constexpr double kMaxRunParticles = 3000.0;  // keeps an execution in the milliseconds
constexpr int kSteps = 4;

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_scene: %s: %s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sph;
  using namespace sph::scene;
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scene s;
  try {
    s = scene_from_json(parse_json_text(text, "fuzz"));
  } catch (const SceneError&) {
    return 0;  // rejected with a message: the expected answer to most inputs
  } catch (const std::exception& e) {
    finding("the parser threw something other than SceneError", e.what());
  }
  try {
    if (!(scene_from_json(scene_to_json(s)) == s)) finding("round trip", "scene_from_json(scene_to_json(s)) != s");
  } catch (const std::exception& e) {
    finding("an accepted scene's own JSON was rejected", e.what());
  }
  if (!(estimated_particles(s) <= kMaxRunParticles)) return 0;
  try {
    with_dimension(s, [&](auto dim) {
      auto sim = build_simulation<decltype(dim)::value>(s);
      for (int k = 0; k < kSteps && sim.time() < s.time.end; ++k) {
        sim.step(s.time.end - sim.time());
        sim.run_stages();
      }
    });
  } catch (const SimulationFailure&) {
    return 0;  // the watchdog stopped an odd scene: a clear, valid outcome
  } catch (const std::exception& e) {
    finding("a valid scene failed to build or run", e.what());
  }
  return 0;
}
