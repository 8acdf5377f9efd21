// CellGrid: the neighbour sets found through the grid equal the O(N^2) brute force, on many point
// layouts; the traversal is deterministic; cell ranges hold exactly their cell's particles.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/thread_count.hpp"
#include "core/cell_grid.hpp"
#include "core/types.hpp"
#include "tests/support/brute_force.hpp"
#include "tests/support/test_scale.hpp"

namespace sph {
namespace {

using NeighbourLists = std::vector<std::vector<std::uint32_t>>;

/// SPH_TEST_SCALE=short (the asan preset) shrinks the brute-force comparisons.
std::size_t scaled(std::size_t n) {
  return test::short_runs() ? std::max<std::size_t>(n / 4, 1) : n;
}

using sph::test::ThreadCount;

template <int D>
struct Points {
  std::vector<Vec<D>> x;
  std::vector<double> h;
};

/// The grid's neighbour lists, mapped back to the caller's (unsorted) indices, each list sorted.
/// Also checks that every reported r2 is the squared distance and that no pair is reported twice.
template <int D>
NeighbourLists grid_neighbours(const Points<D>& pts, double cell_size, CellGrid<D>* grid_out = nullptr,
                               double max_h = -1.0) {
  const std::size_t n = pts.x.size();
  CellGrid<D> grid;
  grid.build(pts.x.data(), n, cell_size, max_h);
  const auto& order = grid.order();
  EXPECT_EQ(order.size(), n);
  std::vector<Vec<D>> xs(n);
  std::vector<double> hs(n);
  for (std::size_t k = 0; k < n; ++k) {
    xs[k] = pts.x[order[k]];
    hs[k] = pts.h[order[k]];
  }
  NeighbourLists nb(n);
  for (std::size_t k = 0; k < n; ++k) {
    auto& list = nb[order[k]];
    grid.for_each_neighbour(k, xs.data(), hs.data(), [&](std::uint32_t j, double r2) {
      EXPECT_EQ(r2, (xs[k] - xs[j]).squaredNorm());
      list.push_back(order[j]);
    });
    std::sort(list.begin(), list.end());
    EXPECT_TRUE(std::adjacent_find(list.begin(), list.end()) == list.end()) << "pair reported twice";
  }
  if (grid_out) *grid_out = std::move(grid);
  return nb;
}

double max_h(const std::vector<double>& h) {
  return h.empty() ? 1.0 : *std::max_element(h.begin(), h.end());
}

/// Compares the grid against brute force with three cell sizes: 2 max(h) (cell = the largest support), min(h)
/// with queries reaching h_i + max(h) (what the solver builds), and 0.37 min(h) (many rows per query).
template <int D>
void expect_neighbours_equal_brute_force(const Points<D>& pts, std::size_t min_pairs = 0) {
  const NeighbourLists expected = test::brute_force_neighbours<D>(pts.x, pts.h);
  const double hmax = max_h(pts.h);
  const double hmin = pts.h.empty() ? 1.0 : *std::min_element(pts.h.begin(), pts.h.end());
  for (const double cell : {2.0 * hmax, hmin, 0.37 * hmin}) {
    SCOPED_TRACE("cell size " + std::to_string(cell));
    const NeighbourLists actual = grid_neighbours(pts, cell, static_cast<CellGrid<D>*>(nullptr), hmax);
    ASSERT_EQ(actual.size(), expected.size());
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      if (actual[i] != expected[i]) {
        if (++mismatches <= 5) {
          ADD_FAILURE() << "particle " << i << ": grid found " << actual[i].size()
                        << " neighbours, brute force " << expected[i].size();
        }
      }
    }
    EXPECT_EQ(mismatches, 0u);
  }
  EXPECT_GE(test::pair_count(expected), min_pairs) << "the layout should produce pairs to compare";
}

template <int D>
Points<D> random_points(std::size_t n, double box, double h, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, box);
  Points<D> p;
  p.x.resize(n);
  for (auto& xi : p.x) {
    for (int k = 0; k < D; ++k) xi[k] = u(rng);
  }
  p.h.assign(n, h);
  return p;
}

/// A D-dimensional lattice of side^D points, spacing `d`, starting at `origin` in every coordinate.
template <int D>
Points<D> lattice(std::size_t side, double d, double h, double origin = 0.0) {
  Points<D> p;
  std::size_t total = 1;
  for (int k = 0; k < D; ++k) total *= side;
  p.x.resize(total);
  for (std::size_t idx = 0; idx < total; ++idx) {
    std::size_t rest = idx;
    for (int k = 0; k < D; ++k) {
      p.x[idx][k] = origin + static_cast<double>(rest % side) * d;
      rest /= side;
    }
  }
  p.h.assign(total, h);
  return p;
}

// ---------------------------------------------------------------------------------------------------

TEST(CellGrid, NeighboursEqualBruteForceOnRandomPoints) {
  // ~20 neighbours per particle: density 2, support 2h = 1.8.
  const std::size_t n = scaled(20000);
  const double box = std::sqrt(static_cast<double>(n) / 2.0);
  expect_neighbours_equal_brute_force(random_points<2>(n, box, 0.9, 1), n);
}

TEST(CellGrid, NeighboursEqualBruteForceWithContinuouslyVaryingSmoothingLengths) {
  const std::size_t n = scaled(8000);
  const double box = std::sqrt(static_cast<double>(n) / 2.0);
  auto pts = random_points<2>(n, box, 1.0, 2);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.3, 1.0);
  for (auto& hi : pts.h) hi = u(rng);
  expect_neighbours_equal_brute_force(pts, n);
}

TEST(CellGrid, NeighboursEqualBruteForceOnLattice) {
  // Spacing 1, h = 1.2: neighbours at r = 1, sqrt 2, 2, sqrt 5; not at sqrt 8.
  expect_neighbours_equal_brute_force(lattice<2>(60, 1.0, 1.2), 3600);
  // Spacing 0.1 from a non-zero origin (inexact coordinates), same ratio.
  expect_neighbours_equal_brute_force(lattice<2>(60, 0.1, 0.12, -3.7), 3600);
}

TEST(CellGrid, NeighboursEqualBruteForceOnLatticeWithSupportEqualToSpacing) {
  // 2h equals the spacing: every nearest pair sits at the support radius (up to rounding) and the cell size
  // equals the spacing, so lattice points lie on cell faces.
  for (const double d : {1.0, 0.25, 0.1, 0.3, 1.0 / 3.0, 0.7}) {
    SCOPED_TRACE("spacing " + std::to_string(d));
    expect_neighbours_equal_brute_force(lattice<2>(50, d, d / 2.0, -1.3));
    expect_neighbours_equal_brute_force(lattice<2>(50, d, d / 2.0, 0.0));
  }
}

TEST(CellGrid, NeighboursEqualBruteForceOnClusteredPoints) {
  // Tight Gaussian clusters (many particles per cell) over a sparse uniform background (mostly empty cells).
  const std::size_t n = scaled(12000);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 100.0);
  Points<2> pts;
  for (int c = 0; c < 20; ++c) {
    const Vec<2> centre{u(rng), u(rng)};
    std::normal_distribution<double> g(0.0, 0.5);
    for (std::size_t k = 0; k < n / 25; ++k) pts.x.push_back(centre + Vec<2>{g(rng), g(rng)});
  }
  while (pts.x.size() < n) pts.x.push_back(Vec<2>{u(rng), u(rng)});
  pts.h.assign(pts.x.size(), 0.4);
  expect_neighbours_equal_brute_force(pts, n);
}

TEST(CellGrid, NeighboursEqualBruteForceWithMixedSmoothingLengths) {
  // Refinement levels h, h/2, h/4 randomly interleaved; cell size 2h from the coarsest level.
  const std::size_t n = scaled(12000);
  const double h = 1.0;
  const double box = std::sqrt(static_cast<double>(n) / 4.0);
  auto pts = random_points<2>(n, box, h, 5);
  std::mt19937_64 rng(6);
  std::uniform_int_distribution<int> level(0, 2);
  for (auto& hi : pts.h) hi = h / static_cast<double>(1 << level(rng));
  expect_neighbours_equal_brute_force(pts, n);
}

TEST(CellGrid, NeighboursEqualBruteForceWithRefinedRegions) {
  // Levels in spatial bands as a refinement produces them: coarse lattice on the left, h/2 lattice in the
  // middle, h/4 on the right, each with spacing proportional to its h, meeting at shared interfaces.
  Points<2> pts;
  const double d0 = 1.0;
  const double h0 = 1.3 * d0;
  double x_start = 0.0;
  for (int lvl = 0; lvl < 3; ++lvl) {
    const double d = d0 / static_cast<double>(1 << lvl);
    const auto cols = static_cast<std::size_t>(std::lround(10.0 / d));
    const auto rows = static_cast<std::size_t>(std::lround(20.0 / d));
    for (std::size_t i = 0; i < cols; ++i) {
      for (std::size_t j = 0; j < rows; ++j) {
        pts.x.push_back(
            Vec<2>{x_start + (static_cast<double>(i) + 0.5) * d, (static_cast<double>(j) + 0.5) * d});
        pts.h.push_back(h0 / static_cast<double>(1 << lvl));
      }
    }
    x_start += 10.0;
  }
  expect_neighbours_equal_brute_force(pts, pts.x.size());
}

TEST(CellGrid, EmptySetBuildsAndHasNoParticles) {
  CellGrid<2> grid;
  const std::vector<Vec<2>> x;
  grid.build(x.data(), 0, 1.0);
  EXPECT_TRUE(grid.order().empty());
  EXPECT_EQ(grid.particle_count(), 0u);
  ASSERT_EQ(grid.cell_start().size(), grid.cell_count() + 1);
  for (const auto s : grid.cell_start()) EXPECT_EQ(s, 0u);
  EXPECT_TRUE(grid_neighbours(Points<2>{}, 1.0).empty());
}

TEST(CellGrid, OneParticleHasNoNeighbours) {
  Points<2> pts;
  pts.x = {Vec<2>{3.5, -2.0}};
  pts.h = {1.0};
  const auto nb = grid_neighbours(pts, 2.0);
  ASSERT_EQ(nb.size(), 1u);
  EXPECT_TRUE(nb[0].empty());
}

TEST(CellGrid, NeighboursEqualBruteForceWithAllParticlesInOneCell) {
  // 300 points in a box of side 0.5, cell size 2 h = 1: a single cell holds every particle.
  auto pts = random_points<2>(300, 0.5, 0.5, 7);
  CellGrid<2> grid;
  const auto nb = grid_neighbours(pts, 1.0, &grid);
  EXPECT_EQ(grid.cell_count(), 1u);
  EXPECT_EQ(nb, test::brute_force_neighbours<2>(pts.x, pts.h));
  // With h = 0.5 every pair in the box is within the support: all-to-all.
  for (const auto& list : nb) EXPECT_EQ(list.size(), 299u);
}

TEST(CellGrid, NeighboursEqualBruteForceWithParticlesExactlyOnCellFaces) {
  // Coordinates are exact multiples of the cell size (the cell size is 2 max h). Mixed with particles at
  // half-cell offsets and some smaller h, so faces carry both neighbours and non-neighbours.
  for (const double cell : {1.0, 0.5, 0.1, 0.3, 0.7, 1.0 / 3.0}) {
    SCOPED_TRACE("cell size " + std::to_string(cell));
    Points<2> pts;
    std::mt19937_64 rng(8);
    std::uniform_int_distribution<int> pick(0, 3);
    for (int i = -12; i <= 12; ++i) {
      for (int j = -12; j <= 12; ++j) {
        const double xi = static_cast<double>(i) * cell;
        const double yj = static_cast<double>(j) * cell;
        const double h = (pick(rng) == 0) ? cell / 4.0 : cell / 2.0;
        pts.x.push_back(Vec<2>{xi, yj});
        pts.h.push_back(h);
        if (pick(rng) == 0) {
          pts.x.push_back(Vec<2>{xi + 0.5 * cell, yj});
          pts.h.push_back(cell / 2.0);
        }
      }
    }
    // Exactly at the cell size along a face, h = cell / 2: at the support radius, not a neighbour.
    pts.x.push_back(Vec<2>{20.0 * cell, 0.0});
    pts.x.push_back(Vec<2>{21.0 * cell, 0.0});
    pts.h.push_back(cell / 2.0);
    pts.h.push_back(cell / 2.0);
    expect_neighbours_equal_brute_force(pts, pts.x.size() / 2);
  }
}

TEST(CellGrid, NeighboursEqualBruteForceForFarFlungSparsePoints) {
  // The bounding box would need ~1e8 cells of size 2h: the grid coarsens its cells past kMaxCells.
  Points<2> pts = random_points<2>(200, 2.0, 0.5, 9);
  auto far = random_points<2>(200, 2.0, 0.5, 10);
  for (auto& xi : far.x) xi += Vec<2>{1e4, 1e4};
  pts.x.insert(pts.x.end(), far.x.begin(), far.x.end());
  pts.h.insert(pts.h.end(), far.h.begin(), far.h.end());
  CellGrid<2> grid;
  const auto nb = grid_neighbours(pts, 1.0, &grid);
  EXPECT_LE(grid.cell_count(), CellGrid<2>::kMaxCells);
  EXPECT_GT(grid.cell_size(), 1.0);
  EXPECT_EQ(nb, test::brute_force_neighbours<2>(pts.x, pts.h));
}

TEST(CellGrid, AParticleFlungBeyondTheIntegerRangeStillGivesAValidGrid) {
  // Found by the scene fuzzer (UBSan): a particle at 1e25 m made the cell count per axis overflow an integer
  // before the cells could grow. The grid must size itself in floating point and stay correct.
  Points<2> pts = random_points<2>(300, 3.0, 0.5, 11);
  pts.x.push_back(Vec<2>{1.1e25, -3.0e24});
  pts.h.push_back(0.5);
  CellGrid<2> grid;
  const auto nb = grid_neighbours(pts, 1.0, &grid);
  EXPECT_LE(grid.cell_count(), CellGrid<2>::cell_budget(pts.x.size()));
  EXPECT_EQ(nb, test::brute_force_neighbours<2>(pts.x, pts.h));
}

TEST(CellGrid, NeighboursEqualBruteForceOnRandomPoints3D) {
  // ~30 neighbours per particle: density 1, support 2h = 1.9.
  const std::size_t n = scaled(12000);
  const double box = std::cbrt(static_cast<double>(n));
  expect_neighbours_equal_brute_force(random_points<3>(n, box, 0.95, 11), n);
}

TEST(CellGrid, NeighboursEqualBruteForceOnLattice3D) {
  expect_neighbours_equal_brute_force(lattice<3>(16, 1.0, 1.2), 4096);
  expect_neighbours_equal_brute_force(lattice<3>(16, 0.1, 0.05, -0.35));  // on faces, at the support radius
}

TEST(CellGrid, NeighboursEqualBruteForceWithMixedSmoothingLengths3D) {
  const std::size_t n = scaled(8000);
  const double box = std::cbrt(static_cast<double>(n) / 2.0);
  auto pts = random_points<3>(n, box, 1.0, 12);
  std::mt19937_64 rng(13);
  std::uniform_int_distribution<int> level(0, 2);
  for (auto& hi : pts.h) hi = 1.0 / static_cast<double>(1 << level(rng));
  expect_neighbours_equal_brute_force(pts, n);
}

/// The traversal as a flat sequence of (i, j) in sorted indices, particle by particle.
template <int D>
std::vector<std::pair<std::size_t, std::uint32_t>> traversal(const Points<D>& pts, double cell_size,
                                                             int threads,
                                                             std::vector<std::uint32_t>* order_out) {
  const ThreadCount tc(threads);
  CellGrid<D> grid;
  grid.build(pts.x.data(), pts.x.size(), cell_size);
  *order_out = grid.order();
  std::vector<Vec<D>> xs(pts.x.size());
  std::vector<double> hs(pts.x.size());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    xs[k] = pts.x[grid.order()[k]];
    hs[k] = pts.h[grid.order()[k]];
  }
  std::vector<std::pair<std::size_t, std::uint32_t>> seq;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    grid.for_each_neighbour(i, xs.data(), hs.data(),
                            [&](std::uint32_t j, double) { seq.emplace_back(i, j); });
  }
  return seq;
}

TEST(CellGrid, TraversalOrderIsDeterministicAcrossRunsAndThreadCounts) {
  auto pts = random_points<2>(scaled(200000), 300.0, 0.6, 14);
  std::vector<std::uint32_t> order1, order2, order4;
  const auto seq1 = traversal(pts, 1.2, 1, &order1);
  const auto seq1_again = traversal(pts, 1.2, 1, &order2);
  EXPECT_EQ(order1, order2);
  EXPECT_EQ(seq1, seq1_again);
  const auto seq2 = traversal(pts, 1.2, 2, &order2);
  const auto seq4 = traversal(pts, 1.2, 4, &order4);
  EXPECT_EQ(order1, order2);
  EXPECT_EQ(order1, order4);
  EXPECT_EQ(seq1, seq2);
  EXPECT_EQ(seq1, seq4);
  EXPECT_FALSE(seq1.empty());
}

template <int D>
void expect_cell_ranges_hold_their_cells(const Points<D>& pts, double cell_size) {
  CellGrid<D> grid;
  grid.build(pts.x.data(), pts.x.size(), cell_size);
  const auto& order = grid.order();
  const auto& start = grid.cell_start();
  const std::size_t n = pts.x.size();
  ASSERT_EQ(order.size(), n);
  ASSERT_EQ(start.size(), grid.cell_count() + 1);
  // order() is a permutation.
  std::vector<std::uint32_t> sorted_order = order;
  std::sort(sorted_order.begin(), sorted_order.end());
  for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(sorted_order[k], k);
  // The ranges partition [0, n) ...
  EXPECT_EQ(start.front(), 0u);
  EXPECT_EQ(start.back(), n);
  EXPECT_TRUE(std::is_sorted(start.begin(), start.end()));
  // ... and range c holds exactly the particles with cell_of() == c, in their original order (stable).
  for (std::size_t c = 0; c < grid.cell_count(); ++c) {
    for (std::uint32_t k = start[c]; k < start[c + 1]; ++k) {
      ASSERT_EQ(grid.cell_of(pts.x[order[k]]), c) << "particle " << order[k] << " in the range of cell " << c;
      if (k > start[c]) {
        ASSERT_LT(order[k - 1], order[k]) << "cell " << c << " is not in original order";
      }
    }
  }
}

TEST(CellGrid, CellRangesContainExactlyTheParticlesOfTheirCell) {
  expect_cell_ranges_hold_their_cells(random_points<2>(scaled(50000), 100.0, 0.5, 15), 1.0);
  expect_cell_ranges_hold_their_cells(lattice<2>(100, 0.3, 0.15, -1.0), 0.3);
  expect_cell_ranges_hold_their_cells(random_points<3>(scaled(20000), 20.0, 0.5, 16), 1.0);
  expect_cell_ranges_hold_their_cells(random_points<2>(1, 1.0, 0.5, 17), 1.0);
}

TEST(CellGrid, BuildRejectsInvalidCellSizeAndNonFinitePositions) {
  CellGrid<2> grid;
  const std::vector<Vec<2>> x{Vec<2>{0.0, 0.0}, Vec<2>{1.0, 1.0}};
  EXPECT_THROW(grid.build(x.data(), x.size(), 0.0), std::invalid_argument);
  EXPECT_THROW(grid.build(x.data(), x.size(), -1.0), std::invalid_argument);
  EXPECT_THROW(grid.build(x.data(), x.size(), std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_THROW(grid.build(x.data(), x.size(), std::numeric_limits<double>::infinity()),
               std::invalid_argument);
  const std::vector<Vec<2>> bad{Vec<2>{0.0, 0.0}, Vec<2>{std::numeric_limits<double>::quiet_NaN(), 1.0}};
  EXPECT_THROW(grid.build(bad.data(), bad.size(), 1.0), std::runtime_error);
  const std::vector<Vec<2>> inf{Vec<2>{0.0, 0.0}, Vec<2>{std::numeric_limits<double>::infinity(), 1.0}};
  EXPECT_THROW(grid.build(inf.data(), inf.size(), 1.0), std::runtime_error);
}

}  // namespace
}  // namespace sph
