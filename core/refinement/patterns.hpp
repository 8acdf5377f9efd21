#pragma once
// Daughter patterns (section 3.2). A pattern gives the four offsets of the daughters from x_i; they are
// point-symmetric about x_i (o_{a+2} = -o_a), so mass, linear and angular momentum and kinetic energy are
// conserved exactly when every daughter gets m_i/4 and v_i.
#include <array>
#include <cmath>

#include "core/boundary/wall.hpp"
#include "core/refinement/neighbour_query.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

using Offsets = std::array<Vec<2>, 4>;

/// A square of side s with one axis along the unit vector e: daughters at the sub-cell centres,
/// +-s/4 along each axis, ordered so that o[a+2] = -o[a].
inline Offsets square_pattern(double s, const Vec<2>& e) {
  const Vec<2> u = 0.25 * s * e;
  const Vec<2> w = 0.25 * s * Vec<2>(-e[1], e[0]);
  return {-u - w, u - w, u + w, -u + w};
}

/// AAP: the axis-aligned square of side d^{l_i}.
inline Offsets axis_aligned_pattern(double d_i) { return square_pattern(d_i, Vec<2>(1.0, 0.0)); }

/// The RSP reference neighbour: largest F_ij = d_ij / r_ij over the fluid neighbours j.
struct Reference {
  bool found = false;
  double F = 1.0;
  Vec<2> direction = Vec<2>(1.0, 0.0);  // unit vector from x_i towards x_j
};

inline Reference find_reference(const ParticleStore<2>& store, const NeighbourQuery& query, std::size_t i) {
  Reference ref;
  double best = -1.0;
  query.for_each_fluid_neighbour(i, [&](std::size_t j, double r) {
    if (r <= 0.0) return;
    const double F = 0.5 * (store.d[i] + store.d[j]) / r;
    if (F > best) {  // strict: the first of equal F in the fixed traversal order wins
      best = F;
      ref.found = true;
      ref.F = F;
      ref.direction = (store.x[j] - store.x[i]) / r;
    }
  });
  return ref;
}

/// RSP: the square aligned with x_i x_j (j the reference) and side s = k d^{l_i} / F_ij; without any
/// neighbour it falls back to AAP scaled by k.
inline Offsets rotated_scaled_pattern(double d_i, const Reference& ref, double k) {
  if (!ref.found) return square_pattern(k * d_i, Vec<2>(1.0, 0.0));
  return square_pattern(k * d_i / ref.F, ref.direction);
}

/// The wall rule (docs/METHOD.md, "Daughters near walls"): every daughter must stay at least `margin` inside
/// every wall the parent is near. The pattern is first compressed along the wall normal (symmetrically, so the
/// centroid stays at x_i and conservation is exact), to no less than a quarter of its extent; only if the
/// deepest daughter is still closer than the margin is the compressed pattern shifted inward, which moves the
/// centroid. Returns true when it shifted.
inline bool keep_inside_walls(const Vec<2>& xi, Offsets& o, const std::vector<Wall2>& walls, double margin) {
  bool shifted = false;
  double reach = 0.0;
  for (const Vec<2>& a : o) reach = std::max(reach, a.norm());
  for (const Wall2& w : walls) {
    const double dist = w.signed_distance(xi);
    if (dist < -reach || dist > reach + margin || !w.projects_onto(xi, reach)) continue;
    double deepest = 0.0;  // most negative normal component among the daughters
    for (const Vec<2>& a : o) deepest = std::min(deepest, a.dot(w.n));
    const double room = dist - margin;
    if (-deepest <= room) continue;
    constexpr double kMinScale = 0.25;  // never collapse daughters onto each other
    double scale = room > 0.0 ? room / -deepest : 0.0;
    if (scale < kMinScale) scale = kMinScale;
    for (Vec<2>& a : o) a -= (1.0 - scale) * a.dot(w.n) * w.n;
    const double lowest = dist + scale * deepest;  // distance of the deepest daughter after compression
    if (lowest < margin) {
      for (Vec<2>& a : o) a += (margin - lowest) * w.n;
      shifted = true;
    }
  }
  return shifted;
}

}  // namespace sph::refine
