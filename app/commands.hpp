#pragma once
// The program's commands, thin over core/: run, validate, info, keys. Each returns the process exit code:
//   0 success, 1 the run failed (diverged, I/O), 2 a scene or command-line error (nothing created),
//   3 the output folder already holds a run (use --force).
#include <optional>
#include <string>
#include <vector>

namespace sph::app {

inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitFolderHoldsRun = 3;

struct RunArguments {
  std::string scene;
  std::string output;
  int threads = 0;
  std::vector<std::string> overrides;
  bool force = false;
  std::string resume;
  double checkpoint_every = 0.0;
  bool quiet = false;
};

/// The largest --threads value: 4 threads per processor the process may run on (omp_get_num_procs()).
int max_threads_option();
/// The rule a --threads value breaks ("" when it is a whole number from 1 to max_threads_option()).
std::string threads_option_error(const std::string& value);
/// The rule a --checkpoint-every value breaks ("" when it is a positive, finite number of seconds).
std::string checkpoint_every_option_error(const std::string& value);

int run_command(const RunArguments& args);
int validate_command(const std::string& scene, const std::vector<std::string>& overrides);
int info_command();

struct KeysArguments {
  bool markdown = false;  // the tables of docs/SCENES.md instead of the list
  std::string file;       // a Markdown file whose tables to rewrite (--sync) or compare (--check)
  bool check = false;     // with a file: exit 1 when its tables differ, change nothing
};
/// The scene key registry: every key path with its type, default and range; or its Markdown tables; or a file's
/// tables rewritten or checked (exit 1 when they differ).
int keys_command(const KeysArguments& args);

}  // namespace sph::app
