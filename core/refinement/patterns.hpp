#pragma once
// Daughter patterns (section 3.2). A pattern gives the 2^D offsets of the daughters from x_i (a square of four
// in 2D, a cube of eight in 3D); they are point-symmetric about x_i, so mass, linear and angular momentum and
// kinetic energy are conserved exactly when every daughter gets m_i / 2^D and v_i.
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "core/boundary/wall.hpp"
#include "core/refinement/neighbour_query.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

/// The daughters' offsets from x_i: 2^D of them.
template <int D>
using OffsetsIn = std::array<Vec<D>, (1u << D)>;
using Offsets = OffsetsIn<2>;

/// A square of side s with one axis along the unit vector e: daughters at the sub-cell centres,
/// +-s/4 along each axis, ordered so that o[a+2] = -o[a].
inline Offsets square_pattern(double s, const Vec<2>& e) {
  const Vec<2> u = 0.25 * s * e;
  const Vec<2> w = 0.25 * s * Vec<2>(-e[1], e[0]);
  return {-u - w, u - w, u + w, -u + w};
}

/// A cube of side s with axes along the orthonormal frame (e0, e1, e2): daughters at the sub-cube centres,
/// +-s/4 along each axis; daughter a takes + along axis k where bit k of a is set, so o[7 - a] = -o[a].
inline OffsetsIn<3> cube_pattern(double s, const std::array<Vec<3>, 3>& e) {
  OffsetsIn<3> o;
  for (unsigned a = 0; a < 8; ++a) {
    Vec<3> x = Vec<3>::Zero();
    for (unsigned k = 0; k < 3; ++k) x += ((a >> k) & 1u ? 0.25 * s : -0.25 * s) * e[k];
    o[a] = x;
  }
  return o;
}

/// The orthonormal frame whose first axis is the unit vector e: the second is the coordinate axis least aligned
/// with e (the first of equals) with its part along e removed, the third their cross product. Deterministic,
/// and the coordinate frame itself for e = e_x.
inline std::array<Vec<3>, 3> frame_along(const Vec<3>& e) {
  int least = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(e[k]) < std::abs(e[least])) least = k;
  Vec<3> b = Vec<3>::Zero();
  b[least] = 1.0;
  b = (b - b.dot(e) * e).normalized();
  return {e, b, e.cross(b)};
}

/// The pattern of side s oriented by the unit vector e (2D: the square with one side along e; 3D: the cube with
/// one axis along e, frame_along(e)).
template <int D>
OffsetsIn<D> oriented_pattern(double s, const Vec<D>& e) {
  if constexpr (D == 2) {
    return square_pattern(s, e);
  } else {
    return cube_pattern(s, frame_along(e));
  }
}

/// AAP: the axis-aligned square (cube) of side d^{l_i}.
template <int D = 2>
OffsetsIn<D> axis_aligned_pattern(double d_i) {
  return oriented_pattern<D>(d_i, Vec<D>::Unit(0));
}

/// The RSP reference neighbour: largest F_ij = d_ij / r_ij over the fluid neighbours j.
template <int D>
struct ReferenceIn {
  bool found = false;
  double F = 1.0;
  Vec<D> direction = Vec<D>::Unit(0);  // unit vector from x_i towards x_j
};
using Reference = ReferenceIn<2>;

template <int D>
ReferenceIn<D> find_reference(const ParticleStore<D>& store, const NeighbourQueryIn<D>& query, std::size_t i,
                              bool same_level = false) {
  ReferenceIn<D> ref;
  double best = -1.0;
  ParticleId best_id = 0;
  query.for_each_fluid_neighbour(i, [&](std::size_t j, double r) {
    if (r <= 0.0) return;
    if (same_level && store.level[j] != store.level[i]) return;  // buffered coupling: the level's own lattice
    const double F = 0.5 * (store.d[i] + store.d[j]) / r;
    // Of equal F (a lattice's equally near neighbours), the lowest id: the choice is the particles' own, whatever
    // order the query visits them in (on a rank, its grid holds only part of the particles, issue #19).
    if (F > best || (F == best && store.id[j] < best_id)) {
      best = F;
      best_id = store.id[j];
      ref.found = true;
      ref.F = F;
      ref.direction = (store.x[j] - store.x[i]) / r;
    }
  });
  return ref;
}

/// RSP: the square (cube) with one axis along x_i x_j (j the reference) and side s = k d^{l_i} / F_ij; without
/// any neighbour it falls back to AAP scaled by k.
template <int D>
OffsetsIn<D> rotated_scaled_pattern(double d_i, const ReferenceIn<D>& ref, double k) {
  if (!ref.found) return oriented_pattern<D>(k * d_i, Vec<D>::Unit(0));
  return oriented_pattern<D>(k * d_i / ref.F, ref.direction);
}

/// How far inside every wall a daughter of a parent of spacing d must start: half the daughters' spacing d / 2,
/// where the set-up puts a particle of that spacing and where its Lennard-Jones wall force begins (r0 = d / 2 at
/// the default r0_factor). A quarter of it, as before 2026-12-02, let RSP put a daughter 0.54 r0 from the drop's
/// left wall, and the wall's (r0 / r)^12 repulsion threw it out at 194 m/s (docs/METHOD.md, "Daughters near walls").
inline double daughter_wall_margin(double parent_spacing) { return 0.5 * (0.5 * parent_spacing); }

/// The wall rule (docs/METHOD.md, "Daughters near walls"): every daughter must stay at least `margin` inside
/// every wall the parent is near. The pattern is first compressed along the wall normal (symmetrically, so the
/// centroid stays at x_i and conservation is exact), to no less than a quarter of its extent; only if the
/// deepest daughter is still closer than the margin is the compressed pattern shifted inward, which moves the
/// centroid. Returns true when it shifted.
template <int D>
bool keep_inside_walls(const Vec<D>& xi, OffsetsIn<D>& o, const std::vector<Wall<D>>& walls, double margin) {
  bool shifted = false;
  double reach = 0.0;
  for (const Vec<D>& a : o) reach = std::max(reach, a.norm());
  for (const Wall<D>& w : walls) {
    const double dist = w.signed_distance(xi);
    if (dist < -reach || dist > reach + margin || !w.projects_onto(xi, reach)) continue;
    double deepest = 0.0;  // most negative normal component among the daughters
    for (const Vec<D>& a : o) deepest = std::min(deepest, a.dot(w.n));
    const double room = dist - margin;
    if (-deepest <= room) continue;
    constexpr double kMinScale = 0.25;  // never collapse daughters onto each other
    double scale = room > 0.0 ? room / -deepest : 0.0;
    if (scale < kMinScale) scale = kMinScale;
    for (Vec<D>& a : o) a -= (1.0 - scale) * a.dot(w.n) * w.n;
    const double lowest = dist + scale * deepest;  // distance of the deepest daughter after compression
    if (lowest < margin) {
      for (Vec<D>& a : o) a += (margin - lowest) * w.n;
      shifted = true;
    }
  }
  return shifted;
}

}  // namespace sph::refine
