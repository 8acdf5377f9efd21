#pragma once
// Solid walls (section 2.4): axis-aligned faces with a unit normal pointing into the fluid, in D = 2 (segments)
// or D = 3 (rectangles in planes). The container is an axis-aligned box, open at the top or closed, and the
// obstacles are boxes; "up" is the last axis (y in 2D, z in 3D), against gravity.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/types.hpp"

namespace sph {

/// One axis-aligned wall face: the box [lo, hi] with lo[axis] == hi[axis] (the plane), and n = +-e_axis into
/// the fluid. lo is the face's smallest corner (the segment's first end point in 2D).
template <int D>
struct Wall {
  Vec<D> lo, hi;
  Vec<D> n;  // unit normal, pointing into the fluid
  int axis = 0;

  /// The length of the face's diagonal: a segment's length in 2D.
  double span() const { return (hi - lo).norm(); }
  /// Signed distance of x from the wall's plane, positive on the fluid side.
  double signed_distance(const Vec<D>& x) const { return (x - lo).dot(n); }
  /// True when x projects onto the face (within margin along each of its edges).
  bool projects_onto(const Vec<D>& x, double margin = 0.0) const {
    for (int a = 0; a < D; ++a) {
      if (a == axis) continue;
      const double s = x[a] - lo[a];
      if (!(s >= -margin && s <= (hi[a] - lo[a]) + margin)) return false;
    }
    return true;
  }
  /// The point of the face nearest to x.
  Vec<D> nearest_point(const Vec<D>& x) const {
    Vec<D> p = lo;
    for (int a = 0; a < D; ++a) {
      if (a != axis) p[a] = lo[a] + std::clamp(x[a] - lo[a], 0.0, hi[a] - lo[a]);
    }
    return p;
  }
  Vec<D> reflect_point(const Vec<D>& x) const { return x - 2.0 * signed_distance(x) * n; }
  Vec<D> reflect_vector(const Vec<D>& v) const { return v - 2.0 * v.dot(n) * n; }

  /// The face of the box [lo, hi] at its low (side = -1) or high (side = +1) end of `axis`, with the normal
  /// `normal_sign` e_axis.
  static Wall face(const Vec<D>& lo, const Vec<D>& hi, int axis, int side, double normal_sign) {
    Wall w;
    w.lo = lo;
    w.hi = hi;
    const double plane = side < 0 ? lo[axis] : hi[axis];
    w.lo[axis] = plane;
    w.hi[axis] = plane;
    w.n = Vec<D>::Zero();
    w.n[axis] = normal_sign;
    w.axis = axis;
    return w;
  }
};

/// Axis-aligned box [lo, hi].
template <int D>
struct Box {
  Vec<D> lo = Vec<D>::Zero();
  Vec<D> hi = Vec<D>::Zero();
  bool operator==(const Box&) const = default;
  bool contains(const Vec<D>& x) const {
    for (int a = 0; a < D; ++a)
      if (!(x[a] >= lo[a] && x[a] <= hi[a])) return false;
    return true;
  }
  bool contains_strictly(const Vec<D>& x) const {
    for (int a = 0; a < D; ++a)
      if (!(x[a] > lo[a] && x[a] < hi[a])) return false;
    return true;
  }
};

/// What happens to fluid that leaves through an open top (over the rim): the watchdog stops the run, or the
/// step removes it (core/boundary/outflow.hpp), counting it and its mass.
enum class Outflow : std::uint8_t { stop, remove };

/// The solid geometry of a scene: a container (fluid inside, open at the top if `open_top`, with what happens to
/// fluid leaving through it) and box obstacles (fluid outside).
template <int D>
struct Geometry {
  static constexpr int up = D - 1;  // the vertical axis
  Box<D> container{Vec<D>::Zero(), Vec<D>::Ones()};
  bool open_top = true;
  std::vector<Box<D>> obstacles;
  Outflow outflow = Outflow::stop;

  /// Every wall face with its normal into the fluid. The container's floor, then the low and high side of each
  /// horizontal axis, then the top when closed; each obstacle's top, bottom, then the low and high side of each
  /// horizontal axis. (The order fixes the order of the ghost images, so it is part of the results.)
  std::vector<Wall<D>> walls() const {
    std::vector<Wall<D>> w;
    const Vec<D>& lo = container.lo;
    const Vec<D>& hi = container.hi;
    w.push_back(Wall<D>::face(lo, hi, up, -1, 1.0));  // floor
    for (int a = 0; a < up; ++a) {
      w.push_back(Wall<D>::face(lo, hi, a, -1, 1.0));   // low side
      w.push_back(Wall<D>::face(lo, hi, a, +1, -1.0));  // high side
    }
    if (!open_top) w.push_back(Wall<D>::face(lo, hi, up, +1, -1.0));
    for (const Box<D>& b : obstacles) {
      w.push_back(Wall<D>::face(b.lo, b.hi, up, +1, 1.0));   // top face
      w.push_back(Wall<D>::face(b.lo, b.hi, up, -1, -1.0));  // bottom face
      for (int a = 0; a < up; ++a) {
        w.push_back(Wall<D>::face(b.lo, b.hi, a, -1, -1.0));
        w.push_back(Wall<D>::face(b.lo, b.hi, a, +1, 1.0));
      }
    }
    return w;
  }

  /// True when x is in the fluid domain: inside the container (above its top too when open) and outside
  /// every obstacle.
  bool in_fluid_domain(const Vec<D>& x) const {
    for (int a = 0; a < up; ++a)
      if (x[a] < container.lo[a] || x[a] > container.hi[a]) return false;
    if (x[up] < container.lo[up]) return false;
    if (!open_top && x[up] > container.hi[up]) return false;
    for (const Box<D>& b : obstacles) {
      if (b.contains_strictly(x)) return false;
    }
    return true;
  }

  /// For a particle outside the fluid domain at x that drifted along u in its last step (x = x_prev + dt u,
  /// with x_prev inside): true when it left through the open top, i.e. beside the container above the rim
  /// or having crossed a side wall's plane above the rim (over the wall's top, then down within the step);
  /// false when it went through a wall (the floor, a side wall below the rim, or into an obstacle).
  /// Traced back along u to each side plane it is beyond, so it depends neither on dt nor on how far the step
  /// went.
  bool left_through_open_top(const Vec<D>& x, const Vec<D>& u) const {
    if (!open_top) return false;
    const double rim = container.hi[up];
    bool beside = false;
    for (int a = 0; a < up; ++a) beside = beside || x[a] < container.lo[a] || x[a] > container.hi[a];
    if (!beside) return false;  // within the span and out of the domain: below the floor or inside an obstacle
    if (x[up] > rim) return true;
    // Below the rim now: where did its path cross the side plane? Only a path that moved outwards crossed it.
    for (int a = 0; a < up; ++a) {
      double side;
      if (x[a] < container.lo[a]) {
        side = container.lo[a];
      } else if (x[a] > container.hi[a]) {
        side = container.hi[a];
      } else {
        continue;
      }
      const double outward = x[a] < container.lo[a] ? -u[a] : u[a];
      if (!(outward > 0.0)) continue;
      const double up_cross = x[up] - u[up] * ((x[a] - side) / u[a]);
      if (up_cross > rim) return true;
    }
    return false;
  }

  /// Distance from x to the nearest wall face (for daughters near walls).
  double distance_to_walls(const Vec<D>& x) const {
    double best = std::numeric_limits<double>::infinity();
    for (const Wall<D>& w : walls()) best = std::min(best, (x - w.nearest_point(x)).norm());
    return best;
  }
};

/// A box whose dimension is known only when a scene is read (AnyVec corners); `fixed<D>()` gives the solver's.
struct AnyBox {
  AnyVec lo, hi;
  AnyBox() = default;
  AnyBox(AnyVec lo_, AnyVec hi_) : lo(std::move(lo_)), hi(std::move(hi_)) {}
  template <int D>
  AnyBox(const Box<D>& b) : lo(b.lo), hi(b.hi) {}  // NOLINT: a Box<D> is an AnyBox
  bool operator==(const AnyBox&) const = default;
  template <int D>
  Box<D> fixed() const {
    return Box<D>{lo.fixed<D>(), hi.fixed<D>()};
  }
};

using Wall2 = Wall<2>;
using Box2 = Box<2>;
using Geometry2 = Geometry<2>;
using Wall3 = Wall<3>;
using Box3 = Box<3>;
using Geometry3 = Geometry<3>;

}  // namespace sph
