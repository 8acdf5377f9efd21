// sphrefine: the command-line program, thin over core/ (see app/commands.hpp for the exit codes).
//   sphrefine run SCENE [-o DIR] [--threads N] [--set key.path=value ...] [--force]
//                       [--checkpoint-every T] [--resume CHECKPOINT] [--quiet]
//   sphrefine validate SCENE [--set key.path=value ...]
//   sphrefine info
//   sphrefine keys [--markdown | --sync FILE | --check FILE]
// Built with the mpi preset, `mpirun -np N sphrefine run SCENE` runs the scene across N ranks (issue #19).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <optional>

#include "app/commands.hpp"
#include "app/wait_policy.hpp"
#include "core/allocator_tuning.hpp"
#include "parallel/comm.hpp"

namespace {

int program(int argc, char** argv) {
  CLI::App app{"sphrefine: weakly-compressible SPH with dynamic particle refinement"};
  app.require_subcommand(1);

  sph::app::RunArguments run;
  CLI::App* run_cmd = app.add_subcommand("run", "Run a scene file to its end time, writing its outputs");
  run_cmd->add_option("scene", run.scene, "Scene file (JSON, docs/SCENES.md)")->required();
  run_cmd->add_option("-o,--output", run.output, "Output folder (default: output.folder, else out/<name>)");
  run_cmd->add_option("--threads", run.threads, "OpenMP threads (default: one per 4096 fluid particles, at most OMP_NUM_THREADS or the processors)")
      ->check(CLI::Validator(sph::app::threads_option_error, "1.." + std::to_string(sph::app::max_threads_option())));
  run_cmd->add_option("--set", run.overrides, "Override a scene key before validation: key.path=value (repeatable)")
      ->expected(1)
      ->take_all();
  run_cmd->add_flag("--force", run.force, "Overwrite an output folder that already holds a run");
  run_cmd->add_option("--checkpoint-every", run.checkpoint_every,
                      "Write <output>/checkpoint.h5 every T simulated seconds and at the end")
      ->check(CLI::Validator(sph::app::checkpoint_every_option_error, "SECONDS > 0"));
  run_cmd->add_option("--resume", run.resume, "Continue the run in the output folder from this checkpoint");
  run_cmd->add_flag("-q,--quiet", run.quiet, "No progress line and no banner");

  std::string validate_scene;
  std::vector<std::string> validate_overrides;
  CLI::App* validate_cmd = app.add_subcommand("validate", "Check a scene file and report what it sets up; writes nothing");
  validate_cmd->add_option("scene", validate_scene, "Scene file (JSON)")->required();
  validate_cmd->add_option("--set", validate_overrides, "Override a scene key: key.path=value (repeatable)")
      ->expected(1)
      ->take_all();

  CLI::App* info_cmd = app.add_subcommand("info", "Version, build type, threads and library versions");

  sph::app::KeysArguments keys;
  std::string keys_check;
  CLI::App* keys_cmd = app.add_subcommand("keys", "Every scene key: path, type, unit, default, range (docs/SCENES.md)");
  auto* markdown_opt =
      keys_cmd->add_flag("--markdown", keys.markdown, "The key tables of docs/SCENES.md, each between its markers");
  auto* sync_opt = keys_cmd->add_option("--sync", keys.file, "Rewrite the key tables between the markers of this file");
  auto* check_opt = keys_cmd->add_option("--check", keys_check, "Exit 1 when this file's key tables differ from the registry");
  sync_opt->excludes(check_opt);
  markdown_opt->excludes(sync_opt)->excludes(check_opt);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : sph::app::kExitUsage;
  }
  if (run_cmd->parsed()) return sph::app::run_command(run);
  if (validate_cmd->parsed()) return sph::app::validate_command(validate_scene, validate_overrides);
  if (info_cmd->parsed()) return sph::app::info_command();
  if (keys_cmd->parsed()) {
    if (!keys_check.empty()) keys.file = keys_check, keys.check = true;
    return sph::app::keys_command(keys);
  }
  return sph::app::kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  sph::app::ensure_wait_policy(argv);  // may start the program again, before anything else happens
  sph::tune_allocator();
  std::optional<sph::par::Session> mpi;
  try {
    mpi.emplace(argc, argv);  // MPI only when an MPI launcher started this process
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return sph::app::kExitUsage;
  }
  const int code = program(argc, argv);
  // A rank that stops with an error takes the others down with it (they may be waiting for it), with its code.
  if (code != 0 && sph::par::Comm::world().distributed()) sph::par::Session::abort(code);
  return code;
}
