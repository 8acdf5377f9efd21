// The program on busy cores: `sphrefine run` as a user starts it (its default thread count and wait
// policy), timed as a whole process, on quiet cores and with a busy loop on every core. The busy loops are
// threads of this benchmark, started before the run and stopped after it; they only spin.
//
// Cases: the paper's dam break (cases/dam_break.json, 900 fluid particles: one thread by the work rule) and
// the same at 16x the particles (d = 25/120 m, 14,400: two threads on two cores). Each also with the old
// behaviour forced (--threads 2 and OMP_WAIT_POLICY=active), to show what the defaults remove; at 14,400 on
// quiet cores only (what the passive policy costs there): on busy cores it collapses and takes many minutes.
// The end time is cut to 1 s of the 4 s run: the ratio busy / quiet is the figure, not the time itself.
#include <benchmark/benchmark.h>
#include <spawn.h>
#include <sys/wait.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#ifndef SPH_SOURCE_DIR
#error "SPH_SOURCE_DIR must name the repository root"
#endif
#ifndef SPH_PROGRAM
#error "SPH_PROGRAM must name the sphrefine executable"
#endif

extern char** environ;

namespace {

/// One spinning thread per core while alive.
class BusyCores {
 public:
  BusyCores() {
    const unsigned n = std::max(1u, std::thread::hardware_concurrency());
    for (unsigned k = 0; k < n; ++k) {
      threads_.emplace_back([this] {
        volatile double x = 1.0;
        while (!stop_.load(std::memory_order_relaxed)) x = x * 1.0000001 + 1e-9;
      });
    }
  }
  ~BusyCores() {
    stop_ = true;
    for (auto& t : threads_) t.join();
  }
  BusyCores(const BusyCores&) = delete;
  BusyCores& operator=(const BusyCores&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

/// Runs the program to completion with `args` and the environment less the OpenMP variables, plus `env`.
void run_program(const std::vector<std::string>& args, const std::vector<std::string>& env) {
  std::vector<std::string> envs;
  for (char** e = environ; *e; ++e) {
    const std::string v = *e;
    if (v.rfind("OMP_", 0) == 0 || v.rfind("GOMP_", 0) == 0 || v.rfind("KMP_", 0) == 0) continue;
    envs.push_back(v);
  }
  for (const auto& v : env) envs.push_back(v);
  std::vector<char*> argv, envp;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  for (const auto& v : envs) envp.push_back(const_cast<char*>(v.c_str()));
  envp.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), envp.data()) != 0) {
    throw std::runtime_error("cannot start " + args[0]);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error("the run failed");
}

struct Variant {
  std::string spacing;            // fluid.0.spacing
  std::vector<std::string> extra;  // extra arguments
  std::vector<std::string> env;    // extra environment
};

void BM_Program(benchmark::State& state, Variant v, bool busy) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "sph_bench_busy";
  std::vector<std::string> args{SPH_PROGRAM, "run", std::string(SPH_SOURCE_DIR) + "/cases/dam_break.json",
                                "-o", out.string(), "--force", "--quiet", "--set", "time.end=1.0",
                                "--set", "fluid.0.spacing=" + v.spacing, "--set", "output.frames=false"};
  args.insert(args.end(), v.extra.begin(), v.extra.end());
  for (auto _ : state) {
    if (busy) {
      BusyCores load;
      run_program(args, v.env);
    } else {
      run_program(args, v.env);
    }
  }
  std::filesystem::remove_all(out);
}

const Variant kPaper{"0.8333333333333334", {}, {}};
const Variant kPaperOld{"0.8333333333333334", {"--threads", "2"}, {"OMP_WAIT_POLICY=active"}};
const Variant kFine{"0.20833333333333334", {}, {}};
const Variant kFineOld{"0.20833333333333334", {"--threads", "2"}, {"OMP_WAIT_POLICY=active"}};

void registered() {
  struct Entry {
    const char* name;
    const Variant* v;
  };
  for (const Entry& e : {Entry{"DamBreak900/default", &kPaper}, Entry{"DamBreak900/old_2threads_active", &kPaperOld},
                         Entry{"DamBreak14400/default", &kFine}, Entry{"DamBreak14400/old_2threads_active", &kFineOld}}) {
    for (const bool busy : {false, true}) {
      if (busy && e.v == &kFineOld) continue;  // the collapse itself: minutes a repetition, nothing to learn
      benchmark::RegisterBenchmark((std::string("BM_Program/") + e.name + (busy ? "/busy" : "/quiet")).c_str(),
                                   BM_Program, *e.v, busy)
          ->Unit(benchmark::kSecond)
          ->UseRealTime()
          ->Iterations(1);
    }
  }
}

const bool registered_once = (registered(), true);

}  // namespace

BENCHMARK_MAIN();
