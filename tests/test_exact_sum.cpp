// par::ExactSum (parallel/exact_sum.hpp): the exact sum of doubles rounded once. Checked against hand-derived
// roundings, against an exact integer twin where the numbers allow one, and for its point: the same bits in any
// order and any split into merged partial sums.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "parallel/exact_sum.hpp"

namespace {

using sph::par::ExactSum;

double exact(const std::vector<double>& xs) {
  ExactSum s;
  for (double x : xs) s.add(x);
  return s.value();
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(ExactSum, CancellationLeavesTheSmallTerm) {
  // 1e16 + 1 - 1e16: plain left-to-right addition loses the 1 (the spacing of doubles at 1e16 is 2).
  EXPECT_EQ(exact({1e16, 1.0, -1e16}), 1.0);
  EXPECT_EQ(exact({1e308, 1e308, -1e308}), 1e308);  // no overflow on the way
  EXPECT_EQ(exact({std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min()}), 0.0);
  EXPECT_EQ(exact({3.0 * std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min()}),
            2.0 * std::numeric_limits<double>::denorm_min());  // subnormal results are exact
  EXPECT_EQ(exact({}), 0.0);
}

TEST(ExactSum, RoundsOnceToNearestWithTiesToEven) {
  const double u = std::ldexp(1.0, -52);  // the spacing of doubles in [1, 2)
  // 1 + u/2 lies halfway between 1 and 1 + u: ties to even gives 1 (mantissa even).
  EXPECT_EQ(exact({1.0, u / 2}), 1.0);
  // Anything above the halfway point, however far below it, rounds up: the sticky bit.
  EXPECT_EQ(exact({1.0, u / 2, std::ldexp(1.0, -200)}), 1.0 + u);
  EXPECT_EQ(exact({1.0, u / 2, -std::ldexp(1.0, -200)}), 1.0);
  // 1 + u + u/2 is halfway between 1 + u (odd) and 1 + 2u (even): up.
  EXPECT_EQ(exact({1.0 + u, u / 2}), 1.0 + 2 * u);
  // The same on the negative side.
  EXPECT_EQ(exact({-1.0 - u, -u / 2}), -1.0 - 2 * u);
  // Past the largest double: infinity, as the rounding of the exact sum says.
  EXPECT_EQ(exact({std::numeric_limits<double>::max(), std::numeric_limits<double>::max()}),
            std::numeric_limits<double>::infinity());
}

TEST(ExactSum, InfinitiesAndNaNDominateAsInPlainAddition) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(exact({1.0, inf, 2.0}), inf);
  EXPECT_EQ(exact({1.0, -inf}), -inf);
  EXPECT_TRUE(std::isnan(exact({inf, -inf})));
  EXPECT_TRUE(std::isnan(exact({1.0, std::numeric_limits<double>::quiet_NaN()})));
}

TEST(ExactSum, EqualsAnExactIntegerTwin) {
  // Multiples of 2^-40 with |k| < 2^50: 2000 of them sum exactly in a 128-bit integer, whose conversion to double
  // rounds to nearest (ties to even); scaling by 2^-40 is exact. Values from 2^-40 to 2^10, both signs.
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> xs;
    sph::par::Int128 total = 0;
    for (int k = 0; k < 2000; ++k) {
      const int bits = static_cast<int>(rng() % 50);
      auto q = static_cast<std::int64_t>(rng() >> (64 - bits - 1)) * ((rng() & 1u) ? 1 : -1);
      if (bits == 0) q = (rng() & 1u) ? 1 : -1;
      total += q;
      xs.push_back(std::ldexp(static_cast<double>(q), -40));
    }
    const double twin = std::ldexp(static_cast<double>(total), -40);
    ASSERT_TRUE(same_bits(exact(xs), twin)) << "trial " << trial << ": " << exact(xs) << " vs " << twin;
  }
}

TEST(ExactSum, SameBitsInAnyOrderAndAnySplit) {
  // Values over the whole range of exponents, both signs: summed in shuffled orders, and in parts merged in
  // another order, the result is one and the same double.
  std::mt19937_64 rng(11);
  std::vector<double> xs;
  for (int k = 0; k < 5000; ++k) {
    double x = std::ldexp(std::uniform_real_distribution<double>(0.5, 1.0)(rng),
                          std::uniform_int_distribution<int>(-1070, 1000)(rng));
    xs.push_back((rng() & 1u) ? x : -x);
  }
  const double reference = exact(xs);
  double plain = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    std::shuffle(xs.begin(), xs.end(), rng);
    EXPECT_TRUE(same_bits(exact(xs), reference)) << "order " << trial;
    // Split into 1..8 parts at random cuts, each summed alone, merged last to first.
    const std::size_t parts = 1 + rng() % 8;
    std::vector<std::size_t> cut{0, xs.size()};
    for (std::size_t p = 1; p < parts; ++p) cut.push_back(rng() % xs.size());
    std::sort(cut.begin(), cut.end());
    std::vector<ExactSum> partial(cut.size() - 1);
    for (std::size_t p = 0; p + 1 < cut.size(); ++p)
      for (std::size_t i = cut[p]; i < cut[p + 1]; ++i) partial[p].add(xs[i]);
    ExactSum merged;
    for (std::size_t p = partial.size(); p-- > 0;) merged.merge(partial[p]);
    EXPECT_TRUE(same_bits(merged.value(), reference)) << "split " << trial << " into " << parts;
    if (trial == 0) plain = std::accumulate(xs.begin(), xs.end(), 0.0);
  }
  // Not a trivial set: plain summation of it depends on the order.
  std::shuffle(xs.begin(), xs.end(), rng);
  EXPECT_FALSE(same_bits(std::accumulate(xs.begin(), xs.end(), 0.0), plain) &&
               same_bits(std::accumulate(xs.rbegin(), xs.rend(), 0.0), plain));
}

TEST(ExactSum, ItsPartsRestoreItExactly) {
  // A checkpoint keeps the parts; a resumed run adds them to an empty sum and must go on as the uninterrupted
  // one: the same value after the same later additions.
  std::mt19937_64 rng(13);
  ExactSum s;
  for (int k = 0; k < 1000; ++k) s.add(std::ldexp(std::uniform_real_distribution<double>(0.5, 1.0)(rng),
                                                 std::uniform_int_distribution<int>(-60, 60)(rng)));
  const std::vector<double> parts = s.parts();
  ASSERT_GE(parts.size(), 2u) << "a sum that one double cannot hold";
  ExactSum restored;
  for (double p : parts) restored.add(p);
  EXPECT_EQ(restored.parts(), parts);
  for (int k = 0; k < 100; ++k) {
    const double x = std::ldexp(1.0, -70 - k);
    s.add(x);
    restored.add(x);
  }
  EXPECT_TRUE(same_bits(restored.value(), s.value()));
  EXPECT_EQ(restored.parts(), s.parts());
  EXPECT_TRUE(ExactSum{}.parts().empty());
}

}  // namespace
