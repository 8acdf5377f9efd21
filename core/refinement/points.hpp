#pragma once
// Points sorted into a cell grid, for the buffered levels' "is any of these within reach" questions
// (core/refinement/buffer.cpp). tests/test_buffered_levels.cpp checks the query against a brute-force loop.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/cell_grid.hpp"
#include "core/types.hpp"

namespace sph::refine::detail {

/// Points sorted into the project's cell grid (one layer, cells of edge `edge`): near(x, reach) is true when a point
/// lies within reach <= edge of x.
template <int D>
class Points {
 public:
  void add(const Vec<D>& x) { x_.push_back(x); }
  bool empty() const { return x_.empty(); }
  void sort(double edge) {
    if (x_.empty()) return;
    // A query around p with "smoothing length" h reaches h + max_h: max_h = edge / 2, and near() asks h = reach - max_h.
    grid_.build(x_.data(), x_.size(), edge, 0.5 * edge);
    half_edge_ = 0.5 * edge;
  }
  bool near(const Vec<D>& x, double reach) const {
    if (x_.empty()) return false;
    bool found = false;
    const auto& order = grid_.order();
    grid_.for_each_support_run(x, reach - half_edge_, [&](std::uint32_t b, std::uint32_t e) {
      for (std::uint32_t k = b; k < e && !found; ++k) found = (x_[order[k]] - x).squaredNorm() < reach * reach;
    });
    return found;
  }

 private:
  std::vector<Vec<D>> x_;
  CellGrid<D> grid_;
  double half_edge_ = 0.0;
};

}  // namespace sph::refine::detail
