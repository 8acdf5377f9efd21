// A rank's share, in one process (the ground of issue #19's "same result at any rank count"): the sweep over a
// region's particles and their halo (every particle within the largest pair support of the region) gives the
// region's fluid particles bitwise the rates that the sweep over all particles gives them. That takes the step's
// cell lattice to be fixed by the scene (grid_anchor, core/neighbour_cells.hpp) and not by the particles' box:
// without the anchor the share's cells are cut elsewhere, its sums run in another order, and the bits differ.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/neighbour_cells.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "core/sweep_factory.hpp"
#include "tests/support/physics_helpers.hpp"

namespace {

using namespace sph;

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

struct ShareResult {
  std::size_t fluid = 0;      // the region's fluid particles
  std::size_t differing = 0;  // of them, those whose rates differ in any bit
};

/// The sweep over the share of [x_lo, x_hi) (its particles and those within `halo` of it, in the whole store's
/// order) on a grid of its own, against the whole store's rates.
template <int D>
ShareResult sweep_share(const SimulationT<D>& sim, double x_lo, double x_hi, double halo, bool anchored) {
  const ParticleStore<D>& all = sim.store();
  std::vector<std::uint32_t> pick;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (all.x[i][0] >= x_lo - halo && all.x[i][0] < x_hi + halo) pick.push_back(static_cast<std::uint32_t>(i));
  ParticleStore<D> share = all;
  share.gather(pick);
  CellGrid<D> grid;
  std::vector<std::uint8_t> layer;
  const Vec<D> anchor = grid_anchor(sim.settings().geometry.container);
  build_level_grid(share, grid, layer, anchored ? &anchor : nullptr);
  std::vector<std::uint32_t> from(share.size());  // share position -> whole store index
  for (std::size_t k = 0; k < share.size(); ++k) from[k] = pick[grid.order()[k]];
  share.gather(grid.order());
  make_sweep(sim.settings())->run(share.view(), grid);
  ShareResult r;
  for (std::size_t k = 0; k < share.size(); ++k) {
    if (share.kind[k] != Kind::fluid || share.x[k][0] < x_lo || share.x[k][0] >= x_hi) continue;
    const std::size_t i = from[k];
    ++r.fluid;
    const bool same = same_bits(share.a[k], all.a[i]) && same_bits(share.drho[k], all.drho[i]) &&
                      same_bits(share.kick[k], all.kick[i]) && same_bits(share.kick_rho[k], all.kick_rho[i]);
    r.differing += same ? 0 : 1;
  }
  return r;
}

TEST(Partition, ARegionAndItsHaloSweepToTheBitsOfTheWhole) {
  // The dam break with a refined quarter (level-1 particles next to level-0 ones, walls and ghosts), set in
  // motion, its rates as Simulation::refresh() leaves them.
  const auto cases = std::filesystem::path(__FILE__).parent_path().parent_path() / "cases";
  scene::Json doc = scene::read_json_file(cases / "dam_break.json");
  doc["effects"]["static_refinement"] = scene::Json{{"box", {{"lo", {0, 0}}, {"hi", {12.5, 12.5}}}}};
  Simulation sim = scene::build_simulation(scene::scene_from_json(doc));
  for (int k = 0; k < 200; ++k) sim.step();
  sim.refresh();
  // A pair interacts within h_i + h_j <= 2 h_max: the halo that a region's sums need.
  const double halo = 2.0 * test::max_h(sim.store());
  // Three shares side by side, as three ranks would hold them: mixed levels and the left wall; the middle; the
  // front, coarse only (a grid of one layer where the whole one has two).
  const double cuts[] = {0.0, 7.0, 15.0, 60.0};
  std::size_t fluid = 0;
  for (int r = 0; r < 3; ++r) {
    SCOPED_TRACE("share [" + std::to_string(cuts[r]) + ", " + std::to_string(cuts[r + 1]) + ")");
    const ShareResult anchored = sweep_share(sim, cuts[r], cuts[r + 1], halo, true);
    EXPECT_GT(anchored.fluid, 50u);
    EXPECT_EQ(anchored.differing, 0u) << "of " << anchored.fluid;
    fluid += anchored.fluid;
    // The same share on a lattice from its own box: the test can tell.
    const ShareResult own = sweep_share(sim, cuts[r], cuts[r + 1], halo, false);
    EXPECT_GT(own.differing, 0u) << "a grid cut at the share's own corner gave the same bits";
  }
  EXPECT_EQ(fluid, sim.diagnostics().fluid);
}

TEST(Partition, ThreeDimensionalSharesSweepToTheBitsOfTheWhole) {
  // DualSPHysics' 3D dam break with its column (cases/dam_break_3d.json: ghosts in corners, wall particles on every
  // face and on the column), set in motion; shares along x, the middle one holding the column.
  const auto cases = std::filesystem::path(__FILE__).parent_path().parent_path() / "cases";
  SimulationT<3> sim = scene::build_simulation<3>(scene::load_scene(cases / "dam_break_3d.json"));
  for (int k = 0; k < 20; ++k) sim.step();
  sim.refresh();
  const double halo = 2.0 * test::max_h(sim.store());
  const double cuts[] = {-1.0, 0.25, 0.95, 2.0};
  std::size_t fluid = 0;
  for (int r = 0; r < 3; ++r) {
    SCOPED_TRACE("share [" + std::to_string(cuts[r]) + ", " + std::to_string(cuts[r + 1]) + ")");
    const ShareResult anchored = sweep_share(sim, cuts[r], cuts[r + 1], halo, true);
    EXPECT_EQ(anchored.differing, 0u) << "of " << anchored.fluid;
    fluid += anchored.fluid;
    if (anchored.fluid > 0) {
      EXPECT_GT(sweep_share(sim, cuts[r], cuts[r + 1], halo, false).differing, 0u);
    }
  }
  EXPECT_EQ(fluid, sim.diagnostics().fluid);
}

}  // namespace
