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
  out.bucket_start.resize(buckets + 1);
  out.bucket_start[buckets] = static_cast<std::uint32_t>(n);
  out.order.resize(n);
  // The exclusive scan of the table (par::team_exclusive_scan, inside this function's region).
  const std::size_t table = scratch.size();
  const std::size_t blocks = chunk_count(table);
  thread_local std::vector<std::uint32_t> block_total_buffer;  // reused; see par::reduce for the reference
  std::vector<std::uint32_t>& block_total = block_total_buffer;
  block_total.assign(blocks + 1, 0);
  const auto n_chunks = static_cast<std::ptrdiff_t>(chunks);
  const auto n_buckets = static_cast<std::ptrdiff_t>(buckets);
  std::uint32_t* t = scratch.data();
  // One parallel region for the whole sort (each region costs a fork and a join); the worksharing loops'
  // barriers order the phases: histogram, scan of the table (block totals, their serial scan, offsets),
  // bucket starts, stable scatter. With one thread, or one chunk and one block of the table, no region: the
  // orphaned worksharing runs on the calling thread alone.
  const auto phases = [&] {
#pragma omp for schedule(dynamic, 1)
    for (std::ptrdiff_t c = 0; c < n_chunks; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      const std::size_t end = std::min(n, (cc + 1) * chunk);
      for (std::size_t i = cc * chunk; i < end; ++i) {
        const auto k = static_cast<std::uint32_t>(key(i));
        keys[i] = k;
        ++t[k * chunks + cc];
      }
    }
    team_exclusive_scan(t, t, table, block_total.data());
#pragma omp for schedule(static)
    for (std::ptrdiff_t b = 0; b < n_buckets; ++b) {
      out.bucket_start[static_cast<std::size_t>(b)] = chunks ? t[static_cast<std::size_t>(b) * chunks] : 0;
    }
#pragma omp for schedule(dynamic, 1)
    for (std::ptrdiff_t c = 0; c < n_chunks; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      const std::size_t end = std::min(n, (cc + 1) * chunk);
      for (std::size_t i = cc * chunk; i < end; ++i) out.order[t[keys[i] * chunks + cc]++] = static_cast<std::uint32_t>(i);
    }
  };
  if (serial(std::max(chunks, blocks))) {
    phases();
  } else {
#pragma omp parallel
    phases();
  }
}

template <class Key>
CountingSortResult counting_sort(std::size_t n, std::size_t buckets, Key&& key) {
  CountingSortResult r;
  std::vector<std::uint32_t> scratch;
  counting_sort(n, buckets, std::forward<Key>(key), r, scratch);
  return r;
}

}  // namespace sph::par
