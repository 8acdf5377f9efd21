// The OpenMP building blocks equal a serial reference for sizes around the chunk boundaries and large
// sizes, at 1, 2 and 4 threads; floating-point results are bitwise identical at every thread count.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/thread_count.hpp"
#include "core/types.hpp"
#include "parallel/compaction.hpp"
#include "parallel/counting_sort.hpp"
#include "parallel/parallel_for.hpp"
#include "parallel/range_max.hpp"
#include "parallel/scan.hpp"
#include "parallel/threads.hpp"

namespace sph {
namespace {

using sph::test::ThreadCount;

constexpr int kThreadCounts[] = {1, 2, 4};

/// 0, 1, around one chunk (kChunk = 4096), odd sizes, and a large odd size.
std::vector<std::size_t> sizes() {
  return {0, 1, 2, 4095, 4096, 4097, 12345, 65537, 1000003};
}

std::string label(std::size_t n, int threads) {
  return "n = " + std::to_string(n) + ", threads = " + std::to_string(threads);
}

/// Deterministic pseudo-random values (splitmix64), cheap enough for a million items.
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
/// A double in [-1, 1) with a wide spread of magnitudes, so summation order changes the rounding.
double mixed_double(std::uint64_t i) {
  const double unit = static_cast<double>(mix(i) >> 11) * 0x1.0p-53;
  const double scale = static_cast<double>(std::uint64_t{1} << (mix(i + 77) % 40));
  return (2.0 * unit - 1.0) * scale;
}

std::uint64_t bits(double v) {
  return std::bit_cast<std::uint64_t>(v);
}

TEST(Parallel, ParallelForVisitsEveryIndexExactlyOnce) {
  for (const std::size_t n : sizes()) {
    for (const int t : kThreadCounts) {
      SCOPED_TRACE(label(n, t));
      const ThreadCount tc(t);
      std::vector<int> hits(n, 0);
      par::parallel_for(n, [&](std::size_t i) { ++hits[i]; });
      EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](int h) { return h == 1; }));
      std::vector<int> hits_dyn(n, 0);
      par::parallel_for_dynamic(n, 1000, [&](std::size_t i) { ++hits_dyn[i]; });
      EXPECT_TRUE(std::all_of(hits_dyn.begin(), hits_dyn.end(), [](int h) { return h == 1; }));
    }
  }
}

TEST(Parallel, ExclusiveScanEqualsSerialPrefixSum) {
  for (const std::size_t n : sizes()) {
    std::vector<std::uint32_t> in(n);
    for (std::size_t i = 0; i < n; ++i) in[i] = static_cast<std::uint32_t>(mix(i) % 10);
    std::vector<std::uint32_t> expected(n);
    std::uint32_t running = 0;
    for (std::size_t i = 0; i < n; ++i) {
      expected[i] = running;
      running += in[i];
    }
    for (const int t : kThreadCounts) {
      SCOPED_TRACE(label(n, t));
      const ThreadCount tc(t);
      std::vector<std::uint32_t> out(n, 12345u);
      EXPECT_EQ(par::exclusive_scan(in.data(), out.data(), n), running);
      EXPECT_EQ(out, expected);
      // In place (out aliases in).
      std::vector<std::uint32_t> inplace = in;
      EXPECT_EQ(par::exclusive_scan(inplace.data(), inplace.data(), n), running);
      EXPECT_EQ(inplace, expected);
      // Vector form: n + 1 offsets, the last is the total.
      const std::vector<std::uint32_t> offsets = par::exclusive_scan(in);
      ASSERT_EQ(offsets.size(), n + 1);
      EXPECT_TRUE(std::equal(expected.begin(), expected.end(), offsets.begin()));
      EXPECT_EQ(offsets[n], running);
    }
  }
}

TEST(Parallel, ExclusiveScanOfDoublesIsBitwiseIdenticalAtAnyThreadCount) {
  for (const std::size_t n : sizes()) {
    std::vector<double> in(n);
    for (std::size_t i = 0; i < n; ++i) in[i] = mixed_double(i);
    // The documented rounding: chunk totals summed from zero, chunk offsets accumulated serially, then each
    // chunk runs on from its offset.
    const std::size_t chunks = par::chunk_count(n);
    std::vector<double> offset(chunks + 1, 0.0);
    for (std::size_t c = 0; c < chunks; ++c) {
      double acc = 0.0;
      for (std::size_t i = c * par::kChunk; i < std::min(n, (c + 1) * par::kChunk); ++i) acc += in[i];
      offset[c + 1] = offset[c] + acc;
    }
    std::vector<double> expected(n);
    for (std::size_t c = 0; c < chunks; ++c) {
      double acc = offset[c];
      for (std::size_t i = c * par::kChunk; i < std::min(n, (c + 1) * par::kChunk); ++i) {
        expected[i] = acc;
        acc += in[i];
      }
    }
    for (const int t : kThreadCounts) {
      SCOPED_TRACE(label(n, t));
      const ThreadCount tc(t);
      std::vector<double> out(n);
      const double total = par::exclusive_scan(in.data(), out.data(), n);
      EXPECT_EQ(bits(total), bits(offset[chunks]));
      std::size_t differing = 0;
      for (std::size_t i = 0; i < n; ++i) differing += bits(out[i]) != bits(expected[i]) ? 1 : 0;
      EXPECT_EQ(differing, 0u);
    }
  }
}

/// Reference: std::stable_sort of the indices by key, and bucket starts from the counts.
par::CountingSortResult reference_sort(const std::vector<std::uint32_t>& keys, std::size_t buckets) {
  par::CountingSortResult r;
  r.order.assign(keys.size(), 0u);
  std::iota(r.order.begin(), r.order.end(), 0u);
  std::stable_sort(r.order.begin(), r.order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
  r.bucket_start.assign(buckets + 1, 0);
  for (const auto k : keys) ++r.bucket_start[k + 1];
  for (std::size_t b = 0; b < buckets; ++b) r.bucket_start[b + 1] += r.bucket_start[b];
  return r;
}

TEST(Parallel, CountingSortIsStableAndEqualsStdStableSort) {
  for (const std::size_t n : sizes()) {
    for (const std::size_t buckets : {std::size_t{1}, std::size_t{17}, std::size_t{5000}, n + 3}) {
      if (buckets > 100000) continue;  // bucket tables of (chunks x buckets) counters: keep them small
      std::vector<std::uint32_t> keys(n);
      for (std::size_t i = 0; i < n; ++i)
        keys[i] = static_cast<std::uint32_t>(mix(i + 1000 * buckets) % buckets);
      const par::CountingSortResult expected = reference_sort(keys, buckets);
      for (const int t : kThreadCounts) {
        SCOPED_TRACE(label(n, t) + ", buckets = " + std::to_string(buckets));
        const ThreadCount tc(t);
        const par::CountingSortResult got =
            par::counting_sort(n, buckets, [&](std::size_t i) { return keys[i]; });
        EXPECT_EQ(got.order, expected.order);
        EXPECT_EQ(got.bucket_start, expected.bucket_start);
      }
    }
  }
}

TEST(Parallel, CountingSortReusingBuffersEqualsAFreshSort) {
  // The overload that reuses `out` and `scratch`: shrinking and growing n and the bucket count.
  par::CountingSortResult out;
  std::vector<std::uint32_t> scratch;
  const std::pair<std::size_t, std::size_t> runs[] = {
      {200000, 300}, {5000, 7}, {0, 4}, {70000, 9000}, {1, 1}};
  for (const auto& [n, buckets] : runs) {
    SCOPED_TRACE("n = " + std::to_string(n) + ", buckets = " + std::to_string(buckets));
    std::vector<std::uint32_t> keys(n);
    for (std::size_t i = 0; i < n; ++i) keys[i] = static_cast<std::uint32_t>(mix(3 * i + n) % buckets);
    par::counting_sort(
        n, buckets, [&](std::size_t i) { return keys[i]; }, out, scratch);
    const par::CountingSortResult expected = reference_sort(keys, buckets);
    EXPECT_EQ(out.order, expected.order);
    EXPECT_EQ(out.bucket_start, expected.bucket_start);
  }
}

TEST(Parallel, ExpansionMapEqualsSerialExpansion) {
  for (const std::size_t n : sizes()) {
    auto count = [](std::size_t i) { return static_cast<std::uint32_t>(mix(i + 5) % 4); };  // 0..3 outputs
    std::vector<std::uint32_t> expected_src;
    std::vector<std::uint32_t> expected_offsets{0};
    for (std::size_t i = 0; i < n; ++i) {
      for (std::uint32_t k = 0; k < count(i); ++k) expected_src.push_back(static_cast<std::uint32_t>(i));
      expected_offsets.push_back(static_cast<std::uint32_t>(expected_src.size()));
    }
    for (const int t : kThreadCounts) {
      SCOPED_TRACE(label(n, t));
      const ThreadCount tc(t);
      std::vector<std::uint32_t> offsets;
      EXPECT_EQ(par::expansion_map(n, count, &offsets), expected_src);
      EXPECT_EQ(offsets, expected_offsets);
      EXPECT_EQ(par::expansion_offsets(n, count), expected_offsets);
    }
  }
}

TEST(Parallel, CompactionMapEqualsSerialFilter) {
  for (const std::size_t n : sizes()) {
    auto keep = [](std::size_t i) { return mix(i + 9) % 3 != 0; };
    std::vector<std::uint32_t> expected;
    for (std::size_t i = 0; i < n; ++i) {
      if (keep(i)) expected.push_back(static_cast<std::uint32_t>(i));
    }
    for (const int t : kThreadCounts) {
      SCOPED_TRACE(label(n, t));
      const ThreadCount tc(t);
      EXPECT_EQ(par::compaction_map(n, keep), expected);
      EXPECT_EQ(par::compaction_map(n, [](std::size_t) { return false; }).size(), 0u);
      EXPECT_EQ(par::compaction_map(n, [](std::size_t) { return true; }).size(), n);
    }
  }
}

TEST(Parallel, IntegerSumAndReduceEqualSerialReference) {
  for (const std::size_t n : sizes()) {
    std::uint64_t expected_sum = 0;
    std::uint64_t expected_max = 0;
    for (std::size_t i = 0; i < n; ++i) {
      expected_sum += mix(i) >> 20;
      expected_max = std::max(expected_max, mix(i));
    }
    // An associative but non-commutative combine: composition of affine maps x -> a x + b (mod 2^64),
    // so a reduction that combined chunks out of order would differ.
    using Affine = std::pair<std::uint64_t, std::uint64_t>;
    auto affine = [](std::size_t i) { return Affine{mix(i) | 1u, mix(i + 1)}; };
    auto compose = [](const Affine& f, const Affine& g) {  // first f, then g
      return Affine{g.first * f.first, g.first * f.second + g.second};
    };
    Affine expected_affine{1, 0};
    for (std::size_t i = 0; i < n; ++i) expected_affine = compose(expected_affine, affine(i));
    for (const int t : kThreadCounts) {
      SCOPED_TRACE(label(n, t));
      const ThreadCount tc(t);
      EXPECT_EQ(par::sum(n, std::uint64_t{0}, [](std::size_t i) { return mix(i) >> 20; }), expected_sum);
      EXPECT_EQ(par::reduce(
                    n, std::uint64_t{0}, [](std::size_t i) { return mix(i); },
                    [](std::uint64_t a, std::uint64_t b) { return std::max(a, b); }),
                expected_max);
      EXPECT_EQ(par::reduce(n, Affine{1, 0}, affine, compose), expected_affine);
    }
  }
}

TEST(Parallel, FloatingPointSumIsBitwiseIdenticalAtAnyThreadCount) {
  for (const std::size_t n : sizes()) {
    // The documented rounding: each chunk of kChunk items summed from zero in index order, then the chunk
    // sums added in chunk order.
    double expected = 0.0;
    Vec<2> expected_vec = Vec<2>::Zero();
    for (std::size_t c = 0; c < par::chunk_count(n); ++c) {
      double acc = 0.0;
      Vec<2> acc_vec = Vec<2>::Zero();
      for (std::size_t i = c * par::kChunk; i < std::min(n, (c + 1) * par::kChunk); ++i) {
        acc += mixed_double(i);
        acc_vec = Vec<2>(acc_vec + Vec<2>{mixed_double(i), mixed_double(i + n)});
      }
      expected += acc;
      expected_vec = Vec<2>(expected_vec + acc_vec);
    }
    std::vector<std::uint64_t> seen;
    for (const int t : kThreadCounts) {
      SCOPED_TRACE(label(n, t));
      const ThreadCount tc(t);
      const double s = par::sum(n, 0.0, [](std::size_t i) { return mixed_double(i); });
      EXPECT_EQ(bits(s), bits(expected)) << s << " vs " << expected;
      const double r = par::reduce(
          n, 0.0, [](std::size_t i) { return mixed_double(i); }, [](double a, double b) { return a + b; });
      EXPECT_EQ(bits(r), bits(expected));
      const Vec<2> v = par::sum(n, Vec<2>(Vec<2>::Zero()), [n](std::size_t i) {
        return Vec<2>{mixed_double(i), mixed_double(i + n)};
      });
      EXPECT_EQ(bits(v[0]), bits(expected_vec[0]));
      EXPECT_EQ(bits(v[1]), bits(expected_vec[1]));
      seen.push_back(bits(s));
    }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [&](std::uint64_t b) { return b == seen.front(); }));
  }
}

TEST(Parallel, FloatingPointSumDiffersFromNaiveOrderSoTheTestIsMeaningful) {
  // Guard for the test above: with these values the summation order does change the rounding, so bitwise
  // agreement across thread counts is a real property and not an accident of exact arithmetic.
  const std::size_t n = 1000003;
  double naive = 0.0;
  for (std::size_t i = n; i-- > 0;) naive += mixed_double(i);
  const double chunked = par::sum(n, 0.0, [](std::size_t i) { return mixed_double(i); });
  EXPECT_NE(bits(naive), bits(chunked));
}

// par::RangeMax (the bin limiter's pre-test) against its brute-force twin: the maximum over every range [b, e) of
// arrays whose lengths are and are not powers of two, including negative entries and ranges of one entry, after
// a rebuild of the same object with other values and another length.
TEST(Parallel, RangeMaxEqualsTheMaximumOverEveryRange) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> value(-1, 15);
  par::RangeMax<std::int8_t> table;
  for (const std::size_t n : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{64}, std::size_t{333}}) {
    std::vector<std::int8_t> a(n);
    for (auto& x : a) x = static_cast<std::int8_t>(value(rng));
    table.build(n, [&](std::size_t i) { return a[i]; });
    ASSERT_EQ(table.size(), n);
    for (std::size_t b = 0; b < n; ++b) {
      std::int8_t expect = a[b];
      for (std::size_t e = b + 1; e <= n; ++e) {
        expect = std::max(expect, a[e - 1]);
        ASSERT_EQ(table.max(b, e), expect) << "n " << n << " range [" << b << ", " << e << ")";
      }
    }
  }
}

}  // namespace
}  // namespace sph

// The default thread count: one thread per kMinItemsPerThread items, at least one, at most what is offered.
TEST(Parallel, ThreadsForTheWorkFollowTheRule) {
  EXPECT_EQ(sph::par::threads_for(0, 8), 1);
  EXPECT_EQ(sph::par::threads_for(900, 2), 1);  // the paper's dam break
  EXPECT_EQ(sph::par::threads_for(2 * sph::par::kMinItemsPerThread - 1, 8), 1);
  EXPECT_EQ(sph::par::threads_for(2 * sph::par::kMinItemsPerThread, 8), 2);
  EXPECT_EQ(sph::par::threads_for(1000000, 2), 2);
  EXPECT_EQ(sph::par::threads_for(1000000, 0), 1);  // nothing offered: still one
}
