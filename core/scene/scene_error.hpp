#pragma once
// The one error a bad scene produces: "scene error: <key.path>: <rule>". The program prints it, exits
// with kSceneErrorExitCode, and has created nothing.
#include <stdexcept>
#include <string>

namespace sph::scene {

/// Exit code of the program for a scene (or command-line override) it refuses.
inline constexpr int kSceneErrorExitCode = 2;

class SceneError : public std::runtime_error {
 public:
  SceneError(std::string path, std::string rule)
      : std::runtime_error("scene error: " + (path.empty() ? std::string("(root)") : path) + ": " + rule),
        path_(std::move(path)),
        rule_(std::move(rule)) {}

  /// Where: a key path such as "fluid[0].spacing" (empty for the document itself).
  const std::string& path() const { return path_; }
  /// What rule it breaks.
  const std::string& rule() const { return rule_; }
  int exit_code() const { return kSceneErrorExitCode; }

 private:
  std::string path_;
  std::string rule_;
};

}  // namespace sph::scene
