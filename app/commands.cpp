#include "app/commands.hpp"

#include <CLI/Version.hpp>
#include <hdf5.h>
#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "app/progress.hpp"
#include "core/io/hdf5_frames.hpp"
#include "core/scene/runner.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "parallel/comm.hpp"

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

/// "[1.5e+00, -2.0e-03]" or "[..., ..., ...]".
template <int D>
std::string vector_text(const Vec<D>& v) {
  std::string out = "[";
  char buf[32];
  for (int a = 0; a < D; ++a) {
    std::snprintf(buf, sizeof buf, "%.3e", v[a]);
    out += (a ? ", " : "") + std::string(buf);
  }
  return out + "]";
}

template <int D>
void print_summary(const scene::Scene& s, const scene::RunSummaryT<D>& r, const std::filesystem::path& folder) {
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
  std::printf("  momentum change    |P - P0| = %.3e kg m/s (P = %s)\n", r.momentum_change,
              vector_text<D>(r.final.momentum).c_str());
  if (!folder.empty()) {
    std::printf("  output             %s (%llu rows, %llu frames, %llu checkpoints)\n", folder.string().c_str(),
                static_cast<unsigned long long>(r.rows), static_cast<unsigned long long>(r.frames),
                static_cast<unsigned long long>(r.checkpoints));
  }
}

/// The first line of `file` that starts with `key` (then whitespace or ':'), as the number after it; nullopt
/// when there is none. `key` empty: the file's first word as a number ("max" is not one).
std::optional<double> read_number(const std::filesystem::path& file, const std::string& key = "") {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (!key.empty()) {
      if (first != key && first != key + ":") continue;
      words >> first;
    }
    char* end = nullptr;
    const double x = std::strtod(first.c_str(), &end);
    if (first.empty() || *end != '\0' || !std::isfinite(x)) return std::nullopt;
    return x;
  }
  return std::nullopt;
}

/// The path of this process's cgroup (from /proc/self/cgroup): in cgroup v2 the line "0::/a/b", in cgroup v1
/// the memory controller's line "4:memory:/a/b".
std::string own_cgroup(bool v2) {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    std::string controllers(1, ',');  // ",memory," or ",," (v2)
    controllers.append(line, a + 1, b - a - 1).push_back(',');
    if (v2 ? line.compare(0, a, "0") == 0 && controllers == ",," : controllers.find(",memory,") != std::string::npos) {
      return line.substr(b + 1);
    }
  }
  return "";
}

/// What a cgroup memory limit leaves this process (bytes), when one is set: the limit less the usage, the
/// usage without the page cache the kernel can drop (inactive_file). cgroup v2 (memory.max) or v1.
std::optional<double> cgroup_memory_left() {
  struct Hierarchy {
    bool v2;
    const char* root;
    const char *limit, *usage, *inactive;
  };
  for (const Hierarchy& h : {Hierarchy{true, "/sys/fs/cgroup", "memory.max", "memory.current", "inactive_file"},
                             Hierarchy{false, "/sys/fs/cgroup/memory", "memory.limit_in_bytes", "memory.usage_in_bytes",
                                       "total_inactive_file"}}) {
    // Inside a container the process's own cgroup is usually the hierarchy's root as mounted there.
    for (const std::filesystem::path& dir : {std::filesystem::path(h.root + own_cgroup(h.v2)), std::filesystem::path(h.root)}) {
      const std::optional<double> limit = read_number(dir / h.limit);
      const std::optional<double> usage = read_number(dir / h.usage);
      if (!limit || !usage) continue;  // no such file, or no limit ("max")
      const double inactive = read_number(dir / "memory.stat", h.inactive).value_or(0.0);
      return std::max(0.0, *limit - std::max(0.0, *usage - inactive));
    }
  }
  return std::nullopt;
}

/// The memory this process can still take (bytes): MemAvailable of /proc/meminfo, lowered to what a cgroup
/// limit leaves; nullopt when neither is known.
std::optional<double> available_memory() {
  std::optional<double> available;
  if (const auto kib = read_number("/proc/meminfo", "MemAvailable")) available = *kib * 1024.0;
  if (const auto left = cgroup_memory_left()) available = std::min(available.value_or(*left), *left);
  return available;
}

/// Whether a run of the scene fits in the memory available, checked before anything is allocated. When it does
/// not, prints the estimate and the memory available and returns false. `report`, when given, receives the
/// estimate (validate prints it). An unknown amount available is not checked.
bool memory_fits(const scene::Scene& s, std::string* report = nullptr) {
  const scene::MemoryEstimate need = scene::estimated_memory(s, omp_get_max_threads());
  const std::optional<double> available = available_memory();
  if (available) {
    const std::string refusal = scene::memory_refusal(need, *available);
    if (!refusal.empty()) {
      std::fprintf(stderr, "error: %s\n", refusal.c_str());
      return false;
    }
  }
  if (report) {
    *report = scene::to_string(need) + " at the start, " + (available ? scene::memory_text(*available) : "unknown") +
              " available";
  }
  return true;
}

}  // namespace

namespace {
// A step runs a few dozen parallel regions, each a fork and a barrier over every thread: past a few threads
// per processor more threads only add waiting and switching, so they only slow a run. Far past it they fail
// outright (tens of thousands of threads: a crash, or minutes before the first step).
constexpr int kThreadsPerProcessor = 4;
}  // namespace

int max_threads_option() { return kThreadsPerProcessor * std::max(1, omp_get_num_procs()); }

std::string threads_option_error(const std::string& value) {
  long long n = 0;
  const char* end = value.data() + value.size();
  const auto [ptr, ec] = std::from_chars(value.data(), end, n);
  const int most = max_threads_option();
  if (ec != std::errc() || ptr != end || n < 1 || n > most) {
    return "must be a whole number from 1 to " + std::to_string(most) + " (got '" + value + "'; more than " +
           std::to_string(kThreadsPerProcessor) + " per processor only slow a run)";
  }
  return "";
}

std::string checkpoint_every_option_error(const std::string& value) {
  char* end = nullptr;
  const double t = value.empty() ? 0.0 : std::strtod(value.c_str(), &end);
  if (value.empty() || end != value.c_str() + value.size() || !std::isfinite(t) || !(t > 0.0)) {
    return "must be a positive number of simulated seconds (got '" + value + "')";
  }
  return "";
}

namespace {

template <int D>
void run_scene(const scene::Scene& s, const scene::RunOptions& options, const RunArguments& args,
               const io::RunFiles& files, const std::filesystem::path& folder, ProgressPrinter& progress) {
  {
    scene::RunnerT<D> runner(s, options);
    const par::Comm& comm = par::Comm::world();
    if (args.force && args.resume.empty() && comm.root()) files.clear_run();
    const std::size_t fluid = runner.simulation().diagnostics().fluid;  // collective when distributed
    if (!args.quiet && comm.root()) {
      std::printf("sphrefine %s: %s (%dD), %zu fluid particles, threads %d, sweep %s -> %s\n", SPH_VERSION,
                  s.name.c_str(), D, fluid, omp_get_max_threads(), runner.simulation().sweep_name(),
                  folder.string().c_str());
      if (comm.distributed()) std::printf("ranks %d (cells cut by Zoltan RCB)\n", comm.size());
      if (options.resume) {
        std::printf("resuming from %s at t = %.6g s (step %llu)\n", args.resume.c_str(), runner.simulation().time(),
                    static_cast<unsigned long long>(runner.simulation().step_count()));
      }
      std::fflush(stdout);
    }
    const scene::RunSummaryT<D> summary = runner.run([&](const scene::Progress& p) { progress(p); });
    progress.done();
    if (comm.root()) print_summary<D>(s, summary, folder);
  }
}

template <int D>
void describe_scene(const scene::Scene& s, const std::string& memory) {
  {
    const SimulationT<D> sim = scene::build_simulation<D>(s);
    const DiagnosticsT<D> d = sim.diagnostics();
    std::printf("scene OK: %s (%dD)\n", s.name.c_str(), D);
    std::printf("  fluid particles    %zu (%s), wall particles %zu\n", d.fluid, levels_text(d.per_level).c_str(), d.walls);
    std::printf("  sound speed        c0 = %.6g m/s, finest level %d (spacing %.6g m)\n", scene::sound_speed(s),
                scene::finest_level(s), scene::finest_spacing(s));
    std::printf("  sweep              %s%s\n", sim.sweep_name(), s.effects.ghost_walls ? ", ghost walls" : "");
    std::printf("  first time step    %.6g s, end time %.6g s\n", sim.dt(), s.time.end);
    std::printf("  memory             %s\n", memory.c_str());
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
    if (const std::string why = io::checkpoint_problem(args.resume); !why.empty()) {
      std::fprintf(stderr, "error: --resume: %s is not a sphrefine checkpoint (%s)\n", args.resume.c_str(), why.c_str());
      return kExitUsage;
    }
    if (const int dim = io::checkpoint_dimension(args.resume); dim != scene::dimension(s)) {
      std::fprintf(stderr, "error: --resume: %s holds a %dD run, but the scene is %dD\n", args.resume.c_str(), dim,
                   scene::dimension(s));
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
  if (!memory_fits(s)) return kExitUsage;

  scene::RunOptions options;
  options.folder = folder;
  if (!args.resume.empty()) options.resume = args.resume;
  if (args.checkpoint_every > 0.0) options.checkpoint_interval = args.checkpoint_every;
  options.threads_from_work = args.threads <= 0;  // --threads fixes the count; otherwise it follows the work
  // Distributed, the root rank speaks for the run; an error every rank meets (the scene's, a watchdog stop) is
  // printed once, by the root, and any other by the rank that met it.
  const par::Comm& comm = par::Comm::world();
  ProgressPrinter progress(stdout, args.quiet || !comm.root());
  try {
    scene::with_dimension(s, [&](auto dim) {
      constexpr int D = decltype(dim)::value;
      run_scene<D>(s, options, args, files, folder, progress);
    });
  } catch (const scene::SceneError& e) {
    progress.done();
    if (!comm.root()) return kExitUsage;
    return scene_error(e);
  } catch (const scene::RunFailure& e) {
    progress.done();
    if (comm.root()) std::fprintf(stderr, "error: %s\n", e.what());
    return kExitFailure;
  } catch (const std::exception& e) {
    progress.done();
    if (comm.distributed()) {
      std::fprintf(stderr, "error (rank %d): %s\n", comm.rank(), e.what());
    } else {
      std::fprintf(stderr, "error: %s\n", e.what());
    }
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
  std::string memory;
  if (!memory_fits(s, &memory)) return kExitUsage;
  try {
    scene::with_dimension(s, [&](auto dim) {
      constexpr int D = decltype(dim)::value;
      describe_scene<D>(s, memory);
    });
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
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  std::printf("  wait policy %s\n", policy ? policy : "the runtime's default (GOMP_SPINCOUNT or KMP_BLOCKTIME set)");
  std::printf("  Eigen       %d.%d.%d\n", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION);
  std::printf("  HDF5        %u.%u.%u\n", h5_major, h5_minor, h5_release);
  std::printf("  nlohmann    %d.%d.%d\n", NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH);
  std::printf("  CLI11       %s\n", CLI11_VERSION);
  std::printf("  MPI         %s\n", par::Session::built_with_mpi()
                                       ? "built with MPI and Zoltan: mpirun -np N sphrefine run SCENE runs across N ranks"
                                       : "not built with it (one process; the mpi preset builds it)");
  return 0;
}

}  // namespace sph::app
