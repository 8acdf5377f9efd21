// Coarsening with buffered levels (effects.refinement.coarsening with coupling = "buffered", retract_buffered in
// core/refinement/buffer.hpp): a refined region that calms returns to the set-up's particles, and the grid query the
// buffered passes use against a brute-force loop. The flips test for both couplings is in test_coarsening.cpp.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include "core/case_builder.hpp"
#include "core/refinement/family.hpp"
#include "core/refinement/points.hpp"
#include "core/refinement/refinement_stage.hpp"

namespace {

using namespace sph;

// Coarsening with buffered levels (retract_buffered), on the still tank, as
// Coarsening.ARegionThatStopsBeingRefinedReturnsToTheOriginalParticles does it with mixed pairs: a block given 2 m/s
// is split twice (velocity criterion, threshold 1 m/s, two levels), and the splits give it a band; then every active
// particle is given a speed below the merge threshold (0.5 m/s) that varies from place to place, and after the hold
// (0.3 s) the level-2 families merge into their shadows, then the level-1 ones, and every band goes. The store is the
// set-up's again: the same ids, every particle active, each at its set-up place (a family's centre of mass is its
// parent's place up to the rounding of four offsets) with its mass. No step is taken between the passes, so each
// pass is seen alone. At every pass no particle is left without its parent, a shadow has its whole family, the active
// fluid's mass is exact (m / 4 four times) and its momentum kept to rounding (sums of a few hundred terms: 1e-12 of
// sum |m v|). The store after the first merges is bitwise the same at one and two threads.
struct RetractCase {
  const char* name;
  Vec<2> lo, hi;
  refine::Pattern pattern;
};

class BufferedCoarsening : public ::testing::TestWithParam<RetractCase> {};

void expect_families_whole(const ParticleStore<2>& s) {
  std::vector<ParticleId> ids;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.kind[i] == Kind::fluid) ids.push_back(s.id[i]);
  std::sort(ids.begin(), ids.end());
  const auto present = [&](ParticleId id) { return std::binary_search(ids.begin(), ids.end(), id); };
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    if (refine::has_parent(s.id[i])) {
      EXPECT_TRUE(present(refine::parent_id(s.id[i]))) << "orphan " << s.id[i];
    }
    if (s.role[i] == Role::shadow) {
      for (unsigned a = 0; a < refine::kChildren<2>; ++a)
        EXPECT_TRUE(present(refine::daughter_id(s.id[i], a))) << "shadow " << s.id[i] << " without daughter " << a;
    }
  }
}

TEST_P(BufferedCoarsening, ARegionThatStopsBeingRefinedReturnsToTheOriginalParticles) {
  const RetractCase& c = GetParam();
  refine::RefinementSettings rs;
  rs.criterion = refine::CriterionKind::velocity;
  rs.v_threshold = 1.0;
  rs.check_interval = 1;
  rs.max_level = 2;
  rs.pattern = c.pattern;
  rs.coupling = LevelCoupling::buffered;
  rs.coarsening = refine::CoarseningSettings{0.5, 16, 0.3};
  const Box2 block{c.lo, c.hi};
  const int threads = omp_get_max_threads();
  std::vector<ParticleStore<2>> after_first_merges;
  for (const int nt : {1, 2}) {
    omp_set_num_threads(nt);
    Simulation sim = make_still_tank(TankSpec{});
    refine::RefinementStage& stage = refine::add_refinement_stage(sim, rs);
    const ParticleStore<2> original = sim.store();
    auto& s = sim.store();
    std::size_t original_fluid = 0;
    for (std::size_t i = 0; i < s.size(); ++i) original_fluid += s.kind[i] == Kind::fluid ? 1 : 0;
    const auto active = [&](std::size_t i) { return s.kind[i] == Kind::fluid && !is_passive(s.role[i]); };
    const auto active_count = [&] {
      std::size_t k = 0;
      for (std::size_t i = 0; i < s.size(); ++i) k += active(i) ? 1 : 0;
      return k;
    };
    const auto set_block = [&] {
      for (std::size_t i = 0; i < s.size(); ++i)
        if (active(i) && block.contains(s.x[i])) s.v[i] = s.vh[i] = Vec<2>(2.0, 0.0);
    };
    const auto set_slow = [&] {  // below the merge threshold everywhere, different from place to place
      for (std::size_t i = 0; i < s.size(); ++i)
        if (active(i)) s.v[i] = s.vh[i] = 0.3 * Vec<2>(std::sin(0.7 * s.x[i][0]), std::cos(0.5 * s.x[i][1]));
    };
    const auto pass = [&](double time, std::uint64_t step) {
      double m0 = 0.0, m1 = 0.0, scale = 0.0;
      Vec<2> p0 = Vec<2>::Zero(), p1 = Vec<2>::Zero();
      for (std::size_t i = 0; i < s.size(); ++i) {
        if (!active(i)) continue;
        m0 += s.m[i];
        p0 += s.m[i] * s.v[i];
        scale += s.m[i] * s.v[i].norm();
      }
      sim.set_clock(time, step, sim.dt());
      sim.run_stages();
      for (std::size_t i = 0; i < s.size(); ++i) {
        if (!active(i)) continue;
        m1 += s.m[i];
        p1 += s.m[i] * s.v[i];
      }
      // m / 4 four times is exact, but the sum runs over another set in another order: a few hundred terms.
      EXPECT_NEAR(m1, m0, 1e-13 * m0) << "t = " << time;
      EXPECT_LE((p1 - p0).norm(), 1e-12 * scale) << "t = " << time;
      expect_families_whole(s);
    };
    set_block();
    pass(0.0, 0);  // level 0 -> 1
    set_block();
    pass(0.1, 1);  // level 1 -> 2
    const std::size_t refined = active_count();
    ASSERT_GT(refined, original_fluid + 3 * 16 * 3);
    set_slow();
    pass(0.2, 2);
    EXPECT_EQ(active_count(), refined) << "held: the level-2 daughters were born 0.1 s ago";
    set_slow();
    pass(0.41, 3);  // level 2 -> 1: those born at 0.1 s
    EXPECT_LT(active_count(), refined);
    EXPECT_GT(active_count(), original_fluid) << "the merged level-1 particles are held again";
    after_first_merges.push_back(s);
    set_slow();
    pass(0.72, 4);  // level 1 -> 0, and the bands go
    ASSERT_EQ(s.size(), original.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      ASSERT_EQ(s.id[i], original.id[i]) << i;
      EXPECT_EQ(s.role[i], Role::active) << i;
      EXPECT_EQ(s.m[i], original.m[i]) << i;
      EXPECT_EQ(s.level[i], original.level[i]) << i;
      EXPECT_LE((s.x[i] - original.x[i]).norm(), 1e-12 * 25.0) << i << " (a tank 25 m wide)";
    }
    EXPECT_EQ(stage.total_merged(), (refined - original_fluid) / 3);
  }
  omp_set_num_threads(threads);
  const ParticleStore<2>& a = after_first_merges[0];
  const ParticleStore<2>& b = after_first_merges[1];
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.id[i], b.id[i]) << i;
    EXPECT_EQ(a.x[i], b.x[i]) << i;
    EXPECT_EQ(a.v[i], b.v[i]) << i;
    EXPECT_EQ(a.rho[i], b.rho[i]) << i;
    EXPECT_EQ(a.role[i], b.role[i]) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Blocks, BufferedCoarsening,
                         ::testing::Values(RetractCase{"bulk_aap", Vec<2>(8, 2), Vec<2>(14, 6), refine::Pattern::aap},
                                           RetractCase{"wall_aap", Vec<2>(0, 3), Vec<2>(4, 7), refine::Pattern::aap},
                                           RetractCase{"corner_rsp", Vec<2>(0, 0), Vec<2>(5, 4), refine::Pattern::rsp}),
                         [](const auto& p) { return std::string(p.param.name); });

// The grid query of the buffered levels' passes (refine::detail::Points::near) against a loop over every point:
// random points in a 10 m square, queried at random places with reaches up to the cells' edge. Both sides compare
// the same squared distances with the same reach, so they agree exactly.
TEST(BufferedPoints, NearAgreesWithABruteForceLoop) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> place(0.0, 10.0), unit(0.0, 1.0);
  std::vector<Vec<2>> x;
  refine::detail::Points<2> points;
  for (int k = 0; k < 400; ++k) {
    x.emplace_back(place(rng), place(rng));
    points.add(x.back());
  }
  const double edge = 0.5;
  points.sort(edge);
  int hits = 0;
  for (int q = 0; q < 2000; ++q) {
    const Vec<2> p(place(rng), place(rng));
    const double reach = edge * unit(rng);
    bool near = false;
    for (const Vec<2>& xj : x) near = near || (xj - p).squaredNorm() < reach * reach;
    EXPECT_EQ(points.near(p, reach), near) << q;
    hits += near;
  }
  // Both answers occur often (4 points per m^2, reaches of 0-0.5 m: about one point in reach on average), so the
  // comparison tests something.
  EXPECT_GT(hits, 200);
  EXPECT_LT(hits, 1800);
}

}  // namespace
