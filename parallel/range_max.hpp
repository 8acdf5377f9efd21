#pragma once
// The largest value over any index range [b, e) of an array, in constant time: a sparse table whose level k holds
// the maxima of the windows of 2^k entries (level 0 is the array). A range is covered by two windows of the largest
// power of two that fits in it. Built in O(n log n), level by level, each level in parallel; max is exact, so the
// table is the same at any thread count.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "parallel/parallel_for.hpp"

namespace sph::par {

template <class T>
class RangeMax {
 public:
  /// Level 0 from value(i), i = 0 .. n - 1; the workspace is reused from build to build.
  template <class F>
  void build(std::size_t n, F&& value) {
    n_ = n;
    levels_ = n == 0 ? 0 : std::bit_width(n);
    table_.resize(static_cast<std::size_t>(levels_) * n);
    if (n == 0) return;
    T* t = table_.data();
    parallel_for(n, [&](std::size_t i) { t[i] = value(i); });
    for (int k = 1; k < levels_; ++k) {
      const std::size_t half = std::size_t{1} << (k - 1);
      const std::size_t width = std::size_t{1} << k;
      const T* prev = t + static_cast<std::size_t>(k - 1) * n;
      T* cur = t + static_cast<std::size_t>(k) * n;
      parallel_for(n - width + 1, [&](std::size_t i) { cur[i] = std::max(prev[i], prev[i + half]); });
    }
  }

  /// The largest of entries b .. e - 1 (b < e <= n).
  T max(std::size_t b, std::size_t e) const {
    const int k = std::bit_width(e - b) - 1;
    const T* level = table_.data() + static_cast<std::size_t>(k) * n_;
    return std::max(level[b], level[e - (std::size_t{1} << k)]);
  }

  std::size_t size() const { return n_; }

 private:
  std::size_t n_ = 0;
  int levels_ = 0;
  std::vector<T> table_;
};

}  // namespace sph::par
