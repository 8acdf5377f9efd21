#pragma once
// Probes: measurements of the fluid written to the time series (docs/SCENES.md, "probes").
//   water_height       H = max(y_i + d_i/2) - floor over fluid particles with |x_i - x| <= band
//                      (the paper's H(t) at a wall; H = H0 at t = 0 for a lattice column)
//   surface_elevation  max(y_i + d_i/2) - datum over the same column (NaN when the column is dry)
//   surge_front        Z = max(x_i + d_i/2) - origin over every fluid particle (the paper's Z(t))
// Each maximum leaves isolated splash particles out. Sorted from the bottom (or from the back wall), the
// particles fall into layers wherever more than one coarse spacing of empty space separates a particle's edge
// from the edge reached so far (edges, not centres: the same gap at any particle size). The surge front is the
// end of the first layer, the body of water. A column's top is the highest top of a layer that is the lowest
// one or at least two coarse spacings thick: a wave plunging over an air cavity counts, as a wave gauge
// sees it, and a few droplets above the surface do not.
//   pressure           Shepard-normalised SPH interpolation of p at a point over fluid and ghost particles,
//                      sum_j V_j p_j W(r, h_j) / sum_j V_j W(r, h_j), V_j = m_j / rho_j (0 when no particle
//                      reaches the point)
// Each probe is one pass over the store, run only at output times.
#include <string>
#include <vector>

#include "core/domain.hpp"
#include "core/particle_store.hpp"
#include "core/scene/scene.hpp"

namespace sph::scene {

/// A point in the horizontal plane: x in 2D, (x, y) in 3D.
template <int D>
using Horizontal = Vec<D - 1>;

/// The water height at a gauge: the column's top minus `floor` (0 when dry). In 3D a gauge is the vertical line
/// at (x, y), sampled over the square column of half-width `band` about it.
template <int D>
double water_height(const ParticleStore<D>& store, const Horizontal<D>& at, double band, double floor, double gap);
double water_height(const ParticleStore<2>& store, double x, double band, double floor, double gap);
/// The surge front along x, over every fluid particle (2D or 3D).
template <int D>
double surge_front(const ParticleStore<D>& store, double origin, double gap);
/// The pressure at a point (a sensor on a wall: the ghosts across the wall take part), in 2D or 3D.
template <int D>
double point_pressure(const ParticleStore<D>& store, const Vec<D>& point);

class Probes {
 public:
  explicit Probes(const Scene& scene);
  const std::vector<std::string>& names() const { return names_; }
  /// One value per probe, in scene order (D the scene's dimension). Distributed (`domain`), collective: every
  /// rank gets the values of the whole fluid, with the same bits as in one process.
  template <int D>
  std::vector<double> measure(const ParticleStore<D>& store, const DomainT<D>* domain = nullptr) const;

 private:
  struct Resolved {
    ProbeKind kind;
    AnyVec at;  // a gauge's horizontal position: x in 2D, (x, y) in 3D
    double band, reference;
    AnyVec position;
  };
  std::vector<Resolved> probes_;
  double gap_ = 0.0;  // one coarse spacing: a wider empty space separates splash from the body of water
  std::vector<std::string> names_;
};

}  // namespace sph::scene
