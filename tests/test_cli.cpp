// The sphrefine program, run as a user would: each kind of bad input ends with exit code 2, one
// "scene error: <key.path>: <rule>" line on stderr and nothing created; a good run writes its folder, prints
// a summary, and a second run into the same folder is refused (exit 3) unless --force.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <regex>
#include <string>

#include "core/io/hdf5_frames.hpp"

namespace {

using namespace sph;

namespace fs = std::filesystem;

/// The program next to this test in the build tree (build/tests/ -> build/app/sphrefine), unless CMake names it.
fs::path program() {
#ifdef SPHREFINE_EXE
  return SPHREFINE_EXE;
#else
  return fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "app" / "sphrefine";
#endif
}

struct Result {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(program())) << program() << " not built";
    dir_ = fs::temp_directory_path() /
           ("sph_test_cli_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  /// Runs the program with `args` (shell words) in the work folder; stdout and stderr go to files outside it.
  /// `env`: words for env(1) (variables to set, or -u NAME to unset); `limits`: shell commands before it (ulimit).
  Result run(const std::string& args, const std::string& env = "OMP_NUM_THREADS=1", const std::string& limits = "") {
    const std::string cmd = "cd '" + (dir_ / "work").string() + "' && " + limits + " env " + env + " '" +
                            program().string() + "' " + args + " > '" + (dir_ / "stdout").string() + "' 2> '" +
                            (dir_ / "stderr").string() + "'";
    const int status = std::system(cmd.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(dir_ / "stdout");
    r.err = slurp(dir_ / "stderr");
    return r;
  }

  void write_scene(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / "work" / name) << text;
  }

  /// The names in the work folder (to check that nothing was created).
  std::vector<std::string> work_files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(dir_ / "work")) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

const char* kTiny = R"({
  "name": "tiny",
  "container": { "lo": [0, 0], "hi": [4, 3] },
  "obstacles": [ { "lo": [3, 0], "hi": [3.5, 0.5] } ],
  "fluid": [ { "shape": "rectangle", "lo": [0, 0], "hi": [1, 2], "spacing": 0.1, "hydrostatic": true } ],
  "material": { "rho0": 1000, "mach_factor": 10, "reference_height": 2 },
  "effects": {
    "gravity": [0, -9.81],
    "artificial_viscosity": { "alpha": 0.02 },
    "lennard_jones_wall": { "reference_height": 2 },
    "ghost_walls": "free-slip",
    "refinement": { "criterion": "velocity", "v_threshold": 0.4, "check_interval": 20, "max_level": 1 }
  },
  "time": { "end": 0.02, "output_interval": 0.005 },
  "probes": [ { "type": "water_height", "name": "H", "x": 0 }, { "type": "surge_front", "name": "Z" } ]
})";

/// kTiny with one textual replacement.
std::string tiny_with(const std::string& from, const std::string& to) {
  std::string s = kTiny;
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST_F(Cli, InfoPrintsVersionsAndThreads) {
  const Result r = run("info");
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* word : {"sphrefine 0.", "OpenMP", "max threads 1", "Eigen", "HDF5", "nlohmann", "CLI11"}) {
    EXPECT_NE(r.out.find(word), std::string::npos) << word << "\n" << r.out;
  }
}

// The program chooses a passive wait policy (app/wait_policy.hpp) unless the environment chooses one.
TEST_F(Cli, InfoNamesTheWaitPolicyTheProgramChoseOrTheUsers) {
  const Result chosen = run("info", "-u OMP_WAIT_POLICY -u GOMP_SPINCOUNT -u KMP_BLOCKTIME OMP_NUM_THREADS=1");
  EXPECT_EQ(chosen.code, 0) << chosen.err;
  EXPECT_NE(chosen.out.find("wait policy passive"), std::string::npos) << chosen.out;
  const Result users = run("info", "OMP_WAIT_POLICY=active OMP_NUM_THREADS=1");
  EXPECT_EQ(users.code, 0) << users.err;
  EXPECT_NE(users.out.find("wait policy active"), std::string::npos) << users.out;
}

// Without --threads the count follows the work (parallel/threads.hpp): the 200-particle scene runs on one
// thread although two are offered; --threads 2 is taken as given.
TEST_F(Cli, ThreadsFollowTheWorkUnlessGiven) {
  write_scene("tiny.json", kTiny);
  ASSERT_EQ(run("run tiny.json -q -o auto", "OMP_NUM_THREADS=2").code, 0);
  const std::string automatic = slurp(dir_ / "work" / "auto" / "run.json");
  EXPECT_NE(automatic.find("\"threads\": 1,"), std::string::npos) << automatic;
  EXPECT_NE(automatic.find("one per 4096 fluid particles, at most 2"), std::string::npos) << automatic;
  ASSERT_EQ(run("run tiny.json -q -o given --threads 2", "OMP_NUM_THREADS=1").code, 0);
  const std::string given = slurp(dir_ / "work" / "given" / "run.json");
  EXPECT_NE(given.find("\"threads\": 2,"), std::string::npos) << given;
  EXPECT_NE(given.find("\"threads_rule\": \"as set\""), std::string::npos) << given;
}

TEST_F(Cli, KeysListsTheRegistryAndKeepsAMarkdownFileInStep) {
  const Result list = run("keys");
  EXPECT_EQ(list.code, 0) << list.err;
  EXPECT_NE(list.out.find("time.cfl  number  default 0.2  0 < x <= 1\n"), std::string::npos) << list.out;
  EXPECT_NE(list.out.find("fluid[i].radius  number (m)  required  > 0  for circle\n"), std::string::npos) << list.out;
  const Result md = run("keys --markdown");
  EXPECT_EQ(md.code, 0);
  EXPECT_NE(md.out.find("<!-- keys: effects.refinement.coarsening -->\n| key | for |"), std::string::npos) << md.out;

  // A file with a stale table: --check fails and changes nothing, --sync rewrites it, then --check passes.
  const std::string all = md.out;
  std::string stale = "# Scenes\n\nprose\n" + all;
  const std::string good_table = "| `cfl` | number |";
  const std::size_t at = stale.find(good_table);
  ASSERT_NE(at, std::string::npos);
  stale.replace(at, good_table.size(), "| `cfl` | string |");
  write_scene("doc.md", stale);
  const Result check = run("keys --check doc.md");
  EXPECT_EQ(check.code, 1);
  EXPECT_NE(check.err.find("doc.md: the key tables differ from the registry; run 'sphrefine keys --sync doc.md'"),
            std::string::npos)
      << check.err;
  EXPECT_EQ(slurp(dir_ / "work" / "doc.md"), stale);
  EXPECT_EQ(run("keys --sync doc.md").code, 0);
  EXPECT_EQ(slurp(dir_ / "work" / "doc.md"), "# Scenes\n\nprose\n" + all);
  EXPECT_EQ(run("keys --check doc.md").code, 0);
  write_scene("unknown.md", "<!-- keys: tiem -->\n<!-- end keys -->\n");
  const Result unknown = run("keys --check unknown.md");
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("the marker names no scene object: 'tiem'"), std::string::npos) << unknown.err;
}

TEST_F(Cli, ValidateAGoodSceneWritesNothing) {
  write_scene("tiny.json", kTiny);
  const Result r = run("validate tiny.json");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("scene OK: tiny"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("fluid particles    200"), std::string::npos) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(\n  memory             about \d+ MiB \([\d,]+ particles at ~(\d+ B|[\d.]+ kB) each\) at the start, [\d.]+ GiB available\n)")))
      << r.out;
  EXPECT_EQ(work_files(), std::vector<std::string>{"tiny.json"});
}

TEST_F(Cli, EveryKindOfBadInputExitsTwoWithOneMessageAndCreatesNothing) {
  struct Case {
    std::string scene;    // the scene text
    std::string extra;    // extra arguments
    std::string message;  // the expected first line of stderr (prefix)
  };
  const Case cases[] = {
      {tiny_with("\"spacing\"", "\"spacng\""), "", "scene error: fluid[0].spacng: unknown key (did you mean 'spacing'?)"},
      {tiny_with("\"end\": 0.02", "\"end\": \"soon\""), "", "scene error: time.end: must be a number (got a string)"},
      {tiny_with("\"end\": 0.02, ", ""), "", "scene error: time.end: missing required key"},
      {tiny_with("\"spacing\": 0.1", "\"spacing\": 0"), "", "scene error: fluid[0].spacing: must be positive (got 0)"},
      {tiny_with("\"spacing\": 0.1", "\"spacing\": -0.1"), "", "scene error: fluid[0].spacing: must be positive (got -0.1)"},
      {tiny_with("\"rho0\": 1000", "\"rho0\": -1"), "", "scene error: material.rho0: must be positive (got -1)"},
      {tiny_with("\"end\": 0.02", "\"end\": -1"), "", "scene error: time.end: must be positive (got -1)"},
      {tiny_with("\"hi\": [1, 2]", "\"hi\": [5, 2]"), "", "scene error: fluid[0]: the rectangle reaches outside the container"},
      {tiny_with("\"hi\": [1, 2]", "\"hi\": [3.2, 2]"), "",
       "scene error: fluid[0]: overlaps obstacles[0] (fluid must start outside every obstacle)"},
      {tiny_with("\"hydrostatic\": true } ]",
                 "\"hydrostatic\": true }, { \"shape\": \"rectangle\", \"lo\": [0.5, 0], \"hi\": [1.5, 1], \"spacing\": 0.1 } ]"),
       "",
       "scene error: fluid[1]: overlaps fluid[0] (fluid[1]: rectangle [0.5, 0] .. [1.5, 1]; fluid[0]: rectangle [0, 0] .. [1, 2])"},
      {tiny_with("\"lennard_jones_wall\": { \"reference_height\": 2 }",
                 "\"lennard_jones_wall\": { \"reference_height\": 2, \"spacing\": 0.1 }"),
       "",
       "scene error: effects.lennard_jones_wall.spacing: the walls cannot resolve level 1"},
      {tiny_with("\"max_level\": 1", "\"max_level\": 12"), "",
       "scene error: effects.refinement.max_level: must be between 1 and 8 (got 12)"},
      {tiny_with("\"ghost_walls\": \"free-slip\"", "\"ghost_walls\": \"sticky\""), "",
       "scene error: effects.ghost_walls: must be one of: free-slip, no-slip (got 'sticky')"},
      {tiny_with("\"end\": 0.02,", "\"end\": 0.02, \"end\": 1,"), "", "scene error: time.end: duplicate key"},
      {tiny_with("\"name\": \"tiny\",", "\"name\": \"tiny\""), "", "scene error: scene.json: malformed JSON: "},
      {"", "", "scene error: scene.json: malformed JSON: "},
      {kTiny, "--set time.ned=1", "scene error: time.ned: unknown key (did you mean 'end'?)"},
      {kTiny, "--set time.end", "scene error: --set: expected key.path=value (got 'time.end')"},
      {kTiny, "--set fluid[3].spacing=1", "scene error: --set fluid[3].spacing: index 3 is out of range"},
  };
  for (const Case& c : cases) {
    write_scene("scene.json", c.scene);
    for (const char* command : {"run scene.json -o out -q", "validate scene.json"}) {
      const Result r = run(std::string(command) + " " + c.extra);
      SCOPED_TRACE(std::string(command) + " " + c.extra + " | " + c.message);
      EXPECT_EQ(r.code, 2);
      EXPECT_EQ(r.err.rfind(c.message, 0), 0u) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_EQ(work_files(), std::vector<std::string>{"scene.json"});
    }
  }
  const Result missing = run("run nowhere.json");
  EXPECT_EQ(missing.code, 2);
  EXPECT_EQ(missing.err, "scene error: nowhere.json: no such scene file\n");
}

TEST_F(Cli, CommandLineMistakesExitTwo) {
  write_scene("tiny.json", kTiny);
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("fly tiny.json").code, 2);
  EXPECT_EQ(run("run tiny.json --bogus").code, 2);
  EXPECT_EQ(run("run tiny.json --threads 0").code, 2);
  EXPECT_EQ(run("run").code, 2);
  EXPECT_EQ(run("run tiny.json --resume nowhere.h5").code, 2);
  EXPECT_EQ(work_files(), std::vector<std::string>{"tiny.json"});
  EXPECT_EQ(run("--help").code, 0);
}

TEST_F(Cli, BadThreadCountsAndCheckpointIntervalsAreNamedPlainly) {
  // Each value exits 2 with one plain rule naming the option (CLI11's range check printed the 300 digits of
  // the largest double; 100000 threads crashed and 20000 ran for minutes), and creates nothing.
  write_scene("tiny.json", kTiny);
  for (const char* value : {"0", "-3", "100000", "20000", "1.5", "abc", "99999999999999999999"}) {
    const Result r = run(std::string("run tiny.json -q -o out --threads ") + value);
    SCOPED_TRACE(value);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err.rfind("--threads: must be a whole number from 1 to ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(std::string("(got '") + value + "'; more than 4 per processor only slow a run)"), std::string::npos)
        << r.err;
    EXPECT_LT(r.err.size(), 200u) << r.err;
  }
  for (const char* value : {"0", "-1", "abc", "nan", "inf", "1s"}) {
    const Result r = run(std::string("run tiny.json -q -o out --checkpoint-every ") + value);
    SCOPED_TRACE(value);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err.rfind(std::string("--checkpoint-every: must be a positive number of simulated seconds (got '") + value + "')", 0), 0u)
        << r.err;
    EXPECT_LT(r.err.size(), 200u) << r.err;
  }
  EXPECT_EQ(work_files(), std::vector<std::string>{"tiny.json"});
  // The largest count is stated in the help, from the processors this machine has.
  const Result help = run("run --help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("--threads INT:1.."), std::string::npos) << help.out;
}

TEST_F(Cli, RunWritesItsFolderAndRefusesToOverwriteWithoutForce) {
  write_scene("tiny.json", kTiny);
  const Result first = run("run tiny.json --threads 1");
  ASSERT_EQ(first.code, 0) << first.err;
  for (const char* word : {"reached t = 0.02 s", "particle-steps/s", "fluid per level    L0 ", "mass drift         +0.000e+00",
                           "momentum change", "output             out/tiny"}) {
    EXPECT_NE(first.out.find(word), std::string::npos) << word << "\n" << first.out;
  }
  // Not a terminal: plain progress lines, never a carriage return.
  EXPECT_EQ(first.out.find('\r'), std::string::npos);
  EXPECT_NE(first.out.find("t = 0.02 / 0.02 s (100%)"), std::string::npos) << first.out;
  const fs::path out = dir_ / "work" / "out" / "tiny";
  for (const char* f : {"scene.json", "series.csv", "frames.xdmf", "run.json", "frames/frame_000000.h5"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  const auto before = fs::last_write_time(out / "series.csv");

  const Result second = run("run tiny.json -q");
  EXPECT_EQ(second.code, 3);
  EXPECT_NE(second.err.find("already holds a run; use --force"), std::string::npos) << second.err;
  EXPECT_EQ(fs::last_write_time(out / "series.csv"), before);

  std::ofstream(out / "notes.txt") << "mine";
  const Result forced = run("run tiny.json -q --force --set time.end=0.01");
  EXPECT_EQ(forced.code, 0) << forced.err;
  EXPECT_TRUE(fs::exists(out / "notes.txt")) << "--force removes only the run's own files";
  EXPECT_NE(slurp(out / "scene.json").find("\"end\": 0.01"), std::string::npos);
}

TEST_F(Cli, CheckpointAndResumeThroughTheProgram) {
  write_scene("tiny.json", kTiny);
  ASSERT_EQ(run("run tiny.json -q -o a --checkpoint-every 0.01").code, 0);
  ASSERT_TRUE(fs::exists(dir_ / "work" / "a" / "checkpoint.h5"));
  const Result resumed = run("run tiny.json -o a --resume a/checkpoint.h5 --set time.end=0.03");
  EXPECT_EQ(resumed.code, 0) << resumed.err;
  // The first run's last step was shortened to land on 0.02 s: its checkpoint is the state before that step.
  const std::smatch at = [&] {
    std::smatch m;
    std::regex_search(resumed.out, m, std::regex("resuming from a/checkpoint.h5 at t = ([0-9.e-]+) s"));
    return m;
  }();
  ASSERT_EQ(at.size(), 2u) << resumed.out;
  EXPECT_LE(std::stod(at[1].str()), 0.02);
  EXPECT_GT(std::stod(at[1].str()), 0.019);
  EXPECT_NE(resumed.out.find("reached t = 0.03 s"), std::string::npos) << resumed.out;
  // A checkpoint from a different scene is refused.
  const Result other = run("run tiny.json -o a --resume a/checkpoint.h5 --set h_factor=1.5");
  EXPECT_EQ(other.code, 2);
  EXPECT_EQ(other.err.rfind("scene error: --resume: the checkpoint was written by a different scene", 0), 0u) << other.err;
}

TEST_F(Cli, A3DSceneRunsAndResumesOnlyInto3D) {
  // The same program runs a 3D scene (the container's corners have three coordinates) and says so; a checkpoint
  // of one dimension does not resume a scene of the other.
  write_scene("tiny.json", kTiny);
  write_scene("tank3.json", R"({
    "container": { "lo": [0, 0, 0], "hi": [0.3, 0.2, 0.4] },
    "fluid": [ { "shape": "rectangle", "lo": [0, 0, 0], "hi": [0.3, 0.2, 0.2], "spacing": 0.05, "hydrostatic": true } ],
    "material": { "rho0": 1000, "mach_factor": 10, "reference_height": 0.2 },
    "effects": { "gravity": [0, 0, -9.81], "ghost_walls": "free-slip" },
    "time": { "end": 0.01 }
  })");
  const Result validated = run("validate tank3.json");
  EXPECT_EQ(validated.code, 0) << validated.err;
  EXPECT_NE(validated.out.find("scene OK: tank3 (3D)"), std::string::npos) << validated.out;
  const Result ran = run("run tank3.json -o t3 --checkpoint-every 0.005");
  ASSERT_EQ(ran.code, 0) << ran.err;
  EXPECT_NE(ran.out.find("tank3 (3D), 96 fluid particles"), std::string::npos) << ran.out;
  const Result crossed = run("run tiny.json -o t3 --resume t3/checkpoint.h5");
  EXPECT_EQ(crossed.code, 2);
  EXPECT_EQ(crossed.err, "error: --resume: t3/checkpoint.h5 holds a 3D run, but the scene is 2D\n");
}

TEST_F(Cli, ASceneTooBigForMemoryIsRefusedBeforeAnythingIsAllocated) {
  // 48 million lattice points (under the 5e7 cap), quadrupled by a static refinement pass, in a sheet six
  // refined rows thick on the floor of a 12 km tank: with h_factor 3 every particle has a ghost below the
  // floor. About 137 GiB at the start: more than any CI machine has (< 100 GiB). The program runs under a
  // 4 GB address-space limit, so that without the check it fails at once instead of taking the machine's memory.
  write_scene("huge.json", R"({
    "container": { "lo": [0, 0], "hi": [12000, 1] },
    "fluid": [ { "shape": "rectangle", "lo": [0, 0], "hi": [12000, 0.004], "spacing": 0.001 } ],
    "h_factor": 3,
    "material": { "rho0": 1000, "c0": 10 },
    "effects": { "ghost_walls": "free-slip", "static_refinement": {} },
    "time": { "end": 0.001 }
  })");
  // AddressSanitizer reserves terabytes of address space for its shadow memory, so under the sanitizer preset
  // the program cannot start within the limit; there the check alone keeps the run from allocating.
#if defined(__SANITIZE_ADDRESS__)
  const char* limit = "";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  const char* limit = "";
#else
  const char* limit = "ulimit -v 4000000 &&";
#endif
#else
  const char* limit = "ulimit -v 4000000 &&";
#endif
  for (const char* command : {"validate huge.json", "run huge.json -q -o out"}) {
    const Result r = run(command, "OMP_NUM_THREADS=1", limit);
    SCOPED_TRACE(command);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(std::regex_match(r.err, std::regex(R"(error: the scene needs about \d\d\d\.\d GiB \(3\d\d,\d\d\d,\d\d\d particles at ~\d\d\d B each\) but [\d.]+ [MG]iB are available\n)")))
        << r.err;
    EXPECT_EQ(work_files(), std::vector<std::string>{"huge.json"});
  }
}

TEST_F(Cli, ResumeFromAFileThatIsNotACheckpointExitsTwoAndWritesNothing) {
  write_scene("tiny.json", kTiny);
  ASSERT_EQ(run("run tiny.json -q -o a").code, 0);
  const fs::path a = dir_ / "work" / "a";
  const auto files_before = work_files();
  const auto series_before = fs::last_write_time(a / "series.csv");
  struct Case {
    std::string file, why;
  };
  for (const Case& c : {Case{"tiny.json", "not an HDF5 file"},
                        Case{"a/frames/frame_000000.h5", "an HDF5 file without the 'checkpoint' group"}}) {
    for (const char* out : {"a", "b"}) {
      const Result r = run("run tiny.json -q -o " + std::string(out) + " --resume " + c.file);
      SCOPED_TRACE(c.file + " -o " + out);
      EXPECT_EQ(r.code, 2);
      EXPECT_EQ(r.err, "error: --resume: " + c.file + " is not a sphrefine checkpoint (" + c.why + ")\n");
      EXPECT_EQ(work_files(), files_before);
      EXPECT_EQ(fs::last_write_time(a / "series.csv"), series_before);
    }
  }
  EXPECT_FALSE(fs::exists(dir_ / "work" / "b"));
}

TEST_F(Cli, ADirectoryIsNotASceneFile) {
  fs::create_directories(dir_ / "scenes");
  for (const char* command : {"run ../scenes -o out -q", "validate ../scenes"}) {
    const Result r = run(command);
    SCOPED_TRACE(command);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, "scene error: ../scenes: is a directory, not a scene file\n");
    EXPECT_TRUE(work_files().empty());
  }
}

TEST_F(Cli, AKilledRunLeavesEveryListedFrameReadable) {
  // Frames every millisecond of simulated time; the run is killed (SIGKILL) part-way.
  write_scene("tiny.json", tiny_with("\"end\": 0.02, \"output_interval\": 0.005",
                                     "\"end\": 5, \"output_interval\": 0.001"));
  const Result r = run("run tiny.json -q -o k & pid=$!; sleep 0.7; kill -9 $pid; wait $pid");
  EXPECT_EQ(r.code, 128 + 9) << "the run ended before it was killed";
  const fs::path out = dir_ / "work" / "k";
  const std::string xml = slurp(out / "frames.xdmf");
  const std::regex listed(R"re(frames/(frame_\d{6})\.h5:/\1/position)re");
  int frames = 0;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), listed); it != std::sregex_iterator(); ++it, ++frames) {
    const fs::path file = out / "frames" / ((*it)[1].str() + ".h5");
    const io::FrameHeader h = io::read_frame_header(file, (*it)[1].str());
    EXPECT_EQ(io::read_frame_field(file, h.group, "position").size(), 2 * h.particles);
  }
  EXPECT_GT(frames, 2);
  // Every frame file under its final name is complete (a frame being written is only ever a .tmp).
  for (const auto& e : fs::directory_iterator(out / "frames")) {
    if (e.path().extension() != ".h5") continue;
    EXPECT_NO_THROW((void)io::read_frame_header(e.path(), e.path().stem().string())) << e.path();
  }
  // The time series holds only whole lines.
  const std::string csv = slurp(out / "series.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
  EXPECT_FALSE(fs::exists(out / "run.json")) << "killed runs have no summary";
}

}  // namespace
