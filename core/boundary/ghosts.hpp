#pragma once
// Ghost particles (section 2.4): a fluid particle is mirrored across every wall segment in reach (on the
// fluid side, closer than 2 h_i, projecting onto the segment), and through the corner of every two of those
// walls that are perpendicular and meet (a container's corner, an obstacle's foot on the floor or against a
// wall): the doubly reflected ghost. Perpendicular walls that do not meet (the floor and the face of an
// obstacle that stands clear of it) give no corner ghost. Beyond kMaxWalls walls in reach only the nearest
// are mirrored (docs/METHOD.md, "Walls"). Ghosts copy mass, density, pressure and smoothing length; their
// velocity is reflected (free-slip: normal part reversed) or reversed (no-slip). The solver rebuilds them
// from scratch each step (Simulation::prepare_neighbours): one stream expansion through the store's registry,
// output_count() outputs per particle (old ghosts dropped), composed with the cell sort into one gather, then
// make_ghost() on each copy that is an image; the result is deterministic at any thread count.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
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

class GhostBuilder {
 public:
  /// At most this many walls give a particle an image: one on each side, which takes a pocket narrower than
  /// 4 h both ways. More can be in reach only across an obstacle thinner than 2 h or where obstacles overlap;
  /// then the nearest are kept (ties: the first in the wall list).
  static constexpr int kMaxWalls = 4;
  /// An image per wall and a corner image per perpendicular pair of them: among four walls at most four such
  /// pairs (the walls are axis-aligned, two horizontal times two vertical).
  static constexpr int kMaxGhosts = kMaxWalls + 4;

  GhostBuilder(std::vector<Wall2> walls, GhostSlip slip, GhostPressure pressure = GhostPressure::mirrored,
               Vec<2> gravity = Vec<2>::Zero(), TaitEquationOfState eos = {})
      : walls_(std::move(walls)), slip_(slip), pressure_(pressure), gravity_(std::move(gravity)), eos_(eos) {}

  const std::vector<Wall2>& walls() const { return walls_; }
  GhostSlip slip() const { return slip_; }

  /// The ghost images of a particle at x with smoothing length h: positions and velocities. First one per
  /// wall in reach, in the order of the wall list; then one per pair of those walls (in the same order) that
  /// are perpendicular and meet, reflected through both.
  struct Images {
    int count = 0;
    std::array<Vec<2>, kMaxGhosts> x;
    std::array<Vec<2>, kMaxGhosts> v;
  };

  Images images(const Vec<2>& x, const Vec<2>& v, double h) const {
    struct Near {
      std::size_t wall;
      double dist;
    };
    std::array<Near, kMaxWalls> near{};
    std::size_t nnear = 0;
    const double reach = 2.0 * h;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const Wall2& wall = walls_[w];
      const double dist = wall.signed_distance(x);
      if (dist < 0.0 || dist >= reach || !wall.projects_onto(x)) continue;
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
      const Wall2& wall = walls_[near[k].wall];
      out.x[static_cast<std::size_t>(out.count)] = wall.reflect_point(x);
      out.v[static_cast<std::size_t>(out.count)] = ghost_velocity(v, wall, nullptr);
      ++out.count;
    }
    for (std::size_t a = 0; a < nnear; ++a) {
      for (std::size_t b = a + 1; b < nnear && out.count < kMaxGhosts; ++b) {
        const Wall2& wa = walls_[near[a].wall];
        const Wall2& wb = walls_[near[b].wall];
        if (std::abs(wa.n.dot(wb.n)) >= 1e-12) continue;
        // The lines cross at the particle's projection onto both; the walls meet when that point lies on both
        // segments (an end of one on the other, up to rounding).
        const Vec<2> corner = x - near[a].dist * wa.n - near[b].dist * wb.n;
        const double tolerance = 1e-9 * (wa.length() + wb.length());
        if (!wa.projects_onto(corner, tolerance) || !wb.projects_onto(corner, tolerance)) continue;
        out.x[static_cast<std::size_t>(out.count)] = wb.reflect_point(wa.reflect_point(x));
        out.v[static_cast<std::size_t>(out.count)] = ghost_velocity(v, wa, &wb);
        ++out.count;
      }
    }
    return out;
  }

  /// How many outputs particle i has in the ghost expansion: old ghosts 0, walls 1, fluid 1 + its images.
  std::uint32_t output_count(const ParticleView<2>& view, std::size_t i) const {
    if (view.kind[i] == Kind::ghost) return 0;
    if (view.kind[i] != Kind::fluid) return 1;
    return 1u + static_cast<std::uint32_t>(images(view.x[i], view.v[i], view.h[i]).count);
  }

  /// Turns item k, a copy of its source particle, into that source's ghost number `image` (0-based).
  void make_ghost(ParticleView<2>& s, std::size_t k, int image) const {
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
  static void remove(ParticleStore<2>& store) {
    const auto view = store.view();
    store.compact([&](std::size_t i) { return view.kind[i] != Kind::ghost; });
  }

 private:
  Vec<2> ghost_velocity(const Vec<2>& v, const Wall2& a, const Wall2* b) const {
    if (slip_ == GhostSlip::no_slip) return -v;
    Vec<2> g = a.reflect_vector(v);
    if (b) g = b->reflect_vector(g);
    return g;
  }

  std::vector<Wall2> walls_;
  GhostSlip slip_;
  GhostPressure pressure_;
  Vec<2> gravity_;
  TaitEquationOfState eos_;
};

}  // namespace sph
