// Scene -> Simulation: the case files build exactly the programmatic cases (bitwise, and after steps), an
// effect absent from the scene is absent from the solver, and refinement is wired in.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <filesystem>
#include <string>
#include <vector>

#include "core/case_builder.hpp"
#include "core/neighbour_cells.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "core/setup.hpp"

#include "tests/support/io_helpers.hpp"

namespace {

using namespace sph;
using test::TempFolder;
using test::expect_bitwise_equal;


const std::filesystem::path kCases = std::filesystem::path(__FILE__).parent_path().parent_path() / "cases";


void expect_same_settings(const SolverSettings& a, const SolverSettings& b) {
  EXPECT_EQ(a.eos.rho0, b.eos.rho0);
  EXPECT_EQ(a.eos.c0, b.eos.c0);
  EXPECT_EQ(a.eos.gamma, b.eos.gamma);
  EXPECT_EQ(a.gravity.has_value(), b.gravity.has_value());
  if (a.gravity && b.gravity) {
    EXPECT_EQ(*a.gravity, *b.gravity);
  }
  ASSERT_EQ(a.viscosity.has_value(), b.viscosity.has_value());
  if (a.viscosity) {
    EXPECT_EQ(a.viscosity->alpha, b.viscosity->alpha);
    EXPECT_EQ(a.viscosity->beta, b.viscosity->beta);
  }
  ASSERT_EQ(a.density_diffusion.has_value(), b.density_diffusion.has_value());
  if (a.density_diffusion) {
    EXPECT_EQ(a.density_diffusion->delta, b.density_diffusion->delta);
  }
  ASSERT_EQ(a.artificial_stress.has_value(), b.artificial_stress.has_value());
  ASSERT_EQ(a.lennard_jones.has_value(), b.lennard_jones.has_value());
  if (a.lennard_jones) {
    EXPECT_EQ(a.lennard_jones->strength, b.lennard_jones->strength);
    EXPECT_EQ(a.lennard_jones->r0_factor, b.lennard_jones->r0_factor);
    EXPECT_EQ(a.lennard_jones->spacing, b.lennard_jones->spacing);
  }
  EXPECT_EQ(a.ghosts, b.ghosts);
  EXPECT_EQ(a.geometry.container.lo, b.geometry.container.lo);
  EXPECT_EQ(a.geometry.container.hi, b.geometry.container.hi);
  EXPECT_EQ(a.geometry.open_top, b.geometry.open_top);
  EXPECT_EQ(a.geometry.outflow, b.geometry.outflow);
  EXPECT_EQ(a.cfl, b.cfl);
  EXPECT_EQ(a.dt_max, b.dt_max);
}

void expect_same_run(Simulation scene_sim, Simulation reference, int steps) {
  expect_same_settings(scene_sim.settings(), reference.settings());
  EXPECT_STREQ(scene_sim.sweep_name(), reference.sweep_name());
  expect_bitwise_equal(scene_sim.store(), reference.store());
  EXPECT_EQ(scene_sim.dt(), reference.dt());
  for (int k = 0; k < steps; ++k) {
    scene_sim.step();
    scene_sim.run_stages();
    reference.step();
    reference.run_stages();
  }
  expect_bitwise_equal(scene_sim.store(), reference.store());
  EXPECT_EQ(scene_sim.time(), reference.time());
}

TEST(SceneBuilder, DamBreakCaseIsMakeDamBreak) {
  const scene::Scene s = scene::load_scene(kCases / "dam_break.json");
  expect_same_run(scene::build_simulation(s), make_dam_break(DamBreakSpec{}), 20);
}

TEST(SceneBuilder, DropCaseIsMakeDrop) {
  const scene::Scene s = scene::load_scene(kCases / "drop.json");
  expect_same_run(scene::build_simulation(s), make_drop(DropSpec{}), 20);
}

TEST(SceneBuilder, StillTankCaseIsMakeStillTank) {
  const scene::Scene s = scene::load_scene(kCases / "still_tank.json");
  expect_same_run(scene::build_simulation(s), make_still_tank(TankSpec{}), 20);
}

TEST(SceneBuilder, AbsentEffectsAreAbsentFromTheSolver) {
  scene::Json doc = scene::read_json_file(kCases / "dam_break.json");
  doc.erase("effects");
  doc["fluid"][0].erase("hydrostatic");
  doc["material"] = scene::Json{{"rho0", 1000}, {"c0", 50}};
  const scene::Scene s = scene::scene_from_json(doc);
  const SolverSettings settings = scene::solver_settings(s);
  EXPECT_FALSE(settings.gravity);
  EXPECT_FALSE(settings.viscosity);
  EXPECT_FALSE(settings.lennard_jones);
  EXPECT_FALSE(settings.ghosts);
  const Simulation sim = scene::build_simulation(s);
  EXPECT_STREQ(sim.sweep_name(), "continuity+pressure");
  EXPECT_EQ(sim.diagnostics().walls, 0u);  // no Lennard-Jones: no wall particles
  EXPECT_EQ(sim.diagnostics().ghosts, 0u);
}

TEST(SceneBuilder, StaticRefinementSplitsEveryParticle) {
  const scene::Scene s = scene::load_scene(kCases / "dam_break_refined.json");
  const Simulation sim = scene::build_simulation(s);
  const Diagnostics d = sim.diagnostics();
  ASSERT_EQ(d.per_level.size(), 2u);
  EXPECT_EQ(d.per_level[0], 0u);
  EXPECT_EQ(d.per_level[1], 3600u);  // the paper's fully refined 60 x 60
  EXPECT_NEAR(d.mass, 1000.0 * 25.0 * 25.0, 1e-6);
  EXPECT_EQ(sim.settings().lennard_jones->spacing, 25.0 / 30.0 / 4.0);  // half the finest spacing
}

TEST(SceneBuilder, StaticRefinementOfABoxSplitsOnlyInside) {
  scene::Json doc = scene::read_json_file(kCases / "dam_break.json");
  doc["effects"]["static_refinement"] = scene::Json{{"box", {{"lo", {0, 0}}, {"hi", {5, 5}}}}};
  const Simulation sim = scene::build_simulation(scene::scene_from_json(doc));
  const Diagnostics d = sim.diagnostics();
  ASSERT_EQ(d.per_level.size(), 2u);
  EXPECT_EQ(d.per_level[1], 4u * 36u);  // the 6 x 6 particles of [0, 5]^2, four daughters each
  EXPECT_EQ(d.per_level[0], 900u - 36u);
}

TEST(SceneBuilder, DynamicRefinementStageRefinesFastParticles) {
  // A zone criterion checked every step refines the particles in the zone at the first check.
  scene::Json doc = scene::read_json_file(kCases / "dam_break_aap.json");
  doc["effects"]["refinement"] = scene::Json{{"criterion", "zone"},
                                             {"zone", {{"lo", {0, 0}}, {"hi", {5, 5}}}},
                                             {"check_interval", 1},
                                             {"max_level", 1}};
  Simulation sim = scene::build_simulation(scene::scene_from_json(doc));
  EXPECT_EQ(sim.diagnostics().per_level.size(), 1u);
  sim.step();
  sim.run_stages();
  const Diagnostics d = sim.diagnostics();
  ASSERT_EQ(d.per_level.size(), 2u);
  EXPECT_GT(d.per_level[1], 0u);
  EXPECT_EQ(d.per_level[1] % 4, 0u);
}

}  // namespace

// The grid's cells follow the finest fluid support (core/neighbour_cells.hpp), in scenes with Lennard-Jones
// wall particles (h = 0) too: they once took part in the minimum, which fell to 0, and the cells were then
// sized by the grid's memory budget. Checked after set-up (refresh) and after a step (the step's own path).
TEST(SceneBuilder, TheGridIsSizedByTheFinestFluidSupportInScenesWithWallParticles) {
  for (const char* file : {"dam_break.json", "dam_break_refined.json", "drop.json"}) {
    SCOPED_TRACE(file);
    Simulation sim = scene::build_simulation(scene::load_scene(kCases / file));
    ASSERT_GT(sim.diagnostics().walls, 0u) << "the check is about scenes with wall particles";
    for (int pass = 0; pass < 2; ++pass) {
      double h_min = std::numeric_limits<double>::infinity();
      const auto& st = sim.store();
      for (std::size_t i = 0; i < st.size(); ++i) {
        if (st.kind[i] == Kind::fluid) h_min = std::min(h_min, st.h[i]);
      }
      // CellGrid pads the requested size by a relative 1e-6 (its rounding margin); nothing else may change it.
      EXPECT_DOUBLE_EQ(sim.grid().cell_size(), kCellPerFinestH * h_min * (1.0 + 1e-6));
      sim.step();
    }
  }
}

namespace {

// The set-up across ranks (issue #19): each of P ranks generates every P-th lattice point with the id the whole
// set-up gives it; together the shares are the whole set-up, ids and positions exact, each point once.
template <int D, class Each>
void expect_shares_make_the_whole(Each&& each, std::size_t ranks) {
  FluidBlockSpecT<D> spec;
  spec.spacing = 0.25;
  ParticleStore<D> whole;
  whole.take_ids(7);  // ids already handed out (a block before this one)
  add_fluid(whole, lattice_share<D>(each, 1, 0), spec, 1000.0);
  std::vector<std::pair<ParticleId, Vec<D>>> joined;
  ParticleId next = 0;
  for (std::size_t r = 0; r < ranks; ++r) {
    ParticleStore<D> part;
    part.take_ids(7);
    const LatticeShare<D> share = lattice_share<D>(each, ranks, r);
    EXPECT_EQ(share.total, whole.size());
    add_fluid(part, share, spec, 1000.0);
    for (std::size_t i = 0; i < part.size(); ++i) joined.emplace_back(part.id[i], part.x[i]);
    next = part.next_id();
  }
  EXPECT_EQ(next, whole.next_id());  // every rank hands out the same ids after the block
  std::sort(joined.begin(), joined.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  ASSERT_EQ(joined.size(), whole.size());
  for (std::size_t i = 0; i < whole.size(); ++i) {
    EXPECT_EQ(joined[i].first, whole.id[i]);
    EXPECT_EQ(joined[i].second, whole.x[i]);
  }
}

TEST(SetUp, SharesOfALatticeOverRanksAreTheWholeLatticeWithItsIds) {
  for (const std::size_t ranks : {1u, 2u, 3u, 4u}) {
    expect_shares_make_the_whole<2>(
        [](auto&& visit) { each_rectangle_point(Vec<2>(0, 0), Vec<2>(2.5, 1.75), 0.25, visit); }, ranks);
    expect_shares_make_the_whole<2>([](auto&& visit) { each_circle_point(Vec<2>(1, 1), 0.9, 0.25, visit); }, ranks);
    expect_shares_make_the_whole<3>(
        [](auto&& visit) { each_box_point(Vec<3>(0, 0, 0), Vec<3>(1.0, 0.75, 0.5), 0.25, visit); }, ranks);
    expect_shares_make_the_whole<3>([](auto&& visit) { each_ball_point(Vec<3>(1, 1, 1), 0.6, 0.25, visit); }, ranks);
  }
}

}  // namespace
