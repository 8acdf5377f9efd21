#pragma once
// Ghost particles (section 2.4): every fluid particle within 2 h_i of a wall is mirrored across it, and a
// particle near two perpendicular walls (a corner) also gets the doubly reflected ghost. Ghosts copy
// mass, density, pressure and smoothing length; their velocity is reflected (free-slip: normal part
// reversed) or reversed (no-slip). The solver rebuilds them from scratch each step
// (Simulation::prepare_neighbours): one stream expansion through the store's registry, output_count() outputs
// per particle (old ghosts dropped), composed with the cell sort into one gather, then make_ghost() on each
// copy that is an image; the result is deterministic at any thread count.
#include <array>
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
  /// Up to two walls and one corner per particle (the container's corners).
  static constexpr int kMaxGhosts = 3;

  GhostBuilder(std::vector<Wall2> walls, GhostSlip slip, GhostPressure pressure = GhostPressure::mirrored,
               Vec<2> gravity = Vec<2>::Zero(), TaitEquationOfState eos = {})
      : walls_(std::move(walls)), slip_(slip), pressure_(pressure), gravity_(std::move(gravity)), eos_(eos) {}

  const std::vector<Wall2>& walls() const { return walls_; }
  GhostSlip slip() const { return slip_; }

  /// The ghost images of a particle at x with smoothing length h: positions and velocities.
  struct Images {
    int count = 0;
    std::array<Vec<2>, kMaxGhosts> x;
    std::array<Vec<2>, kMaxGhosts> v;
  };

  Images images(const Vec<2>& x, const Vec<2>& v, double h) const {
    Images out;
    std::array<int, 2> near{-1, -1};
    int nnear = 0;
    const double reach = 2.0 * h;
    for (int w = 0; w < static_cast<int>(walls_.size()) && nnear < 2; ++w) {
      const Wall2& wall = walls_[static_cast<std::size_t>(w)];
      const double dist = wall.signed_distance(x);
      if (dist < 0.0 || dist >= reach || !wall.projects_onto(x)) continue;
      near[static_cast<std::size_t>(nnear++)] = w;
      out.x[static_cast<std::size_t>(out.count)] = wall.reflect_point(x);
      out.v[static_cast<std::size_t>(out.count)] = ghost_velocity(v, wall, nullptr);
      ++out.count;
    }
    if (nnear == 2) {
      const Wall2& a = walls_[static_cast<std::size_t>(near[0])];
      const Wall2& b = walls_[static_cast<std::size_t>(near[1])];
      if (std::abs(a.n.dot(b.n)) < 1e-12) {
        out.x[static_cast<std::size_t>(out.count)] = b.reflect_point(a.reflect_point(x));
        out.v[static_cast<std::size_t>(out.count)] = ghost_velocity(v, a, &b);
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
