#pragma once
// Ghost particles (section 2.4): a fluid particle is mirrored across every wall face in reach (on the
// fluid side, closer than h_i + h_max, projecting onto the face; h_max the largest fluid smoothing length, so
// that a coarse particle by the wall finds the images of every fine neighbour its support h_i + h_j reaches), and through the corner of every two (in 3D also
// three) of those walls that are mutually perpendicular and meet (a container's corner or edge, an obstacle's
// foot on the floor or against a wall): the doubly (triply) reflected ghost. Perpendicular walls that do not meet (the floor and the face of an
// obstacle that stands clear of it) give no corner ghost. Beyond kMaxWalls walls in reach only the nearest
// are mirrored (docs/METHOD.md, "Walls"). Ghosts copy mass, density, pressure and smoothing length; their
// velocity is reflected (free-slip: normal part reversed) or reversed (no-slip). The solver rebuilds them
// from scratch each step (Simulation::prepare_neighbours): one stream expansion through the store's registry,
// output_count() outputs per particle (old ghosts dropped), composed with the cell sort into one gather, then
// make_ghost() on each copy that is an image; the result is deterministic at any thread count.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "core/boundary/wall.hpp"
#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"

namespace sph {

enum class GhostSlip { free_slip, no_slip };

/// The pressure a ghost carries: the source's (PHYSICS.md, section 2.4 of the paper), or the source's plus
/// the hydrostatic difference rho_i g.(x_ghost - x_i), with the density from the inverse equation of
/// state (an option: it removes the excess pressure of the first layer above a horizontal wall).
enum class GhostPressure { mirrored, hydrostatic };

/// Ghost images of fluid particles across the walls of a D-dimensional geometry.
template <int D>
class GhostBuilderT {
 public:
  /// At most this many walls give a particle an image: one on each side of each axis, which takes a pocket
  /// narrower than 4 h every way. More can be in reach only across an obstacle thinner than 2 h or where
  /// obstacles overlap; then the nearest are kept (ties: the first in the wall list).
  static constexpr int kMaxWalls = 2 * D;
  /// An image per wall in reach, and one per set of 2..D of them that are mutually perpendicular and meet in a
  /// corner: with walls on two sides of each axis, 2D reaches 4 + 4 and 3D 6 + 12 + 8. A particle in a box's
  /// corner has D walls in reach and 2^D - 1 images (3 in 2D, 7 in 3D).
  static constexpr int kMaxGhosts = D == 2 ? 8 : 26;

  GhostBuilderT(std::vector<Wall<D>> walls, GhostSlip slip, GhostPressure pressure = GhostPressure::mirrored,
                Vec<D> gravity = Vec<D>::Zero(), TaitEquationOfState eos = {})
      : walls_(std::move(walls)), slip_(slip), pressure_(pressure), gravity_(std::move(gravity)), eos_(eos) {}

  const std::vector<Wall<D>>& walls() const { return walls_; }
  GhostSlip slip() const { return slip_; }

  /// The largest smoothing length of the fluid (over every rank), which the reach of each particle's images adds
  /// to its own: a pair interacts within h_i + h_j, and the image of j lies at least as far from i as j's own
  /// distance to the wall, so j needs an image while that distance is below h_j + max_i h_i. With one level
  /// (or before it is set, 0) the reach is 2 h. The driver sets it whenever the fluid's range changes
  /// (Simulation::prepare_neighbours), before the output counts.
  void set_largest_h(double h) { largest_h_ = h; }
  double largest_h() const { return largest_h_; }
  double reach(double h) const { return h + std::max(h, largest_h_); }

  /// The ghost images of a particle at x with smoothing length h: positions and velocities. First one per
  /// wall in reach, in the order of the wall list; then one per pair of those walls (in the same order) that
  /// are perpendicular and meet, reflected through both; in 3D then one per such triple.
  struct Images {
    int count = 0;
    std::array<Vec<D>, kMaxGhosts> x;
    std::array<Vec<D>, kMaxGhosts> v;
  };

  Images images(const Vec<D>& x, const Vec<D>& v, double h) const {
    struct Near {
      std::size_t wall;
      double dist;
    };
    std::array<Near, kMaxWalls> near{};
    std::size_t nnear = 0;
    const double within = reach(h);
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const Wall<D>& wall = walls_[w];
      const double dist = wall.signed_distance(x);
      if (dist < 0.0 || dist >= within || !wall.projects_onto(x)) continue;
      if (nnear < near.size()) {
        near[nnear++] = {w, dist};
        continue;
      }
      // More walls in reach than kept: this one replaces the farthest kept one if it is nearer (on a tie the
      // earlier wall stays).
      std::size_t far = 0;
      for (std::size_t k = 1; k < near.size(); ++k) {
        if (near[k].dist > near[far].dist || (near[k].dist == near[far].dist && near[k].wall > near[far].wall)) far = k;
      }
      if (dist < near[far].dist) near[far] = {w, dist};
    }
    for (std::size_t k = 1; k < nnear; ++k) {  // back into wall-list order (a replacement may have broken it)
      const Near t = near[k];
      std::size_t j = k;
      for (; j > 0 && near[j - 1].wall > t.wall; --j) near[j] = near[j - 1];
      near[j] = t;
    }
    Images out;
    for (std::size_t k = 0; k < nnear; ++k) {
      const Wall<D>& wall = walls_[near[k].wall];
      out.x[static_cast<std::size_t>(out.count)] = wall.reflect_point(x);
      out.v[static_cast<std::size_t>(out.count)] = ghost_velocity(v, {&wall});
      ++out.count;
    }
    // Corner images: each pair (a < b), then in 3D each triple (a < b < c), of walls in reach whose normals are
    // mutually perpendicular and which meet: their planes cross at the particle's projection onto all of them,
    // and the walls meet when that point lies on every face (an edge of one on the other, up to rounding).
    const auto perpendicular = [&](std::size_t a, std::size_t b) {
      return std::abs(walls_[near[a].wall].n.dot(walls_[near[b].wall].n)) < 1e-12;
    };
    const auto meet = [&](std::initializer_list<std::size_t> set) {
      Vec<D> corner = x;
      double tolerance = 0.0;
      for (const std::size_t k : set) {
        corner -= near[k].dist * walls_[near[k].wall].n;
        tolerance += walls_[near[k].wall].span();
      }
      tolerance *= 1e-9;
      for (const std::size_t k : set)
        if (!walls_[near[k].wall].projects_onto(corner, tolerance)) return false;
      return true;
    };
    for (std::size_t a = 0; a < nnear; ++a) {
      for (std::size_t b = a + 1; b < nnear && out.count < kMaxGhosts; ++b) {
        if (!perpendicular(a, b) || !meet({a, b})) continue;
        const Wall<D>& wa = walls_[near[a].wall];
        const Wall<D>& wb = walls_[near[b].wall];
        out.x[static_cast<std::size_t>(out.count)] = wb.reflect_point(wa.reflect_point(x));
        out.v[static_cast<std::size_t>(out.count)] = ghost_velocity(v, {&wa, &wb});
        ++out.count;
      }
    }
    if constexpr (D == 3) {
      for (std::size_t a = 0; a < nnear; ++a) {
        for (std::size_t b = a + 1; b < nnear; ++b) {
          if (!perpendicular(a, b)) continue;
          for (std::size_t c = b + 1; c < nnear && out.count < kMaxGhosts; ++c) {
            if (!perpendicular(a, c) || !perpendicular(b, c) || !meet({a, b, c})) continue;
            const Wall<D>& wa = walls_[near[a].wall];
            const Wall<D>& wb = walls_[near[b].wall];
            const Wall<D>& wc = walls_[near[c].wall];
            out.x[static_cast<std::size_t>(out.count)] = wc.reflect_point(wb.reflect_point(wa.reflect_point(x)));
            out.v[static_cast<std::size_t>(out.count)] = ghost_velocity(v, {&wa, &wb, &wc});
            ++out.count;
          }
        }
      }
    }
    return out;
  }

  /// How many outputs particle i has in the ghost expansion: old ghosts 0, walls 1, fluid 1 + its images.
  std::uint32_t output_count(const ParticleView<D>& view, std::size_t i) const {
    if (view.kind[i] == Kind::ghost) return 0;
    if (view.kind[i] != Kind::fluid && view.kind[i] != Kind::halo) return 1;  // a halo has its images too
    return 1u + static_cast<std::uint32_t>(images(view.x[i], view.v[i], view.h[i]).count);
  }

  /// Turns item k, a copy of its source particle, into that source's ghost number `image` (0-based).
  void make_ghost(ParticleView<D>& s, std::size_t k, int image) const {
    const Images im = images(s.x[k], s.v[k], s.h[k]);
    if (pressure_ == GhostPressure::hydrostatic) {
      s.p[k] += s.rho[k] * gravity_.dot(im.x[static_cast<std::size_t>(image)] - s.x[k]);
      s.rho[k] = eos_.density(s.p[k]);
    }
    s.x[k] = im.x[static_cast<std::size_t>(image)];
    s.v[k] = im.v[static_cast<std::size_t>(image)];
    s.kind[k] = Kind::ghost;
    s.a[k].setZero();
    s.drho[k] = 0.0;
  }

  /// Removes every ghost (before output, refinement or checkpoints).
  static void remove(ParticleStore<D>& store) {
    const auto view = store.view();
    store.compact([&](std::size_t i) { return view.kind[i] != Kind::ghost; });
  }

 private:
  /// Free slip reflects the velocity through each wall of the image in turn; no-slip reverses it.
  Vec<D> ghost_velocity(const Vec<D>& v, std::initializer_list<const Wall<D>*> through) const {
    if (slip_ == GhostSlip::no_slip) return -v;
    Vec<D> g = v;
    for (const Wall<D>* w : through) g = w->reflect_vector(g);
    return g;
  }

  std::vector<Wall<D>> walls_;
  GhostSlip slip_;
  GhostPressure pressure_;
  Vec<D> gravity_;
  TaitEquationOfState eos_;
  double largest_h_ = 0.0;
};

using GhostBuilder = GhostBuilderT<2>;

}  // namespace sph
