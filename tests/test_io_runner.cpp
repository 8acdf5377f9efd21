// A scene run with its outputs: writing output does not change the run (bitwise), the folder holds the
// series, frames, XDMF, resolved scene and summary with no temporary file left, and a run resumed from a
// checkpoint (in a copy of the folder taken after the checkpoint, as if killed then) ends bitwise identical
// to the uninterrupted run, with the same time series and XDMF.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <omp.h>

#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "core/io/atomic_file.hpp"
#include "core/io/hdf5_frames.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/scene/runner.hpp"
#include "core/scene/scene_parser.hpp"
#include "tests/support/test_scale.hpp"

#include "tests/support/io_helpers.hpp"

namespace {

using namespace sph;
using test::TempFolder;
using test::expect_bitwise_equal;
namespace fs = std::filesystem;



/// A small dam break with every effect and dynamic refinement that fires during the run.
scene::Scene tiny_scene() {
  return scene::scene_from_json(scene::parse_json_text(R"({
    "name": "tiny",
    "container": { "lo": [0, 0], "hi": [4, 3] },
    "fluid": [ { "shape": "rectangle", "lo": [0, 0], "hi": [1, 2], "spacing": 0.1, "hydrostatic": true } ],
    "material": { "rho0": 1000, "mach_factor": 10, "reference_height": 2 },
    "effects": {
      "gravity": [0, -9.81],
      "artificial_viscosity": { "alpha": 0.02 },
      "lennard_jones_wall": { "reference_height": 2 },
      "ghost_walls": "free-slip",
      "refinement": { "criterion": "velocity", "v_threshold": 0.4, "check_interval": 20, "max_level": 1 }
    },
    "time": { "end": 0.08, "output_interval": 0.01 },
    "probes": [ { "type": "water_height", "name": "H", "x": 0 }, { "type": "surge_front", "name": "Z" },
                { "type": "pressure", "name": "p", "position": [0.5, 0.1] } ],
    "output": { "frame_interval": 0.02 }
  })",
                                                       "tiny"));
}


std::vector<std::string> lines(const fs::path& file) {
  std::istringstream in(io::read_file(file));
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

bool has_temporary_files(const fs::path& folder) {
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (e.path().extension() == ".tmp") return true;
  }
  return false;
}

TEST(Runner, WritingOutputDoesNotChangeTheRun) {
  TempFolder tmp;
  scene::Runner with(tiny_scene(), scene::RunOptions{tmp.path() / "out", std::nullopt, 0.03});
  scene::Runner without(tiny_scene(), scene::RunOptions{});
  const scene::RunSummary a = with.run();
  const scene::RunSummary b = without.run();
  EXPECT_EQ(with.simulation().step_count(), without.simulation().step_count());
  EXPECT_EQ(with.simulation().time(), without.simulation().time());
  expect_bitwise_equal(with.simulation().store(), without.simulation().store());
  ASSERT_GE(a.final.per_level.size(), 2u);
  EXPECT_GT(a.final.per_level[1], 0u) << "refinement should have fired";
  EXPECT_EQ(a.particle_steps, b.particle_steps);
  EXPECT_EQ(b.rows, 0u);
  EXPECT_FALSE(fs::exists(tmp.path() / "nothing"));
}

TEST(Runner, FolderHoldsSeriesFramesXdmfSceneAndSummary) {
  TempFolder tmp;
  const scene::Scene s = tiny_scene();
  const fs::path out = tmp.path() / "run";
  scene::Runner runner(s, scene::RunOptions{out, std::nullopt, std::nullopt});
  EXPECT_FALSE(fs::exists(out)) << "nothing is created before start()";
  const scene::RunSummary r = runner.run();
  const io::RunFiles files{out};
  for (const auto& p : {files.scene(), files.series(), files.xdmf(), files.summary()}) EXPECT_TRUE(fs::exists(p)) << p;
  EXPECT_FALSE(fs::exists(files.checkpoint()));
  EXPECT_FALSE(has_temporary_files(out));
  EXPECT_TRUE(files.holds_run());

  // The resolved scene reads back as the scene that ran.
  EXPECT_EQ(scene::load_scene(files.scene()), s);

  // Rows at t = 0, 0.01, ..., and the end: 9 for 0.08 s (the end coincides with the last output time or
  // adds one row).
  const auto csv = lines(files.series());
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv[0].rfind("time,step,dt,fluid,ghosts,walls,level_0,level_1,mass,", 0), 0u) << csv[0];
  EXPECT_NE(csv[0].find(",H,Z,p"), std::string::npos);
  EXPECT_GE(csv.size() - 1, 9u);
  EXPECT_LE(csv.size() - 1, 10u);
  EXPECT_EQ(r.rows, csv.size() - 1);
  EXPECT_EQ(csv[1].rfind("0,0,", 0), 0u);

  // Frames at 0, 0.02, ..., 0.08 (+ the end if it is not one of them), densely numbered.
  EXPECT_GE(r.frames, 5u);
  for (std::uint64_t k = 0; k < r.frames; ++k) {
    const io::FrameHeader h = io::read_frame_header(files.frame(k), io::RunFiles::frame_group(k));
    EXPECT_EQ(h.index, k);
    EXPECT_NEAR(h.time, std::min(0.02 * static_cast<double>(k), 0.08), 0.002);
  }
  EXPECT_FALSE(fs::exists(files.frame(r.frames)));
}

TEST(Runner, ResumedRunIsBitwiseIdenticalToTheUninterruptedOne) {
  TempFolder tmp;
  const scene::Scene s = tiny_scene();
  const fs::path a_dir = tmp.path() / "a", c_dir = tmp.path() / "c";
  scene::Runner a(s, scene::RunOptions{a_dir, std::nullopt, 0.035});
  a.start();
  const io::RunFiles a_files{a_dir};
  while (!fs::exists(a_files.checkpoint())) a.advance();
  const std::uint64_t checkpoint_step = a.simulation().step_count();
  // Killed some steps after the checkpoint (a row and a frame past it already on disk): take the folder then.
  while (a.simulation().time() < 0.05) a.advance();
  fs::copy(a_dir, c_dir, fs::copy_options::recursive);
  a.run();

  scene::Runner c(s, scene::RunOptions{c_dir, c_dir / "checkpoint.h5", 0.035});
  EXPECT_EQ(c.simulation().step_count(), checkpoint_step);
  c.run();
  EXPECT_EQ(c.simulation().step_count(), a.simulation().step_count());
  EXPECT_EQ(c.simulation().time(), a.simulation().time());
  expect_bitwise_equal(c.simulation().store(), a.simulation().store());
  EXPECT_EQ(lines(c_dir / "series.csv"), lines(a_dir / "series.csv"));
  EXPECT_EQ(io::read_file(c_dir / "frames.xdmf"), io::read_file(a_dir / "frames.xdmf"));
  EXPECT_FALSE(has_temporary_files(c_dir));
}

/// tiny_scene() refined in the zone [lo, hi] up to max_level, checked every 10 steps.
scene::Scene tiny_zone_scene(const Vec<2>& lo, const Vec<2>& hi, int max_level) {
  scene::Scene s = tiny_scene();
  scene::Refinement r;
  r.criterion = scene::Criterion::zone;
  r.zone = scene::Rect{lo, hi};
  r.check_interval = 10;
  r.max_level = max_level;
  s.effects.refinement = r;
  return s;
}

/// Runs `s` with a checkpoint every 0.05 s, resumes a copy from the first checkpoint, and expects the resumed run
/// to end bitwise as the uninterrupted one. `check` looks at the uninterrupted run's end state first.
template <class Check>
void expect_resume_is_bitwise(const scene::Scene& s, Check&& check) {
  TempFolder tmp;
  const fs::path a_dir = tmp.path() / "a", c_dir = tmp.path() / "c";
  scene::Runner a(s, scene::RunOptions{a_dir, std::nullopt, 0.05});
  a.start();
  while (!fs::exists(io::RunFiles{a_dir}.checkpoint())) a.advance();
  fs::copy(a_dir, c_dir, fs::copy_options::recursive);
  a.run();
  check(a.simulation().store());
  scene::Runner c(s, scene::RunOptions{c_dir, c_dir / "checkpoint.h5", 0.05});
  c.run();
  EXPECT_EQ(c.simulation().step_count(), a.simulation().step_count());
  expect_bitwise_equal(c.simulation().store(), a.simulation().store());
  EXPECT_EQ(lines(c_dir / "series.csv"), lines(a_dir / "series.csv"));
}

// The same with coarsening: families split in a zone at the toe of the column and merge as the toe runs out
// of it; the merge state (level_time, origin) travels in the checkpoint like every field.
TEST(Runner, ResumedRunWithCoarseningIsBitwiseIdenticalToTheUninterruptedOne) {
  scene::Scene s = tiny_zone_scene(Vec<2>(0.7, 0.0), Vec<2>(1.0, 0.4), 1);  // the toe, which runs out of the zone
  s.effects.refinement->coarsening = scene::Coarsening{};
  s.effects.refinement->coarsening->hold_time = 0.005;
  s.time.end = 0.15;
  expect_resume_is_bitwise(s, [](const ParticleStore<2>& st) {
    std::size_t merged = 0;
    for (std::size_t i = 0; i < st.size(); ++i)
      merged += st.origin[i] == Origin::merge || st.origin[i] == Origin::fresh_merge;
    EXPECT_GT(merged, 0u) << "no family merged: the test would not see the merge's state";
  });
}

// run.json's refinement section is the stage's own count of this invocation: the particles split, the families
// merged, and the families that passed the merge test and the hold but were left split, by reason (the run above,
// uninterrupted).
TEST(Runner, RunJsonCountsTheMergesAndTheFamiliesLeftSplit) {
  scene::Scene s = tiny_zone_scene(Vec<2>(0.7, 0.0), Vec<2>(1.0, 0.4), 1);
  s.effects.refinement->coarsening = scene::Coarsening{};
  s.effects.refinement->coarsening->hold_time = 0.005;
  s.time.end = 0.15;
  TempFolder tmp;
  const fs::path out = tmp.path() / "out";
  scene::Runner runner(s, scene::RunOptions{out, std::nullopt, 0.05});
  runner.run();
  const refine::RefinementStage* stage = nullptr;
  for (const auto& st : runner.simulation().stages())
    if (const auto* rs = dynamic_cast<const refine::RefinementStage*>(st.get())) stage = rs;
  ASSERT_NE(stage, nullptr);
  ASSERT_GT(stage->total_merged(), 0u) << "no family merged: the count would not be seen";
  const auto j = nlohmann::json::parse(io::read_file(io::RunFiles{out}.summary())).at("refinement");
  EXPECT_EQ(j.at("split").get<std::size_t>(), stage->total_refined());
  EXPECT_EQ(j.at("merged_families").get<std::size_t>(), stage->total_merged());
  const auto& declined = j.at("merges_declined");
  EXPECT_EQ(declined.at("walls").get<std::size_t>(), stage->total_declined().walls);
  EXPECT_EQ(declined.at("criterion").get<std::size_t>(), stage->total_declined().criterion);
  EXPECT_EQ(declined.at("dispersed").get<std::size_t>(), stage->total_declined().dispersed);
  EXPECT_EQ(declined.at("intermixed").get<std::size_t>(), stage->total_declined().intermixed);
  EXPECT_EQ(stage->total_declined().intermixed, 0u) << "mixed coupling has no intermix rule";
}

// The same with per-level time steps (time.stepping = "per_level") and two levels of refinement in a zone: a
// checkpoint is written between steps, where every bin is synchronised, and holds the rates (a, drho, kick) the
// next step opens with.
TEST(Runner, ResumedRunWithPerLevelStepsIsBitwiseIdenticalToTheUninterruptedOne) {
  scene::Scene s = tiny_zone_scene(Vec<2>(0.5, 0.0), Vec<2>(1.0, 0.4), 2);
  s.time.stepping = TimeStepping::per_level;
  s.time.end = test::short_runs() ? 0.1 : 0.15;  // shorter under the sanitizer preset (the checkpoint is at 0.05)
  expect_resume_is_bitwise(s, [](const ParticleStore<2>& st) {
    int finest = 0;
    for (std::size_t i = 0; i < st.size(); ++i) finest = std::max(finest, static_cast<int>(st.level[i]));
    EXPECT_EQ(finest, 2) << "the zone should hold level-2 particles, stepping in their own bin";
  });
}

// The same with buffered levels (effects.refinement.coupling = "buffered") and two levels in a zone: the roles and the
// passive particles' fitted state travel in the checkpoint, and the resumed run fits them as the uninterrupted one.
// Buffered levels are for zones the fluid does not leave (docs/METHOD.md), so the water lies still: the column is
// widened to a pool 1 m deep across the container.
TEST(Runner, ResumedRunWithBufferedLevelsIsBitwiseIdenticalToTheUninterruptedOne) {
  scene::Scene s = tiny_zone_scene(Vec<2>(0.0, 0.0), Vec<2>(0.3, 0.3), 2);
  s.fluid[0].rect = scene::Rect{Vec<2>(0.0, 0.0), Vec<2>(4.0, 1.0)};
  s.effects.refinement->coupling = LevelCoupling::buffered;
  s.time.end = test::short_runs() ? 0.1 : 0.15;
  expect_resume_is_bitwise(s, [](const ParticleStore<2>& st) {
    std::size_t passive = 0;
    for (std::size_t i = 0; i < st.size(); ++i) passive += is_passive(st.role[i]) ? 1 : 0;
    EXPECT_GT(passive, 0u) << "no passive particle: the test would not see their state";
  });
}

// A finished run extended with a later time.end (--resume --set time.end=...) is the run that went to the
// later end without stopping, bitwise, at 1 and 2 threads. The first run's last step is shortened to land on
// its end (0.043 s falls between steps), which the longer run never does.
TEST(Runner, AFinishedRunExtendedToALaterEndIsTheUninterruptedRun) {
  const int saved = omp_get_max_threads();
  for (const int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    omp_set_num_threads(threads);
    TempFolder tmp;
    scene::Scene shorter = tiny_scene();
    shorter.time.end = 0.043;
    const scene::Scene longer = tiny_scene();  // end 0.08
    const fs::path a_dir = tmp.path() / "a", b_dir = tmp.path() / "b";
    scene::Runner a(longer, scene::RunOptions{a_dir, std::nullopt, 0.02});
    a.run();

    {
      scene::Runner b(shorter, scene::RunOptions{b_dir, std::nullopt, 0.02});
      b.run();
      EXPECT_EQ(b.simulation().time(), 0.043) << "the last step lands on the end time";
    }
    scene::Runner extended(longer, scene::RunOptions{b_dir, b_dir / "checkpoint.h5", 0.02});
    EXPECT_LT(extended.simulation().time(), 0.043) << "the checkpoint precedes the shortened step";
    extended.run();
    EXPECT_EQ(extended.simulation().step_count(), a.simulation().step_count());
    EXPECT_EQ(extended.simulation().time(), a.simulation().time());
    expect_bitwise_equal(extended.simulation().store(), a.simulation().store());
    EXPECT_EQ(lines(b_dir / "series.csv"), lines(a_dir / "series.csv"));
  }
  omp_set_num_threads(saved);
}

TEST(Runner, ResumeRefusesACheckpointOfAnotherScene) {
  TempFolder tmp;
  scene::Scene s = tiny_scene();
  s.time.end = 0.01;
  scene::Runner a(s, scene::RunOptions{tmp.path() / "a", std::nullopt, 0.01});
  a.run();
  scene::Scene other = s;
  other.h_factor = 1.5;
  try {
    scene::Runner b(other, scene::RunOptions{tmp.path() / "b", tmp.path() / "a" / "checkpoint.h5", std::nullopt});
    FAIL() << "accepted";
  } catch (const scene::SceneError& e) {
    EXPECT_EQ(e.path(), "--resume");
  }
  // A longer end time is fine: the run continues.
  scene::Scene longer = s;
  longer.time.end = 0.02;
  scene::Runner c(longer, scene::RunOptions{tmp.path() / "a", tmp.path() / "a" / "checkpoint.h5", std::nullopt});
  c.run();
  EXPECT_DOUBLE_EQ(c.simulation().time(), 0.02);
}

}  // namespace
