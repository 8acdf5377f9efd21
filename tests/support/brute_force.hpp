#pragma once
// O(N^2) reference neighbour sets for the tests: for particle i, every j != i with |x_i - x_j| < h_i + h_j
// (r < 2 h_ij, h_ij = (h_i + h_j) / 2). The test is evaluated exactly as CellGrid does it,
// (x_i - x_j).squaredNorm() < (h_i + h_j)^2, so that pairs at the support radius up to rounding are
// classified the same way by both. The criterion is symmetric, so only i < j is evaluated.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/types.hpp"

namespace sph::test {

/// Neighbour lists in index order: result[i] is the sorted list of j != i with r_ij < h_i + h_j.
template <int D>
std::vector<std::vector<std::uint32_t>> brute_force_neighbours(const std::vector<Vec<D>>& x,
                                                               const std::vector<double>& h) {
  if (x.size() != h.size()) throw std::invalid_argument("brute_force_neighbours: x and h differ in size");
  const std::size_t n = x.size();
  std::vector<std::vector<std::uint32_t>> nb(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const double r2 = (x[i] - x[j]).squaredNorm();
      const double support = h[i] + h[j];
      if (r2 < support * support) {
        nb[i].push_back(static_cast<std::uint32_t>(j));
        nb[j].push_back(static_cast<std::uint32_t>(i));
      }
    }
  }
  // nb[j] received i in increasing i; nb[i] received j in increasing j, after all smaller i: sorted.
  return nb;
}

/// Total number of directed pairs (i, j) in a neighbour list set.
inline std::size_t pair_count(const std::vector<std::vector<std::uint32_t>>& nb) {
  std::size_t total = 0;
  for (const auto& list : nb) total += list.size();
  return total;
}

}  // namespace sph::test
