#pragma once
// The partition of space between the ranks (issue #19): Zoltan's recursive coordinate bisection (RCB) over weighted
// points, kept as its cut tree so that any point, not only the ones it was given, has an owner, the same on every
// rank. In one process every point is rank 0's. Zoltan (Trilinos) is used through its C API in the MPI build only.
#include <cstdint>
#include <memory>
#include <vector>

#include "parallel/comm.hpp"

namespace sph::par {

class Partition {
 public:
  explicit Partition(const Comm& comm);
  ~Partition();
  Partition(const Partition&) = delete;
  Partition& operator=(const Partition&) = delete;

  /// Cuts space so that each rank's share of the points' weights is as equal as RCB makes it. Collective: every
  /// rank passes its own points (dim coordinates each, in `coords`) and weights; a point is passed by one rank.
  void cut(int dim, const std::vector<double>& coords, const std::vector<double>& weights);
  /// The rank that owns the point (dim coordinates), from the cuts of the last cut(); 0 before any.
  int owner(const double* point) const;

  struct Zoltan;  // Zoltan's handle and the points of a cut() for its callbacks (MPI build)

 private:
  [[maybe_unused]] const Comm& comm_;  // used by the MPI build only
  std::unique_ptr<Zoltan> zoltan_;
  bool cut_ = false;
};

}  // namespace sph::par
