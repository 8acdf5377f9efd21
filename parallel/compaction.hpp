#pragma once
// Stream compaction and expansion: per-item output counts (0..k) -> exclusive scan -> offsets -> write.
// Output order follows input order, so results are identical at any thread count.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "parallel/parallel_for.hpp"
#include "parallel/scan.hpp"

namespace sph::par {

/// Offsets of a stream expansion: item i writes count(i) outputs starting at offsets[i];
/// offsets has n + 1 entries and offsets[n] is the total output size.
template <class Count>
std::vector<std::uint32_t> expansion_offsets(std::size_t n, Count&& count) {
  std::vector<std::uint32_t> offsets(n + 1);
  parallel_for(n, [&](std::size_t i) { offsets[i] = static_cast<std::uint32_t>(count(i)); });
  offsets[n] = exclusive_scan(offsets.data(), offsets.data(), n);
  return offsets;
}

/// Stream expansion as a source map: returns src of size total where the outputs of item i are
/// src[offsets[i] .. offsets[i+1]) = i. Callers gather every field through it, then adjust the copies.
template <class Count>
std::vector<std::uint32_t> expansion_map(std::size_t n, Count&& count, std::vector<std::uint32_t>* offsets_out = nullptr) {
  std::vector<std::uint32_t> offsets = expansion_offsets(n, std::forward<Count>(count));
  std::vector<std::uint32_t> src(offsets[n]);
  parallel_for(n, [&](std::size_t i) {
    for (std::uint32_t k = offsets[i]; k < offsets[i + 1]; ++k) src[k] = static_cast<std::uint32_t>(i);
  });
  if (offsets_out) *offsets_out = std::move(offsets);
  return src;
}

/// Stream compaction: the indices i in [0, n) with keep(i), in increasing order.
template <class Keep>
std::vector<std::uint32_t> compaction_map(std::size_t n, Keep&& keep) {
  return expansion_map(n, [&](std::size_t i) { return keep(i) ? 1u : 0u; });
}

}  // namespace sph::par
