#include "core/scene/probes.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>
#include <limits>

#include <cstring>

#include "core/kernel.hpp"

namespace sph::scene {

namespace {

/// The top edge of the water along one axis: `v` holds (coordinate, d/2) per particle. Sorted from the smallest
/// coordinate, the particles fall into layers wherever more than `gap` of empty space separates a particle's
/// near edge (value - d/2) from the farthest edge reached so far (value + d/2). Measured between edges, a gap
/// is the same physical distance whatever the particles' sizes, so a refined run and a coarse one split the
/// water at the same place. The result is the highest top of a layer that is the first one or at least
/// `thick` deep (top edge minus bottom edge); with thick = infinity, the end of the first layer, the body of
/// water. -infinity when `v` is empty.
double layered_top(std::vector<std::pair<double, double>>& v, double gap, double thick) {
  if (v.empty()) return -std::numeric_limits<double>::infinity();
  std::sort(v.begin(), v.end());
  double bottom = v.front().first - v.front().second;
  double top = v.front().first + v.front().second;
  double result = top;
  bool first = true;  // the first layer counts whatever its thickness
  for (std::size_t k = 1; k < v.size(); ++k) {
    const double lo = v[k].first - v[k].second;
    if (lo - top > gap) {  // a new layer starts
      first = false;
      bottom = lo;
      top = v[k].first + v[k].second;
    } else {
      top = std::max(top, v[k].first + v[k].second);
    }
    if (first || top - bottom >= thick) result = std::max(result, top);
  }
  return result;
}

/// The top (last coordinate) + d/2 of the water in the vertical column within `band` of `at` along every
/// horizontal axis (2D: |x_i - x| <= band; 3D: a square column about the line at (x, y)), or -infinity when the
/// column is dry: a layer above a gap counts when it is at least two gaps thick, so a wave that plunges over an
/// air cavity is measured at its crest, as a wave gauge sees it, while a few isolated splash particles above the
/// surface are not.
template <int D>
std::vector<std::pair<double, double>> column(const ParticleStore<D>& store, const Horizontal<D>& at, double band) {
  std::vector<std::pair<double, double>> v;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (store.kind[i] != Kind::fluid) continue;
    bool inside = true;
    for (int a = 0; a < D - 1; ++a) inside = inside && std::abs(store.x[i][a] - at[a]) <= band;
    if (!inside) continue;
    v.emplace_back(store.x[i][D - 1], 0.5 * store.d[i]);
  }
  return v;
}

template <int D>
std::vector<std::pair<double, double>> front_edges(const ParticleStore<D>& store) {
  std::vector<std::pair<double, double>> xs;
  for (std::size_t i = 0; i < store.size(); ++i) {
    if (store.kind[i] == Kind::fluid) xs.emplace_back(store.x[i][0], 0.5 * store.d[i]);
  }
  return xs;
}

/// Every rank's pairs (each rank's own fluid), on every rank; the pairs as they are in one process.
std::vector<std::pair<double, double>> everyones(const par::Comm* comm, std::vector<std::pair<double, double>> v) {
  if (comm == nullptr || !comm->distributed()) return v;
  return comm->all_gather_values(v);
}

template <int D>
double column_top(const ParticleStore<D>& store, const Horizontal<D>& at, double band, double gap,
                  const par::Comm* comm = nullptr) {
  std::vector<std::pair<double, double>> v = everyones(comm, column<D>(store, at, band));
  return layered_top(v, gap, 2.0 * gap);
}

}  // namespace

template <int D>
double water_height(const ParticleStore<D>& store, const Horizontal<D>& at, double band, double floor, double gap) {
  const double top = column_top<D>(store, at, band, gap);
  return std::isfinite(top) ? top - floor : 0.0;
}

double water_height(const ParticleStore<2>& store, double x, double band, double floor, double gap) {
  return water_height<2>(store, Horizontal<2>::Constant(x), band, floor, gap);
}

template <int D>
double surge_front(const ParticleStore<D>& store, double origin, double gap) {
  std::vector<std::pair<double, double>> xs = front_edges<D>(store);
  const double front = layered_top(xs, gap, std::numeric_limits<double>::infinity());
  return std::isfinite(front) ? front - origin : 0.0;
}

template <int D>
double point_pressure(const ParticleStore<D>& store, const Vec<D>& point) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < store.size(); ++i) {
    // Passive particles (buffered coupling) are copies of another level's values, not fluid of their own.
    if (store.kind[i] == Kind::wall || is_passive(store.role[i]) || !(store.rho[i] > 0.0)) continue;
    const double r = (store.x[i] - point).norm();
    if (r >= 2.0 * store.h[i]) continue;
    const double w = store.m[i] / store.rho[i] * CubicSpline<D>::value(r, store.h[i]);
    num += w * store.p[i];
    den += w;
  }
  return den > 0.0 ? num / den : 0.0;
}

Probes::Probes(const Scene& scene) {
  const double band = coarsest_spacing(scene);
  gap_ = band;
  for (const Probe& p : scene.probes) {
    AnyVec at = p.y ? AnyVec(Vec<2>(p.x, *p.y)) : AnyVec(Vec<1>::Constant(p.x));
    Resolved r{p.kind, at, p.band.value_or(band), 0.0, p.position};
    switch (p.kind) {
      case ProbeKind::water_height: r.reference = scene.container.box.lo[dimension(scene) - 1]; break;
      case ProbeKind::surface_elevation: r.reference = p.datum; break;
      case ProbeKind::surge_front: r.reference = p.origin.value_or(scene.container.box.lo[0]); break;
      case ProbeKind::pressure: break;
    }
    probes_.push_back(r);
    names_.push_back(p.name);
  }
}

template <int D>
std::vector<double> Probes::measure(const ParticleStore<D>& store, const DomainT<D>* domain) const {
  const par::Comm* comm = domain != nullptr ? &domain->comm() : nullptr;
  std::vector<double> out;
  out.reserve(probes_.size());
  for (const Resolved& p : probes_) {
    switch (p.kind) {
      case ProbeKind::water_height: {
        const double top = column_top<D>(store, Horizontal<D>(p.at.data()), p.band, gap_, comm);
        out.push_back(std::isfinite(top) ? top - p.reference : 0.0);
        break;
      }
      case ProbeKind::surface_elevation: {
        const double top = column_top<D>(store, Horizontal<D>(p.at.data()), p.band, gap_, comm);
        out.push_back(std::isfinite(top) ? top - p.reference : std::numeric_limits<double>::quiet_NaN());
        break;
      }
      case ProbeKind::surge_front: {
        std::vector<std::pair<double, double>> xs = everyones(comm, front_edges<D>(store));
        const double front = layered_top(xs, gap_, std::numeric_limits<double>::infinity());
        out.push_back(std::isfinite(front) ? front - p.reference : 0.0);
        break;
      }
      case ProbeKind::pressure: {
        // Distributed: the rank owning the point's cell holds every particle within reach of it (its own fluid, its
        // halos and their ghosts), in the same relative order as one process's store (cells on the anchored
        // lattice, each in id order), so its sum is the one-process sum; the others' values are not used.
        const Vec<D> at = p.position.fixed<D>();
        const double mine = point_pressure<D>(store, at);
        out.push_back(comm == nullptr || !comm->distributed()
                          ? mine
                          : comm->all_gather_value(mine)[static_cast<std::size_t>(domain->owner_of(at))]);
        break;
      }
    }
  }
  return out;
}

template double water_height<2>(const ParticleStore<2>&, const Horizontal<2>&, double, double, double);
template double water_height<3>(const ParticleStore<3>&, const Horizontal<3>&, double, double, double);
template double surge_front<2>(const ParticleStore<2>&, double, double);
template double surge_front<3>(const ParticleStore<3>&, double, double);
template std::vector<double> Probes::measure<2>(const ParticleStore<2>&, const DomainT<2>*) const;
template std::vector<double> Probes::measure<3>(const ParticleStore<3>&, const DomainT<3>*) const;
template double point_pressure<2>(const ParticleStore<2>&, const Vec<2>&);
template double point_pressure<3>(const ParticleStore<3>&, const Vec<3>&);

}  // namespace sph::scene
