#pragma once
// Stable parallel counting sort by small integer keys: per-chunk histograms, one exclusive scan over
// (key, chunk) in key-major order, then a stable scatter. The output permutation is unique (stable), so
// it is the same at any thread count; the chunking only has to keep it stable, so it follows the thread
// count (one chunk per thread): the histogram table is threads x buckets, not (n / chunk) x buckets.
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
  std::vector<std::uint32_t> keys;  // workspace: each item's key (kept to reuse its storage)
};

/// Sorts indices 0..n-1 by key(i) in [0, buckets), stable. Reuses `out`'s storage.
template <class Key>
void counting_sort(std::size_t n, std::size_t buckets, Key&& key, CountingSortResult& out,
                   std::vector<std::uint32_t>& scratch) {
  // One chunk per thread (at least kChunk items each) keeps the histogram table small: chunks x buckets.
  const std::size_t threads = static_cast<std::size_t>(std::max(1, max_threads()));
  const std::size_t chunk = std::max<std::size_t>(kChunk, (n + threads - 1) / threads);
  const std::size_t chunks = (n + chunk - 1) / chunk;
  scratch.assign(chunks * buckets, 0);  // layout: [bucket][chunk]
  auto& keys = out.keys;
  keys.resize(n);
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
