#pragma once
// OpenMP building blocks with serial semantics. Every result here is identical for any thread count:
// work is split into fixed-size chunks whose boundaries do not depend on the number of threads, and
// chunk results are combined in chunk order.
#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace sph::par {

/// Items per chunk for chunked reductions and scans; fixed so that rounding never depends on threads.
inline constexpr std::size_t kChunk = 4096;

inline int max_threads() { return omp_get_max_threads(); }

/// Whether a loop of `blocks` independent blocks runs on the calling thread alone: with one thread to run it, or one
/// block to share. A parallel region costs a fork and a join even for one thread (libgomp's team set-up: about 3 %
/// of a small per-level run, with its ten regions a substep), and every result here is the same either way.
inline bool serial(std::size_t blocks) { return blocks <= 1 || omp_get_max_threads() == 1 || omp_in_parallel(); }

/// Calls f(i) for i in [0, n) in parallel (static schedule). f must only write to item i's own data.
template <class F>
void parallel_for(std::size_t n, F&& f) {
  const auto count = static_cast<std::ptrdiff_t>(n);
  if (serial(n)) {
    for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
    return;
  }
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
}

/// Like parallel_for but with dynamic scheduling over blocks of `grain` items, for uneven work.
template <class F>
void parallel_for_dynamic(std::size_t n, std::size_t grain, F&& f) {
  const auto count = static_cast<std::ptrdiff_t>(n);
  const auto g = static_cast<std::ptrdiff_t>(std::max<std::size_t>(grain, 1));
  if (serial((n + static_cast<std::size_t>(g) - 1) / static_cast<std::size_t>(g))) {
    for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
    return;
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (std::ptrdiff_t b = 0; b < (count + g - 1) / g; ++b) {
    const std::ptrdiff_t end = std::min(count, (b + 1) * g);
    for (std::ptrdiff_t i = b * g; i < end; ++i) f(static_cast<std::size_t>(i));
  }
}

/// Number of fixed-size chunks covering n items.
inline std::size_t chunk_count(std::size_t n) { return (n + kChunk - 1) / kChunk; }

/// Deterministic parallel reduction: value = combine(...combine(init, chunk_0)..., chunk_last) where each
/// chunk folds map(i) over its items in index order starting from `identity`. Identical at any thread count.
template <class T, class Map, class Combine>
T reduce(std::size_t n, T identity, Map&& map, Combine&& combine) {
  const std::size_t chunks = chunk_count(n);
  // Per calling thread and per T, reused: a step reduces several times and should not allocate each time.
  // (reduce is not re-entered with the same T from inside its own map.)
  // The workers must see the calling thread's buffer: a lambda names a thread_local directly, not by capture.
  thread_local std::vector<T> buffer;
  std::vector<T>& partial = buffer;
  partial.assign(chunks, identity);
  parallel_for_dynamic(chunks, 1, [&](std::size_t c) {
    T acc = identity;
    const std::size_t end = std::min(n, (c + 1) * kChunk);
    for (std::size_t i = c * kChunk; i < end; ++i) acc = combine(acc, map(i));
    partial[c] = acc;
  });
  T result = identity;
  for (const T& p : partial) result = combine(result, p);
  return result;
}

/// reduce() for a large accumulator (an array of boxes, say) that each item updates in place rather than
/// combines whole: update(acc, i) folds item i into its chunk's acc, in index order; the chunks' results are
/// combined in chunk order. Identical at any thread count.
template <class T, class Update, class Combine>
T accumulate(std::size_t n, T identity, Update&& update, Combine&& combine) {
  const std::size_t chunks = chunk_count(n);
  thread_local std::vector<T> buffer;  // as in reduce
  std::vector<T>& partial = buffer;
  partial.assign(chunks, identity);
  parallel_for_dynamic(chunks, 1, [&](std::size_t c) {
    T acc = identity;
    const std::size_t end = std::min(n, (c + 1) * kChunk);
    for (std::size_t i = c * kChunk; i < end; ++i) update(acc, i);
    partial[c] = acc;
  });
  T result = identity;
  for (const T& p : partial) result = combine(result, p);
  return result;
}

/// Deterministic parallel sum of map(i).
template <class T, class Map>
T sum(std::size_t n, T zero, Map&& map) {
  return reduce(n, zero, std::forward<Map>(map), [](const T& a, const T& b) { return T(a + b); });
}

}  // namespace sph::par
