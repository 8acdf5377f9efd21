#pragma once
// Stable parallel counting sort by small integer keys: per-chunk histograms, one exclusive scan over
// (key, chunk) in key-major order, then a stable scatter. The output permutation is unique (stable), so
// it is the same at any thread count.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "parallel/parallel_for.hpp"
#include "parallel/scan.hpp"

namespace sph::par {

/// Result of a counting sort: `order[k]` is the source index of the k-th item in sorted order, and
/// `bucket_start[b]` .. `bucket_start[b+1]` is the range of bucket b in that order (size buckets + 1).
struct CountingSortResult {
  std::vector<std::uint32_t> order;
  std::vector<std::uint32_t> bucket_start;
};

/// Sorts indices 0..n-1 by key(i) in [0, buckets), stable. Reuses `out`'s storage.
template <class Key>
void counting_sort(std::size_t n, std::size_t buckets, Key&& key, CountingSortResult& out,
                   std::vector<std::uint32_t>& scratch) {
  // Few large chunks keep the histogram table small: (chunks x buckets) counters.
  const std::size_t chunk = std::max<std::size_t>(kChunk * 16, (n + 63) / 64);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  scratch.assign(chunks * buckets, 0);  // layout: [bucket][chunk]
  std::vector<std::uint32_t> keys(n);
  parallel_for_dynamic(chunks, 1, [&](std::size_t c) {
    const std::size_t end = std::min(n, (c + 1) * chunk);
    for (std::size_t i = c * chunk; i < end; ++i) {
      const auto k = static_cast<std::uint32_t>(key(i));
      keys[i] = k;
      ++scratch[k * chunks + c];
    }
  });
  out.bucket_start.assign(buckets + 1, 0);
  exclusive_scan(scratch.data(), scratch.data(), scratch.size());
  parallel_for(buckets, [&](std::size_t b) {
    out.bucket_start[b] = chunks ? scratch[b * chunks] : 0;
  });
  out.bucket_start[buckets] = static_cast<std::uint32_t>(n);
  out.order.resize(n);
  parallel_for_dynamic(chunks, 1, [&](std::size_t c) {
    const std::size_t end = std::min(n, (c + 1) * chunk);
    for (std::size_t i = c * chunk; i < end; ++i) {
      out.order[scratch[keys[i] * chunks + c]++] = static_cast<std::uint32_t>(i);
    }
  });
}

template <class Key>
CountingSortResult counting_sort(std::size_t n, std::size_t buckets, Key&& key) {
  CountingSortResult r;
  std::vector<std::uint32_t> scratch;
  counting_sort(n, buckets, std::forward<Key>(key), r, scratch);
  return r;
}

}  // namespace sph::par
