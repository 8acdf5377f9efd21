// The watchdog, provoked on purpose: a NaN, a density error past the limit, a particle leaving the domain.
// For each: step() throws SimulationFailure whose report names the step, time, particle id and position,
// the quantity and a likely cause, and the simulation is back at the state before the failing step (every
// field of every particle compared bitwise by id, and the clock). And the command line: a scene that fails
// exits non-zero with one clear message.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/case_builder.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "core/io/hdf5_frames.hpp"
#include "core/io/output_folder.hpp"
#include "core/setup.hpp"
#include "core/simulation.hpp"
#include "core/watchdog.hpp"

namespace {

using namespace sph;

/// The state of the simulation: every field of every non-ghost particle by id, as bytes.
struct Snapshot {
  std::map<ParticleId, std::map<std::string, std::vector<unsigned char>>> particles;
  double time = 0.0, dt = 0.0;
  std::uint64_t step = 0;
};

Snapshot snapshot(const Simulation& sim) {
  Snapshot s;
  const auto& st = sim.store();
  for (std::size_t i = 0; i < st.size(); ++i) {
    if (st.kind[i] == Kind::ghost) continue;
    auto& fields = s.particles[st.id[i]];
    st.for_each_field([&](const auto& f) {
      const auto* p = reinterpret_cast<const unsigned char*>(&f[i]);
      fields[std::string(f.name())] = std::vector<unsigned char>(p, p + sizeof(f[i]));
    });
  }
  s.time = sim.time();
  s.dt = sim.dt();
  s.step = sim.step_count();
  return s;
}

/// Compares two snapshots; returns the differing fields with a count of particles each ("" when equal).
std::string differences(const Snapshot& a, const Snapshot& b) {
  std::ostringstream out;
  if (a.particles.size() != b.particles.size()) out << "particle count " << a.particles.size() << " vs " << b.particles.size() << "; ";
  std::map<std::string, std::size_t> per_field;
  for (const auto& [id, fields] : a.particles) {
    const auto it = b.particles.find(id);
    if (it == b.particles.end()) {
      ++per_field["<missing id>"];
      continue;
    }
    for (const auto& [name, bytes] : fields) {
      if (it->second.at(name) != bytes) ++per_field[name];
    }
  }
  for (const auto& [name, n] : per_field) out << name << ": " << n << " particles; ";
  if (std::memcmp(&a.time, &b.time, sizeof(double)) != 0) out << "time; ";
  if (a.step != b.step) out << "step; ";
  if (std::memcmp(&a.dt, &b.dt, sizeof(double)) != 0) out << "dt " << a.dt << " vs " << b.dt << "; ";
  return out.str();
}

/// Steps until the watchdog fires (at most max_steps); checks the report and the rollback.
FailureReport expect_failure(Simulation& sim, FailureKind kind, int max_steps) {
  for (int k = 0; k < max_steps; ++k) {
    const Snapshot before = snapshot(sim);
    try {
      sim.step();
      sim.run_stages();
    } catch (const SimulationFailure& e) {
      const FailureReport& r = e.report();
      EXPECT_EQ(static_cast<int>(r.kind), static_cast<int>(kind)) << e.what();
      EXPECT_EQ(r.step, before.step + 1) << "the report names the failing step";
      EXPECT_GT(r.time, before.time) << "the report names the time the failing step reached";
      EXPECT_LE(r.time, before.time + before.dt * (1.0 + 1e-12));
      EXPECT_TRUE(before.particles.count(r.id)) << "the report names a real particle id";
      EXPECT_FALSE(r.quantity.empty());
      EXPECT_FALSE(r.cause.empty());
      const std::string msg = e.what();
      EXPECT_NE(msg.find("step " + std::to_string(r.step)), std::string::npos) << msg;
      EXPECT_NE(msg.find("particle " + std::to_string(r.id)), std::string::npos) << msg;
      EXPECT_NE(msg.find("t = "), std::string::npos) << msg;
      EXPECT_NE(msg.find(" at ("), std::string::npos) << msg;
      EXPECT_NE(msg.find("Likely cause"), std::string::npos) << msg;
      // Back at the last good state: every field of every particle, and the clock.
      const Snapshot after = snapshot(sim);
      EXPECT_EQ(differences(before, after), "") << "the state after the rollback differs from the state before "
                                                   "the failing step";
      return r;
    }
  }
  ADD_FAILURE() << "the watchdog did not fire within " << max_steps << " steps";
  return {};
}

std::size_t index_of(const ParticleStore<2>& s, ParticleId id) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::ghost && s.id[i] == id) return i;
  }
  return s.size();
}

TEST(Watchdog, NaNIsCaughtAndTheStepUndone) {
  TankSpec spec;
  spec.lennard_jones = true;
  Simulation sim = make_still_tank(spec);
  for (int k = 0; k < 5; ++k) sim.step();
  // A NaN density rate on one fluid particle between steps: the next step's density turns NaN while its
  // position stays finite (so the report can name where it is).
  auto& st = sim.store();
  std::size_t i = 0;
  while (st.kind[i] != Kind::fluid) ++i;
  const ParticleId id = st.id[i];
  const Vec<2> x = st.x[i];
  st.drho[i] = std::numeric_limits<double>::quiet_NaN();
  const FailureReport r = expect_failure(sim, FailureKind::not_finite, 1);
  EXPECT_EQ(r.id, id);
  EXPECT_TRUE(std::isfinite(r.position[0]) && std::isfinite(r.position[1]));
  EXPECT_LT((r.position - x).norm(), 0.1) << "the report gives the particle's position";
  EXPECT_NE(r.quantity.find("NaN"), std::string::npos) << r.quantity;
  EXPECT_EQ(sim.step_count(), 5u);
}

/// A 40 m box with no gravity and no walls of any kind, c0 = 2 m/s and the density limit at 0.5: blocks of fluid
/// moving at a few m/s leave the weakly-compressible range within a few steps.
SolverSettings mach_five_box() {
  SolverSettings s;
  s.eos.c0 = 2.0;
  s.gravity.reset();
  s.ghosts.reset();
  s.geometry.container = {Vec<2>(0, 0), Vec<2>(40, 40)};
  s.watchdog.max_density_error = 0.5;
  return s;
}

TEST(Watchdog, DensityErrorPastTheLimitIsCaughtAfterGoodSteps) {
  // Two blocks colliding head-on at 2 x 5 m/s with c0 = 2 m/s (Mach 5): the fluid compresses step by step
  // until |rho/rho0 - 1| passes the limit; the steps before are good.
  const SolverSettings s = mach_five_box();
  Simulation sim(s);
  FluidBlockSpec block;
  block.spacing = 0.5;
  block.velocity = Vec<2>(5, 0);
  add_fluid(sim.store(), lattice_rectangle(Vec<2>(10, 15), Vec<2>(15, 20), 0.5), block, s.eos.rho0);
  block.velocity = Vec<2>(-5, 0);
  add_fluid(sim.store(), lattice_rectangle(Vec<2>(15.5, 15), Vec<2>(20.5, 20), 0.5), block, s.eos.rho0);
  sim.refresh();
  const FailureReport r = expect_failure(sim, FailureKind::density, 5000);
  EXPECT_GT(sim.step_count(), 2u) << "the failure should come after good steps";
  EXPECT_NE(r.quantity.find("density error"), std::string::npos) << r.quantity;
  EXPECT_NE(r.cause.find("sound speed"), std::string::npos) << r.cause;
  const std::size_t i = index_of(sim.store(), r.id);
  ASSERT_LT(i, sim.store().size());
  EXPECT_LE(std::abs(sim.store().rho[i] / s.eos.rho0 - 1.0), 0.5) << "the restored particle is within the limit";
}

TEST(Watchdog, ADensityDeficitIsReportedAsExpansion) {
  // A block whose velocity diverges from its centre at 4 /s with c0 = 2 m/s: the continuity equation drains
  // its density by rho div v = 8 rho per second, far faster than the tension of a 2 m/s sound speed can stop,
  // so |rho/rho0 - 1| passes the limit from below. The report must name an expansion, not a compression.
  const SolverSettings s = mach_five_box();
  Simulation sim(s);
  FluidBlockSpec block;
  block.spacing = 0.5;
  add_fluid(sim.store(), lattice_rectangle(Vec<2>(15, 15), Vec<2>(25, 25), 0.5), block, s.eos.rho0);
  const Vec<2> centre(20, 20);
  for (std::size_t i = 0; i < sim.store().size(); ++i) sim.store().v[i] = 4.0 * (sim.store().x[i] - centre);
  sim.refresh();
  const FailureReport r = expect_failure(sim, FailureKind::density, 5000);
  const std::size_t i = index_of(sim.store(), r.id);
  ASSERT_LT(i, sim.store().size());
  EXPECT_NE(r.quantity.find("density error"), std::string::npos) << r.quantity;
  EXPECT_NE(r.cause.find("expansion"), std::string::npos) << r.cause;
  EXPECT_EQ(r.cause.find("compression"), std::string::npos) << r.cause;
}

/// A block of fluid (spacing 0.5) moving at `velocity` in a 10 m x 10 m container with no walls of any kind
/// (no ghosts, no wall particles) and no gravity.
Simulation block_in_open_box(const Vec<2>& lo, const Vec<2>& hi, const Vec<2>& velocity, double c0) {
  SolverSettings s;
  s.gravity.reset();
  s.ghosts.reset();
  s.eos.c0 = c0;
  s.geometry.container = {Vec<2>(0, 0), Vec<2>(10, 10)};
  Simulation sim(s);
  FluidBlockSpec block;
  block.spacing = 0.5;
  block.velocity = velocity;
  add_fluid(sim.store(), lattice_rectangle(lo, hi, 0.5), block, s.eos.rho0);
  sim.refresh();
  return sim;
}

TEST(Watchdog, ParticleLeavingTheDomainIsCaught) {
  // No ghost walls and no wall particles: a block moving at 20 m/s towards the right wall goes through it.
  Simulation sim = block_in_open_box(Vec<2>(6, 2), Vec<2>(9, 5), Vec<2>(20, 0), 200.0);
  const Geometry2& geometry = sim.settings().geometry;
  const FailureReport r = expect_failure(sim, FailureKind::left_domain, 100000);
  EXPECT_GT(sim.step_count(), 2u);
  EXPECT_GT(r.position[0], 10.0) << "the report gives the position outside the container";
  EXPECT_NE(r.quantity.find("left the domain"), std::string::npos) << r.quantity;
  EXPECT_NE(r.quantity.find("through a wall"), std::string::npos) << r.quantity;
  EXPECT_EQ(r.quantity.find("open top"), std::string::npos) << r.quantity;
  EXPECT_NE(r.cause.find("wall penetration"), std::string::npos) << r.cause;
  EXPECT_EQ(std::string(to_string(r.kind)), "left_domain");
  // Restored: every fluid particle is back inside.
  for (std::size_t i = 0; i < sim.store().size(); ++i) {
    if (sim.store().kind[i] == Kind::fluid) {
      EXPECT_TRUE(geometry.in_fluid_domain(sim.store().x[i]));
    }
  }
}

TEST(Watchdog, ParticleFlyingOverTheOpenTopIsNotCalledWallPenetration) {
  // The same open box (rim at y = 10 m), a block thrown up and to the right at (8, 20) m/s from just below the
  // rim: it is above the rim (still in the domain) before it is beyond the right side, so it leaves over the
  // top of the right wall, as the drop at 30 m/s splashes over its container's rim.
  Simulation sim = block_in_open_box(Vec<2>(6, 8), Vec<2>(9, 9.5), Vec<2>(8, 20), 200.0);
  const FailureReport r = expect_failure(sim, FailureKind::left_open_top, 100000);
  EXPECT_GT(r.position[0], 10.0);
  EXPECT_GT(r.position[1], 10.0) << "beside the container, above its rim";
  EXPECT_NE(r.quantity.find("through the open top"), std::string::npos) << r.quantity;
  EXPECT_NE(r.quantity.find("y = 10 m"), std::string::npos) << "names the rim: " << r.quantity;
  EXPECT_EQ(r.cause.find("wall penetration"), std::string::npos) << r.cause;
  EXPECT_NE(r.cause.find("splash over the rim"), std::string::npos) << r.cause;
  EXPECT_NE(r.cause.find("container.outflow"), std::string::npos) << "names the way out: " << r.cause;
  EXPECT_EQ(std::string(to_string(r.kind)), "left_open_top");
}

TEST(Watchdog, OpenTopAndWallAreToldApartByWhereThePathCrossedTheSide) {
  Geometry2 g;
  g.container = {Vec<2>(0, 0), Vec<2>(10, 10)};
  g.obstacles.push_back({Vec<2>(4, 2), Vec<2>(6, 4)});
  g.open_top = true;
  const Vec<2> right(1, 0), down_right(1, -2);
  EXPECT_TRUE(g.left_through_open_top(Vec<2>(10.01, 10.5), right)) << "beside the container above the rim";
  EXPECT_TRUE(g.left_through_open_top(Vec<2>(-0.01, 12.0), -right)) << "the left side too";
  // Over the rim and down within one step: 0.01 m beyond the side, 0.01 m below the rim, falling at twice its
  // sideways speed, so it crossed the side line at y = 10.01, above the rim.
  EXPECT_TRUE(g.left_through_open_top(Vec<2>(10.01, 9.99), down_right));
  // The same point reached flatter crossed the wall itself (at y = 9.995).
  EXPECT_FALSE(g.left_through_open_top(Vec<2>(10.01, 9.99), Vec<2>(1, -0.5)));
  EXPECT_FALSE(g.left_through_open_top(Vec<2>(10.01, 9.0), right)) << "through the right wall";
  EXPECT_FALSE(g.left_through_open_top(Vec<2>(10.01, 9.99), Vec<2>(-1, -2))) << "moving in: it did not cross now";
  EXPECT_FALSE(g.left_through_open_top(Vec<2>(5, -0.1), Vec<2>(0, -1))) << "through the floor";
  EXPECT_FALSE(g.left_through_open_top(Vec<2>(5, 3), Vec<2>(0, -1))) << "into an obstacle";
  g.open_top = false;
  EXPECT_FALSE(g.left_through_open_top(Vec<2>(10.01, 10.5), right)) << "a closed top has no rim to pass";
}

TEST(Watchdog, ANonFinitePositionFromTheDriftIsAFailureNotAGridError) {
  // Found by the scene fuzzer: gravity pointing up (+9.81) on a column with c0 = 2 m/s turns every position
  // NaN within the first step, before the sweep. The grid refuses non-finite positions; the step must report
  // that as the watchdog's failure (naming the particle, undone), not let the grid's error escape.
  const std::string text = R"({
    "name": "nan_in_one_step",
    "container": { "lo": [0, 0], "hi": [50, 80], "open_top": true },
    "fluid": [ { "shape": "rectangle", "lo": [0, 0], "hi": [25, 25], "spacing": 0.8333333333333334 } ],
    "h_factor": 1.2,
    "material": { "rho0": 1000, "c0": 2 },
    "effects": {
      "gravity": [0, 9.81],
      "artificial_viscosity": { "alpha": 0.02, "beta": 0 },
      "lennard_jones_wall": { "reference_height": 25, "r0_factor": 0.5 },
      "ghost_walls": "free-slip"
    },
    "time": { "end": 4.0, "cfl": 0.2 }
  })";
  Simulation sim = scene::build_simulation(scene::scene_from_json(scene::parse_json_text(text, "nan.json")));
  const FailureReport r = expect_failure(sim, FailureKind::not_finite, 5);
  EXPECT_EQ(r.step, 1u);
}

TEST(Watchdog, RollbackLeavesARunnableSimulation) {
  // After a failure, lowering the step cap lets the run go on from the restored state.
  Simulation sim = block_in_open_box(Vec<2>(4, 4), Vec<2>(6, 6), Vec<2>(1, 0), SolverSettings{}.eos.c0);
  auto& st = sim.store();
  std::size_t i = 0;
  while (st.kind[i] != Kind::fluid) ++i;
  const ParticleId id = st.id[i];
  st.x[i] = Vec<2>(9.999, 5.0);  // teleported next to the wall, moving out
  st.v[i] = Vec<2>(1000.0, 0.0);
  EXPECT_THROW(sim.step(), SimulationFailure);
  // Put it back inside, slow: the run continues.
  i = index_of(sim.store(), id);
  ASSERT_LT(i, sim.store().size());
  sim.store().x[i] = Vec<2>(5.0, 5.0);
  sim.store().v[i] = Vec<2>(1.0, 0.0);
  sim.refresh();
  EXPECT_NO_THROW(sim.step());
  EXPECT_EQ(sim.step_count(), 1u);
}

// --- The command line ---------------------------------------------------------------------------------

std::filesystem::path sphrefine_exe() { return SPHREFINE_EXE; }

std::filesystem::path failing_scene() {
  return std::filesystem::path(__FILE__).parent_path().parent_path() / "cases" / "stress" / "failing_tiny_c0.json";
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct CliRun {
  int exit_code = -1;
  std::string out, err;
  std::filesystem::path folder;
};

CliRun run_failing_scene(const std::string& tag) {
  CliRun r;
  const auto exe = sphrefine_exe();
  const auto dir = std::filesystem::temp_directory_path() / ("sph_watchdog_" + tag + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto scene = failing_scene();
  r.folder = dir / "run";
  const std::string cmd = "'" + exe.string() + "' run '" + scene.string() + "' -o '" + r.folder.string() +
                          "' --threads 2 -q > '" + (dir / "out.txt").string() + "' 2> '" + (dir / "err.txt").string() + "'";
  const int status = std::system(cmd.c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(dir / "out.txt");
  r.err = read_text(dir / "err.txt");
  return r;
}

TEST(WatchdogCli, FailingSceneExitsNonZeroWithOneClearMessage) {
  ASSERT_TRUE(std::filesystem::exists(sphrefine_exe())) << sphrefine_exe();
  const CliRun r = run_failing_scene("msg");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.exit_code, 1) << "kExitFailure";
  // One line on stderr naming the step, time, particle, quantity and cause.
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  for (const char* part : {"step ", "t = ", "particle ", " at (", "density error", "Likely cause", "c0"}) {
    EXPECT_NE(r.err.find(part), std::string::npos) << "missing '" << part << "' in: " << r.err;
  }
  std::filesystem::remove_all(r.folder.parent_path());
}

// On a failure the run leaves the last good state behind: a frame of the state before the failing step, a
// checkpoint of it (so it can be inspected and resumed with a smaller time.cfl), and run.json saying the run
// failed, with the report; the message names where they are.
TEST(WatchdogCli, FailingSceneWritesTheLastGoodFrameACheckpointAndTheReport) {
  ASSERT_TRUE(std::filesystem::exists(sphrefine_exe())) << sphrefine_exe();
  const CliRun r = run_failing_scene("files");
  ASSERT_NE(r.exit_code, 0);
  // The failing step, from the message "run stopped at step N".
  const auto at = r.err.find("run stopped at step ");
  ASSERT_NE(at, std::string::npos) << r.err;
  const std::uint64_t failed_step = std::stoull(r.err.substr(at + std::strlen("run stopped at step ")));
  const io::RunFiles files{r.folder};
  ASSERT_TRUE(std::filesystem::exists(files.checkpoint())) << "no checkpoint of the last good state";
  ParticleStore<2> store;
  const io::CheckpointState cp = io::read_checkpoint(files.checkpoint(), store);
  EXPECT_EQ(cp.step + 1, failed_step) << "the checkpoint holds the state before the failing step";
  // The last frame written is that state too.
  std::uint64_t last = 0;
  bool any = false;
  for (std::uint64_t f = 0; std::filesystem::exists(files.frame(f)); ++f) {
    last = f;
    any = true;
  }
  ASSERT_TRUE(any);
  const io::FrameHeader h = io::read_frame_header(files.frame(last), io::RunFiles::frame_group(last));
  EXPECT_EQ(h.step + 1, failed_step) << "the last frame holds the state before the failing step";
  EXPECT_EQ(h.time, cp.time);
  // The message says where the last good state is.
  EXPECT_NE(r.err.find(files.checkpoint().string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(files.frame(last).filename().string()), std::string::npos) << r.err;
  // run.json: failed, with the report and the last good step.
  const auto summary = nlohmann::json::parse(read_text(files.summary()));
  EXPECT_EQ(summary.at("status"), "failed");
  EXPECT_EQ(summary.at("failure").at("kind"), "density");
  EXPECT_EQ(summary.at("failure").at("step").get<std::uint64_t>(), failed_step);
  EXPECT_EQ(summary.at("failure").at("last_good_step").get<std::uint64_t>(), cp.step);
  EXPECT_EQ(summary.at("step").get<std::uint64_t>(), cp.step);
  // The series ends at the last good state too.
  const std::string series = read_text(files.series());
  ASSERT_FALSE(series.empty());
  const auto last_line = series.substr(series.rfind('\n', series.size() - 2) + 1);
  EXPECT_EQ(std::stoull(last_line.substr(last_line.find(',') + 1)), cp.step) << last_line;

  // The way on: resume from that checkpoint with a quarter of the CFL number. The first step already follows
  // the new number, so the resumed run gets past the failing step (this scene's c0 is hopeless, so it still
  // fails later, at a later time).
  const std::string resume = "'" + sphrefine_exe().string() + "' run '" + failing_scene().string() + "' -o '" +
                             r.folder.string() + "' --resume '" + files.checkpoint().string() +
                             "' --set time.cfl=0.05 -q 2> '" + (r.folder.parent_path() / "err2.txt").string() + "'";
  const int status = std::system(resume.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string err2 = read_text(r.folder.parent_path() / "err2.txt");
  const auto at2 = err2.find("run stopped at step ");
  ASSERT_NE(at2, std::string::npos) << err2;
  EXPECT_GT(std::stoull(err2.substr(at2 + std::strlen("run stopped at step "))), failed_step) << err2;
  std::filesystem::remove_all(r.folder.parent_path());
}

}  // namespace
