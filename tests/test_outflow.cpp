// Outflow through an open top (container.outflow): fluid thrown over the rim is removed inside the step when
// the scene asks for it (and only that fluid: not what went through a wall, not ghosts or wall particles), the
// removed count and mass are reported in series.csv and run.json and close the mass balance
// (M + removed mass = M0), the result is bitwise identical at 1 and 2 threads and on --resume, and with the
// default ("stop") the same scene is stopped by the watchdog with the open-top message.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <nlohmann/json.hpp>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "core/boundary/outflow.hpp"
#include "core/setup.hpp"
#include "core/simulation.hpp"
#include "core/io/atomic_file.hpp"
#include "core/io/output_folder.hpp"
#include "core/scene/runner.hpp"
#include "core/scene/scene_parser.hpp"

#include "tests/support/io_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using namespace sph;
using test::TempFolder;
using test::expect_bitwise_equal;
namespace fs = std::filesystem;

// ---- remove_outflow on a hand-made store ----------------------------------------------------------------------

struct Made {
  Vec<2> x, vh;
  Kind kind;
  double m;
};

ParticleStore<2> store_of(const std::vector<Made>& particles) {
  ParticleStore<2> s;
  for (const Made& p : particles) {
    const std::size_t i = s.append(1);
    s.x[i] = p.x;
    s.vh[i] = p.vh;
    s.v[i] = p.vh;
    s.kind[i] = p.kind;
    s.m[i] = p.m;
    s.rho[i] = 1000.0;
  }
  return s;
}

TEST(Outflow, RemovesOnlyFluidThatLeftOverTheRimKeepingTheRestInOrder) {
  Geometry2 g;
  g.container = {Vec<2>(0, 0), Vec<2>(10, 10)};
  g.obstacles.push_back({Vec<2>(4, 2), Vec<2>(6, 4)});
  g.open_top = true;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Made> made{
      {Vec<2>(5, 5), Vec<2>(0, 0), Kind::fluid, 1.0},             // 0 inside: stays
      {Vec<2>(10.5, 10.5), Vec<2>(1, 1), Kind::fluid, 2.0},       // 1 beside the container above the rim: removed
      {Vec<2>(10.5, 5), Vec<2>(1, 0), Kind::fluid, 4.0},          // 2 through the right wall: stays (watchdog)
      {Vec<2>(10.5, 10.5), Vec<2>(1, 1), Kind::ghost, 8.0},       // 3 a ghost there: stays
      {Vec<2>(10.2, 10.2), Vec<2>(0, 0), Kind::wall, 16.0},       // 4 a wall particle: stays
      {Vec<2>(10.01, 9.99), Vec<2>(1, -2), Kind::fluid, 32.0},    // 5 over the rim, then down: removed
      {Vec<2>(5, 3), Vec<2>(0, -1), Kind::fluid, 64.0},           // 6 inside the obstacle: stays (watchdog)
      {Vec<2>(nan, 12), Vec<2>(1, 1), Kind::fluid, 128.0},        // 7 NaN: stays (watchdog)
      {Vec<2>(5, 15), Vec<2>(0, 5), Kind::fluid, 256.0},          // 8 above the opening, within the span: stays
      {Vec<2>(-0.5, 11), Vec<2>(-1, 0), Kind::fluid, 512.0},      // 9 over the left rim: removed
  };
  ParticleStore<2> s = store_of(made);
  s.take_ids(5);
  const ParticleId next = s.next_id();
  const RemovedFluid r = remove_outflow(s, g);
  EXPECT_EQ(r.particles, 3u);
  EXPECT_EQ(r.mass.value(), 2.0 + 32.0 + 512.0);
  std::vector<ParticleId> ids(s.id.values().begin(), s.id.values().end());
  EXPECT_EQ(ids, (std::vector<ParticleId>{0, 2, 3, 4, 6, 7, 8})) << "the others kept, in order";
  EXPECT_EQ(s.m[1], 4.0) << "every field moved with its particle";
  EXPECT_EQ(s.next_id(), next) << "ids are never reused";

  // A closed top has no opening: nothing is removed.
  ParticleStore<2> closed = store_of(made);
  g.open_top = false;
  EXPECT_EQ(remove_outflow(closed, g).particles, 0u);
  EXPECT_EQ(closed.size(), made.size());
}

TEST(Outflow, AStepTheWatchdogUndoesGivesItsRemovalsBack) {
  // A 10 m x 10 m open box with no walls of any kind and no gravity, a block at rest in the middle; particles
  // teleported between steps next to the right side, moving out at 1000 m/s (about 1 m in one step).
  SolverSettings settings;
  settings.gravity.reset();
  settings.ghosts.reset();
  settings.geometry.container = {Vec<2>(0, 0), Vec<2>(10, 10)};
  settings.geometry.outflow = Outflow::remove;
  Simulation sim(settings);
  FluidBlockSpec block;
  block.spacing = 0.5;
  add_fluid(sim.store(), lattice_rectangle(Vec<2>(4, 4), Vec<2>(6, 6), 0.5), block, settings.eos.rho0);
  sim.refresh();
  const std::size_t n = sim.store().size();
  auto throw_out = [&](ParticleId id, const Vec<2>& x) {
    auto& st = sim.store();
    for (std::size_t i = 0; i < st.size(); ++i) {
      if (st.id[i] != id) continue;
      st.x[i] = x;
      st.v[i] = Vec<2>(1000.0, 0.0);
    }
  };
  // Above the rim (still in the domain, within the span): the step takes it beside the container and removes it.
  throw_out(0, Vec<2>(9.99, 10.5));
  ASSERT_NO_THROW(sim.step());
  EXPECT_EQ(sim.removed().particles, 1u);
  EXPECT_EQ(sim.store().size(), n - 1);
  const double removed_mass = sim.removed().mass.value();
  EXPECT_EQ(removed_mass, block.spacing * block.spacing * settings.eos.rho0);
  // One more over the top and one through the right wall in the same step: the watchdog undoes the step, and
  // with it the removal it made.
  throw_out(1, Vec<2>(9.99, 10.5));
  throw_out(2, Vec<2>(9.999, 5.0));
  try {
    sim.step();
    FAIL() << "the particle through the wall was not caught";
  } catch (const SimulationFailure& e) {
    EXPECT_EQ(e.report().kind, FailureKind::left_domain) << e.what();
    EXPECT_EQ(e.report().id, 2u);
  }
  EXPECT_EQ(sim.removed().particles, 1u) << "the undone step's removal is given back";
  EXPECT_EQ(sim.removed().mass.value(), removed_mass);
  EXPECT_EQ(sim.store().size(), n - 1);
  EXPECT_EQ(sim.step_count(), 1u);
}

// ---- a scene that throws fluid over the rim -------------------------------------------------------------------

/// The pool's rows of particles: 36 (0.45 m, 4320 particles: more than one chunk of the parallel primitives,
/// par::kChunk = 4096). Under the sanitizers 12 rows (0.15 m, 1440 particles), a third of the work: what these
/// tests check happens to the thrown block, which is the same; the runs over more than one chunk are checked
/// there by Determinism.MultiChunkDamBreak, and here by the release suite.
std::size_t pool_rows() { return sph::test::short_runs() ? 12 : 36; }
const std::size_t kPool = 120 * pool_rows();  // the pool's particles (ids 0 .. kPool - 1)
constexpr std::size_t kThrown = 16 * 15;      // the thrown block's (ids kPool .. kPool + kThrown - 1)

/// A pool at rest and a block thrown up and to the right at (2.5, 10) m/s from below the rim: it is above the
/// rim (y = 1 m) before it reaches the right side, so it leaves over the top. t = 0.13 s: the last of it has
/// left by t = 0.12 s.
scene::Scene thrown_scene(const char* outflow) {
  std::string text = R"({
    "name": "thrown_over_the_rim",
    "container": { "lo": [0, 0], "hi": [1.5, 1.0], "open_top": true },
    "fluid": [
      { "shape": "rectangle", "lo": [0, 0], "hi": [1.5, 0.45], "spacing": 0.0125, "hydrostatic": true },
      { "shape": "rectangle", "lo": [1.2, 0.8], "hi": [1.4, 0.99], "spacing": 0.0125, "velocity": [2.5, 10] }
    ],
    "material": { "rho0": 1000, "c0": 20 },
    "effects": {
      "gravity": [0, -9.81],
      "artificial_viscosity": { "alpha": 0.02 },
      "lennard_jones_wall": { "reference_height": 0.45 },
      "ghost_walls": "free-slip"
    },
    "time": { "end": 0.13, "output_interval": 0.01 },
    "output": { "frame_interval": 0.05 }
  })";
  const std::string deep = R"("hi": [1.5, 0.45], "spacing")";
  text.replace(text.find(deep), deep.size(),
               R"("hi": [1.5, )" + std::to_string(0.0125 * static_cast<double>(pool_rows())) + R"(], "spacing")");
  scene::Scene s = scene::scene_from_json(scene::parse_json_text(text, "thrown"));
  s.container.outflow = std::string(outflow) == "remove" ? Outflow::remove : Outflow::stop;
  return s;
}

std::vector<std::string> lines(const fs::path& file) {
  std::istringstream in(io::read_file(file));
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// series.csv as columns by name.
std::map<std::string, std::vector<double>> series(const fs::path& file) {
  const auto rows = lines(file);
  std::vector<std::string> names;
  std::map<std::string, std::vector<double>> out;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    std::istringstream row(rows[r]);
    std::size_t k = 0;
    for (std::string cell; std::getline(row, cell, ','); ++k) {
      if (r == 0) {
        names.push_back(cell);
      } else {
        out[names.at(k)].push_back(std::stod(cell));
      }
    }
  }
  return out;
}

// M (an exact sum over the particles left, rounded once), the removed mass (the same over those removed) and M0
// are each the exact sum of their masses correctly rounded, so M + removed differs from M0 by the three roundings
// and that of the addition: at most 2 ulp of M0.
constexpr double kMassBalance = 2.0 * std::numeric_limits<double>::epsilon();

TEST(Outflow, FluidThrownOverTheRimIsRemovedAndEveryKilogramAccountedFor) {
  TempFolder tmp;
  omp_set_num_threads(1);
  const fs::path out = tmp.path() / "run";
  scene::Runner runner(thrown_scene("remove"), scene::RunOptions{out, std::nullopt, std::nullopt});
  const scene::RunSummary r = runner.run();  // completes: the watchdog does not stop it
  EXPECT_DOUBLE_EQ(runner.simulation().time(), 0.13);

  // Exactly the thrown block left, the pool stayed, and every fluid particle left is in the domain.
  const auto& st = runner.simulation().store();
  const Geometry2& g = runner.simulation().settings().geometry;
  std::vector<ParticleId> fluid_ids;
  for (std::size_t i = 0; i < st.size(); ++i) {
    if (st.kind[i] != Kind::fluid) continue;
    fluid_ids.push_back(st.id[i]);
    EXPECT_TRUE(g.in_fluid_domain(st.x[i])) << "particle " << st.id[i];
  }
  std::sort(fluid_ids.begin(), fluid_ids.end());
  std::vector<ParticleId> pool(kPool);
  std::iota(pool.begin(), pool.end(), ParticleId{0});
  EXPECT_EQ(fluid_ids, pool);
  EXPECT_EQ(r.final.removed, kThrown);
  const double m = 1000.0 * 0.0125 * 0.0125;  // rho0 d^2, every particle
  EXPECT_NEAR(r.final.removed_mass, static_cast<double>(kThrown) * m, kMassBalance * r.initial_mass);

  // The balance closes: M + removed = M0, and run.json's drift counts the removed mass.
  EXPECT_NEAR(r.final.mass + r.final.removed_mass, r.initial_mass, kMassBalance * r.initial_mass);
  EXPECT_LE(std::abs(r.mass_drift), kMassBalance);
  const auto summary = nlohmann::json::parse(io::read_file(io::RunFiles{out}.summary()));
  EXPECT_EQ(summary.at("status"), "completed");
  EXPECT_EQ(summary.at("removed_particles").get<std::uint64_t>(), kThrown);
  EXPECT_EQ(summary.at("removed_mass").get<double>(), r.final.removed_mass);
  EXPECT_EQ(summary.at("mass_drift").get<double>(), r.mass_drift);

  // series.csv: removed and removed_mass per row, growing from 0 to the total, closing the balance on every row.
  auto cols = series(io::RunFiles{out}.series());
  ASSERT_TRUE(cols.count("removed") && cols.count("removed_mass"));
  const auto& mass = cols["mass"];
  const auto& removed = cols["removed"];
  const auto& removed_mass = cols["removed_mass"];
  ASSERT_GE(mass.size(), 14u);
  EXPECT_EQ(removed.front(), 0.0);
  EXPECT_EQ(removed.back(), static_cast<double>(kThrown));
  EXPECT_EQ(removed_mass.back(), r.final.removed_mass);
  for (std::size_t k = 0; k < mass.size(); ++k) {
    if (k > 0) {
      EXPECT_GE(removed[k], removed[k - 1]);
    }
    EXPECT_EQ(cols["fluid"][k] + removed[k], static_cast<double>(kPool + kThrown)) << "row " << k;
    EXPECT_NEAR(mass[k] + removed_mass[k], mass.front(), kMassBalance * mass.front()) << "row " << k;
  }
  EXPECT_GT(std::count_if(removed.begin(), removed.end(), [](double n) { return n > 0 && n < kThrown; }), 0)
      << "the block leaves over several rows, not all at once";
}

TEST(Outflow, WithStopTheSplashEndsTheRunWithTheOpenTopMessage) {
  TempFolder tmp;
  omp_set_num_threads(1);
  const fs::path out = tmp.path() / "run";
  scene::Runner runner(thrown_scene("stop"), scene::RunOptions{out, std::nullopt, std::nullopt});
  try {
    runner.run();
    FAIL() << "the run completed";
  } catch (const scene::RunFailure& e) {
    EXPECT_EQ(e.report().kind, FailureKind::left_open_top) << e.what();
    const std::string msg = e.what();
    EXPECT_NE(msg.find("through the open top"), std::string::npos) << msg;
    EXPECT_NE(msg.find("container.outflow"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("wall penetration"), std::string::npos) << msg;
    EXPECT_GE(e.report().id, kPool) << "a particle of the thrown block";
  }
  const auto summary = nlohmann::json::parse(io::read_file(io::RunFiles{out}.summary()));
  EXPECT_EQ(summary.at("status"), "failed");
  EXPECT_EQ(summary.at("failure").at("kind"), "left_open_top");
  EXPECT_EQ(summary.at("removed_particles").get<std::uint64_t>(), 0u);
}

TEST(Outflow, AStoppedRunResumedWithRemoveContinuesAsARunThatRemovedFromTheStart) {
  // The way on from the open-top message: --resume the checkpoint of the last good state with outflow "remove".
  // Up to that state neither run had removed anything, so the resumed run ends bitwise where the run that
  // removed from the start ends.
  TempFolder tmp;
  omp_set_num_threads(1);
  const fs::path out = tmp.path() / "run";
  {
    scene::Runner stopped(thrown_scene("stop"), scene::RunOptions{out, std::nullopt, std::nullopt});
    try {
      stopped.run();
      FAIL() << "the run completed";
    } catch (const scene::RunFailure& e) {
      EXPECT_NE(std::string(e.what()).find("--resume and --set container.outflow=remove"), std::string::npos)
          << e.what();
    }
  }
  scene::Runner resumed(thrown_scene("remove"), scene::RunOptions{out, out / "checkpoint.h5", std::nullopt});
  resumed.run();
  scene::Runner from_start(thrown_scene("remove"), scene::RunOptions{});
  from_start.run();
  EXPECT_EQ(resumed.simulation().step_count(), from_start.simulation().step_count());
  expect_bitwise_equal(resumed.simulation().store(), from_start.simulation().store());
  EXPECT_EQ(resumed.simulation().removed().particles, kThrown);
  EXPECT_EQ(resumed.simulation().removed().mass.value(), from_start.simulation().removed().mass.value());
}

TEST(Outflow, RemovalIsBitwiseIdenticalAtOneAndTwoThreadsAndOnResume) {
  TempFolder tmp;
  const int threads = omp_get_max_threads();
  const scene::Scene s = thrown_scene("remove");

  omp_set_num_threads(1);
  scene::Runner one(s, scene::RunOptions{});
  one.run();

  // Two threads, a checkpoint every 0.07 s: the first (t = 0.07 s) falls while the block is leaving.
  omp_set_num_threads(2);
  const fs::path a_dir = tmp.path() / "a", c_dir = tmp.path() / "c";
  scene::Runner two(s, scene::RunOptions{a_dir, std::nullopt, 0.07});
  two.start();
  while (!fs::exists(io::RunFiles{a_dir}.checkpoint())) two.advance();
  const std::uint64_t removed_at_checkpoint = two.simulation().removed().particles;
  EXPECT_GT(removed_at_checkpoint, 0u) << "the checkpoint holds removals already";
  EXPECT_LT(removed_at_checkpoint, kThrown) << "and more follow after it";
  while (two.simulation().time() < 0.08) two.advance();  // killed a little after the checkpoint
  fs::copy(a_dir, c_dir, fs::copy_options::recursive);
  two.run();

  scene::Runner resumed(s, scene::RunOptions{c_dir, c_dir / "checkpoint.h5", 0.07});
  EXPECT_EQ(resumed.simulation().removed().particles, removed_at_checkpoint);
  resumed.run();
  omp_set_num_threads(threads);

  for (const scene::Runner* other : {&two, &resumed}) {
    SCOPED_TRACE(other == &two ? "two threads" : "resumed");
    EXPECT_EQ(other->simulation().step_count(), one.simulation().step_count());
    EXPECT_EQ(other->simulation().time(), one.simulation().time());
    expect_bitwise_equal(other->simulation().store(), one.simulation().store());
    EXPECT_EQ(other->simulation().removed().particles, one.simulation().removed().particles);
    const double a = other->simulation().removed().mass.value(), b = one.simulation().removed().mass.value();
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << a << " vs " << b;
  }
  EXPECT_EQ(one.simulation().removed().particles, kThrown);
  EXPECT_EQ(lines(c_dir / "series.csv"), lines(a_dir / "series.csv"));
}

TEST(Outflow, ACheckpointWithTheOlderCompensatedRemovedMassResumesAsTheUninterruptedRun) {
  // Checkpoints written before the exact sum hold the removed mass as a compensated sum's value and compensation
  // (attributes removed_mass, removed_mass_compensation). Read as the two parts of an exact sum, they are the
  // same number when it fits in two doubles (here a few hundred equal masses): the resumed run ends bitwise
  // where the uninterrupted one does.
  TempFolder tmp;
  omp_set_num_threads(1);
  const scene::Scene s = thrown_scene("remove");
  scene::Runner whole(s, scene::RunOptions{});
  whole.run();
  const fs::path dir = tmp.path() / "run";
  {
    scene::Runner first(s, scene::RunOptions{dir, std::nullopt, 0.07});
    first.start();
    while (!fs::exists(io::RunFiles{dir}.checkpoint())) first.advance();
    ASSERT_GT(first.simulation().removed().particles, 0u);
    ASSERT_LE(first.simulation().removed().mass.parts().size(), 2u);
  }
  // The checkpoint rewritten in the older form.
  {
    const hid_t f = H5Fopen(io::RunFiles{dir}.checkpoint().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    const hid_t g = H5Gopen2(f, "checkpoint", H5P_DEFAULT);
    ASSERT_GE(g, 0);
    const hid_t a = H5Aopen(g, "removed_mass_parts", H5P_DEFAULT);
    ASSERT_GE(a, 0);
    const hid_t space = H5Aget_space(a);
    std::vector<double> parts(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
    if (!parts.empty()) {
      ASSERT_GE(H5Aread(a, H5T_NATIVE_DOUBLE, parts.data()), 0);
    }
    H5Sclose(space);
    H5Aclose(a);
    ASSERT_GE(H5Adelete(g, "removed_mass_parts"), 0);
    parts.resize(2, 0.0);
    const char* names[] = {"removed_mass", "removed_mass_compensation"};
    for (int k = 0; k < 2; ++k) {
      const hid_t scalar = H5Screate(H5S_SCALAR);
      const hid_t attr = H5Acreate2(g, names[k], H5T_NATIVE_DOUBLE, scalar, H5P_DEFAULT, H5P_DEFAULT);
      ASSERT_GE(H5Awrite(attr, H5T_NATIVE_DOUBLE, &parts[static_cast<std::size_t>(k)]), 0);
      H5Aclose(attr);
      H5Sclose(scalar);
    }
    H5Gclose(g);
    H5Fclose(f);
  }
  scene::Runner resumed(s, scene::RunOptions{dir, io::RunFiles{dir}.checkpoint(), 0.07});
  resumed.run();
  EXPECT_EQ(resumed.simulation().step_count(), whole.simulation().step_count());
  expect_bitwise_equal(resumed.simulation().store(), whole.simulation().store());
  EXPECT_EQ(resumed.simulation().removed().particles, whole.simulation().removed().particles);
  EXPECT_EQ(resumed.simulation().removed().mass.parts(), whole.simulation().removed().mass.parts());
}

}  // namespace
