#pragma once
// Solid walls as straight segments with a unit normal pointing into the fluid (section 2.4).
// Axis-aligned now (the container and rectangular obstacles); nothing here assumes it except the
// helpers that build them, so a sloped segment can come later.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/types.hpp"

namespace sph {

struct Wall2 {
  Vec<2> p0, p1;  // end points
  Vec<2> n;       // unit normal, pointing into the fluid

  Vec<2> tangent() const { return (p1 - p0).normalized(); }
  double length() const { return (p1 - p0).norm(); }
  /// Signed distance of x from the wall's line, positive on the fluid side.
  double signed_distance(const Vec<2>& x) const { return (x - p0).dot(n); }
  /// Position of x's projection along the segment, 0 at p0 and length() at p1.
  double along(const Vec<2>& x) const { return (x - p0).dot(tangent()); }
  bool projects_onto(const Vec<2>& x, double margin = 0.0) const {
    const double s = along(x);
    return s >= -margin && s <= length() + margin;
  }
  Vec<2> reflect_point(const Vec<2>& x) const { return x - 2.0 * signed_distance(x) * n; }
  Vec<2> reflect_vector(const Vec<2>& v) const { return v - 2.0 * v.dot(n) * n; }
};

/// Axis-aligned rectangle [lo, hi].
struct Box2 {
  Vec<2> lo = Vec<2>::Zero();
  Vec<2> hi = Vec<2>::Zero();
  bool operator==(const Box2&) const = default;
  bool contains(const Vec<2>& x) const {
    return x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1];
  }
  bool contains_strictly(const Vec<2>& x) const {
    return x[0] > lo[0] && x[0] < hi[0] && x[1] > lo[1] && x[1] < hi[1];
  }
};

/// What happens to fluid that leaves through an open top (over the rim): the watchdog stops the run, or the
/// step removes it (core/boundary/outflow.hpp), counting it and its mass.
enum class Outflow : std::uint8_t { stop, remove };

/// The solid geometry of a scene: a container (fluid inside, open at the top if `open_top`, with what happens to
/// fluid leaving through it) and rectangular obstacles (fluid outside).
struct Geometry2 {
  Box2 container{Vec<2>(0, 0), Vec<2>(1, 1)};
  bool open_top = true;
  std::vector<Box2> obstacles;
  Outflow outflow = Outflow::stop;

  /// Every wall segment with its normal into the fluid.
  std::vector<Wall2> walls() const {
    std::vector<Wall2> w;
    const Vec<2> lo = container.lo, hi = container.hi;
    w.push_back({Vec<2>(lo[0], lo[1]), Vec<2>(hi[0], lo[1]), Vec<2>(0, 1)});   // bottom
    w.push_back({Vec<2>(lo[0], lo[1]), Vec<2>(lo[0], hi[1]), Vec<2>(1, 0)});   // left
    w.push_back({Vec<2>(hi[0], lo[1]), Vec<2>(hi[0], hi[1]), Vec<2>(-1, 0)});  // right
    if (!open_top) w.push_back({Vec<2>(lo[0], hi[1]), Vec<2>(hi[0], hi[1]), Vec<2>(0, -1)});
    for (const Box2& b : obstacles) {
      w.push_back({Vec<2>(b.lo[0], b.hi[1]), Vec<2>(b.hi[0], b.hi[1]), Vec<2>(0, 1)});   // top face
      w.push_back({Vec<2>(b.lo[0], b.lo[1]), Vec<2>(b.hi[0], b.lo[1]), Vec<2>(0, -1)});  // bottom face
      w.push_back({Vec<2>(b.lo[0], b.lo[1]), Vec<2>(b.lo[0], b.hi[1]), Vec<2>(-1, 0)});  // left face
      w.push_back({Vec<2>(b.hi[0], b.lo[1]), Vec<2>(b.hi[0], b.hi[1]), Vec<2>(1, 0)});   // right face
    }
    return w;
  }

  /// True when x is in the fluid domain: inside the container (above its top too when open) and outside
  /// every obstacle.
  bool in_fluid_domain(const Vec<2>& x) const {
    if (x[0] < container.lo[0] || x[0] > container.hi[0] || x[1] < container.lo[1]) return false;
    if (!open_top && x[1] > container.hi[1]) return false;
    for (const Box2& b : obstacles) {
      if (b.contains_strictly(x)) return false;
    }
    return true;
  }

  /// For a particle outside the fluid domain at x that drifted along u in its last step (x = x_prev + dt u,
  /// with x_prev inside): true when it left through the open top, i.e. beside the container above the rim
  /// or having crossed a side wall's line above the rim (over the wall's top, then down within the step);
  /// false when it went through a wall (the floor, a side wall below the rim, or into an obstacle).
  /// Traced back along u to the side line, so it depends neither on dt nor on how far the step went.
  bool left_through_open_top(const Vec<2>& x, const Vec<2>& u) const {
    if (!open_top) return false;
    const double rim = container.hi[1];
    double side;  // the side line the particle is beyond
    if (x[0] < container.lo[0]) {
      side = container.lo[0];
    } else if (x[0] > container.hi[0]) {
      side = container.hi[0];
    } else {
      return false;  // within the span and out of the domain: below the floor or inside an obstacle
    }
    if (x[1] > rim) return true;
    // Below the rim now: where did its path cross the side line? Only a path that moved outwards crossed it.
    const double outward = x[0] < container.lo[0] ? -u[0] : u[0];
    if (!(outward > 0.0)) return false;
    const double y_cross = x[1] - u[1] * ((x[0] - side) / u[0]);
    return y_cross > rim;
  }

  /// Distance from x to the nearest wall segment (for daughters near walls).
  double distance_to_walls(const Vec<2>& x) const {
    double best = std::numeric_limits<double>::infinity();
    for (const Wall2& w : walls()) {
      const double s = std::clamp(w.along(x), 0.0, w.length());
      best = std::min(best, (x - (w.p0 + s * w.tangent())).norm());
    }
    return best;
  }
};

}  // namespace sph
