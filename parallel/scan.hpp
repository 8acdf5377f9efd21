#pragma once
// Blocked exclusive prefix sum: per-chunk totals in parallel, a serial scan of the chunk totals, then each
// chunk writes its own offsets, all in one parallel region. Chunk boundaries are fixed, so the result is the same at any thread count.
#include <cstddef>
#include <vector>

#include "parallel/parallel_for.hpp"

namespace sph::par {

/// out[i] = sum_{k<i} in[k]; returns the grand total. `out` may alias `in`. Works for n = 0.
/// The scan's three phases for a team already inside a parallel region (orphaned worksharing: every thread of
/// the team calls it): chunk totals, their serial scan by one thread, then each chunk's offsets. `total` is
/// shared, with chunk_count(n) + 1 entries, total[0] = 0; total[chunks] is the grand total afterwards.
template <class T>
void team_exclusive_scan(const T* in, T* out, std::size_t n, T* total) {
  const std::size_t chunks = chunk_count(n);
  const auto count = static_cast<std::ptrdiff_t>(chunks);
#pragma omp for schedule(static)
  for (std::ptrdiff_t c = 0; c < count; ++c) {
    T acc{};
    const std::size_t end = std::min(n, (static_cast<std::size_t>(c) + 1) * kChunk);
    for (std::size_t i = static_cast<std::size_t>(c) * kChunk; i < end; ++i) acc += in[i];
    total[static_cast<std::size_t>(c) + 1] = acc;
  }
#pragma omp single
  for (std::size_t c = 0; c < chunks; ++c) total[c + 1] += total[c];
#pragma omp for schedule(static)
  for (std::ptrdiff_t c = 0; c < count; ++c) {
    T acc = total[static_cast<std::size_t>(c)];
    const std::size_t end = std::min(n, (static_cast<std::size_t>(c) + 1) * kChunk);
    for (std::size_t i = static_cast<std::size_t>(c) * kChunk; i < end; ++i) {
      const T v = in[i];
      out[i] = acc;
      acc += v;
    }
  }
}

template <class T>
T exclusive_scan(const T* in, T* out, std::size_t n) {
  const std::size_t chunks = chunk_count(n);
  // Per calling thread and T, reused: no allocation once sizes settle. Bound to a reference so that the
  // workers see the calling thread's buffer (a thread_local is not captured).
  thread_local std::vector<T> buffer;
  std::vector<T>& total = buffer;
  total.assign(chunks + 1, T{});
  T* t = total.data();
  // One parallel region (each costs a fork and a join); none for one chunk or one thread, where the orphaned
  // worksharing runs on the calling thread alone.
  if (serial(chunks)) {
    team_exclusive_scan(in, out, n, t);
  } else {
#pragma omp parallel
    team_exclusive_scan(in, out, n, t);
  }
  return total[chunks];
}

/// Vector form: returns offsets of size n + 1 (the last entry is the total).
template <class T>
std::vector<T> exclusive_scan(const std::vector<T>& in) {
  std::vector<T> out(in.size() + 1);
  out[in.size()] = exclusive_scan(in.data(), out.data(), in.size());
  return out;
}

}  // namespace sph::par
