// Outflow through an open top (container.outflow): fluid thrown over the rim is removed inside the step when
// the scene asks for it (and only that fluid: not what went through a wall, not ghosts or wall particles), and a
// step the watchdog undoes gives its removals back.
#include <gtest/gtest.h>
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

}  // namespace
