#pragma once
// How many threads a run uses when the user does not say. Results do not depend on it (every primitive in
// parallel/ is thread-count independent), only speed does.
//
// The rule: one thread per kMinItemsPerThread fluid particles, at least one, at most the threads available
// (OMP_NUM_THREADS, or the processors). A thread with fewer particles than that spends more time at the
// step's barriers than in its share of the work, and on cores busy with other work every barrier can cost a
// scheduler time slice: the paper's 900-particle dam break took 36 s instead of 2 s on two busy cores with
// two threads. kMinItemsPerThread is kChunk, the unit a reduction or scan hands to a thread: with fewer items
// than that per thread, a reduction has no chunk for some threads anyway.
#include <algorithm>
#include <cstddef>

#include "parallel/parallel_for.hpp"

namespace sph::par {

inline constexpr std::size_t kMinItemsPerThread = kChunk;

/// Threads for n items with at most `available` threads: n / kMinItemsPerThread, clamped to [1, available].
inline int threads_for(std::size_t n, int available) {
  const std::size_t by_work = n / kMinItemsPerThread;
  return static_cast<int>(std::clamp<std::size_t>(by_work, 1, static_cast<std::size_t>(std::max(1, available))));
}

}  // namespace sph::par
