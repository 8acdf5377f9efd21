#include "app/commands.hpp"

#include <CLI/Version.hpp>
#include <hdf5.h>
#include <omp.h>

#include <Eigen/Core>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "app/progress.hpp"
#include "core/scene/runner.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"

namespace sph::app {

namespace {

int scene_error(const scene::SceneError& e) {
  std::fprintf(stderr, "%s\n", e.what());
  return scene::kSceneErrorExitCode;
}

std::filesystem::path output_folder(const scene::Scene& s, const std::string& option) {
  if (!option.empty()) return option;
  if (!s.output.folder.empty()) return s.output.folder;
  return std::filesystem::path("out") / s.name;
}

std::string levels_text(const std::vector<std::size_t>& per_level) {
  std::string out;
  for (std::size_t l = 0; l < per_level.size(); ++l) {
    out += (l ? "  " : "") + std::string("L") + std::to_string(l) + " " + std::to_string(per_level[l]);
  }
  return out.empty() ? "none" : out;
}

void print_summary(const scene::Scene& s, const scene::RunSummary& r, const std::filesystem::path& folder) {
  const double pps = r.wall_seconds > 0.0 ? static_cast<double>(r.particle_steps) / r.wall_seconds : 0.0;
  std::printf("sphrefine: %s reached t = %.6g s (step %llu) in %.3f s wall\n", s.name.c_str(), r.final.time,
              static_cast<unsigned long long>(r.final.step), r.wall_seconds);
  std::printf("  steps              %llu (this run)\n", static_cast<unsigned long long>(r.steps));
  std::printf("  particle-steps/s   %.4g\n", pps);
  std::printf("  fluid per level    %s (walls %zu)\n", levels_text(r.final.per_level).c_str(), r.final.walls);
  if (r.final.removed > 0) {
    std::printf("  removed            %llu fluid particles through the open top, %.6g kg/m (%.3g %% of M0)\n",
                static_cast<unsigned long long>(r.final.removed), r.final.removed_mass,
                r.initial_mass > 0.0 ? 100.0 * r.final.removed_mass / r.initial_mass : 0.0);
  }
  std::printf("  mass drift         %+.3e (relative, removed fluid counted)\n", r.mass_drift);
  std::printf("  momentum change    |P - P0| = %.3e kg m/s (P = [%.3e, %.3e])\n", r.momentum_change,
              r.final.momentum[0], r.final.momentum[1]);
  if (!folder.empty()) {
    std::printf("  output             %s (%llu rows, %llu frames, %llu checkpoints)\n", folder.string().c_str(),
                static_cast<unsigned long long>(r.rows), static_cast<unsigned long long>(r.frames),
                static_cast<unsigned long long>(r.checkpoints));
  }
}

}  // namespace

int run_command(const RunArguments& args) {
  scene::Scene s;
  try {
    s = scene::load_scene(args.scene, args.overrides);
  } catch (const scene::SceneError& e) {
    return scene_error(e);
  }
  const std::filesystem::path folder = output_folder(s, args.output);
  const io::RunFiles files{folder};
  if (!args.resume.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(args.resume, ec)) {
      std::fprintf(stderr, "error: --resume: no such checkpoint file '%s'\n", args.resume.c_str());
      return kExitUsage;
    }
    if (args.force) {
      std::fprintf(stderr, "error: --resume continues the run in its folder; --force would erase it\n");
      return kExitUsage;
    }
  } else if (files.holds_run() && !args.force) {
    std::fprintf(stderr,
                 "error: %s already holds a run; use --force to overwrite it, or -o to write elsewhere\n",
                 folder.string().c_str());
    return kExitFolderHoldsRun;
  }
  if (args.threads > 0) omp_set_num_threads(args.threads);

  scene::RunOptions options;
  options.folder = folder;
  if (!args.resume.empty()) options.resume = args.resume;
  if (args.checkpoint_every > 0.0) options.checkpoint_interval = args.checkpoint_every;
  ProgressPrinter progress(stdout, args.quiet);
  try {
    scene::Runner runner(s, options);
    if (args.force && args.resume.empty()) files.clear_run();
    if (!args.quiet) {
      std::printf("sphrefine %s: %s, %zu fluid particles, threads %d, sweep %s -> %s\n", SPH_VERSION, s.name.c_str(),
                  runner.simulation().diagnostics().fluid, omp_get_max_threads(), runner.simulation().sweep_name(),
                  folder.string().c_str());
      if (options.resume) {
        std::printf("resuming from %s at t = %.6g s (step %llu)\n", args.resume.c_str(), runner.simulation().time(),
                    static_cast<unsigned long long>(runner.simulation().step_count()));
      }
      std::fflush(stdout);
    }
    const scene::RunSummary summary = runner.run([&](const scene::Progress& p) { progress(p); });
    progress.done();
    print_summary(s, summary, folder);
  } catch (const scene::SceneError& e) {
    progress.done();
    return scene_error(e);
  } catch (const std::exception& e) {
    progress.done();
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitFailure;
  }
  return 0;
}

int validate_command(const std::string& path, const std::vector<std::string>& overrides) {
  scene::Scene s;
  try {
    s = scene::load_scene(path, overrides);
  } catch (const scene::SceneError& e) {
    return scene_error(e);
  }
  try {
    const Simulation sim = scene::build_simulation(s);
    const Diagnostics d = sim.diagnostics();
    std::printf("scene OK: %s\n", s.name.c_str());
    std::printf("  fluid particles    %zu (%s), wall particles %zu\n", d.fluid, levels_text(d.per_level).c_str(), d.walls);
    std::printf("  sound speed        c0 = %.6g m/s, finest level %d (spacing %.6g m)\n", scene::sound_speed(s),
                scene::finest_level(s), scene::finest_spacing(s));
    std::printf("  sweep              %s%s\n", sim.sweep_name(), s.effects.ghost_walls ? ", ghost walls" : "");
    std::printf("  first time step    %.6g s, end time %.6g s\n", sim.dt(), s.time.end);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: the scene passed validation but could not be set up: %s\n", e.what());
    return kExitFailure;
  }
  return 0;
}

int info_command() {
  unsigned h5_major = 0, h5_minor = 0, h5_release = 0;
  H5get_libversion(&h5_major, &h5_minor, &h5_release);
  std::printf("sphrefine %s (%s build)\n", SPH_VERSION, SPH_BUILD_TYPE);
  std::printf("  OpenMP      %d (max threads %d, processors %d)\n", _OPENMP, omp_get_max_threads(), omp_get_num_procs());
  std::printf("  Eigen       %d.%d.%d\n", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION);
  std::printf("  HDF5        %u.%u.%u\n", h5_major, h5_minor, h5_release);
  std::printf("  nlohmann    %d.%d.%d\n", NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH);
  std::printf("  CLI11       %s\n", CLI11_VERSION);
  return 0;
}

}  // namespace sph::app
