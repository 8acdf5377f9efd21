// Quantities derived from a scene (spacings, sound speed, particle estimates) and the enumerations' names.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"
#include "core/scene/scene_parser.hpp"

namespace sph::scene {

// ---- derived quantities ---------------------------------------------------------------------------------------

double FluidRegion::lattice_spacing() const { return spacing / std::pow(2.0, level); }

double gravity_magnitude(const Scene& s) {
  if (!s.effects.gravity) return 0.0;
  const Vec<2>& g = *s.effects.gravity;
  return g[0] == 0.0 ? std::abs(g[1]) : g.norm();
}

double sound_speed(const Scene& s) {
  const Material& m = s.material;
  if (m.c0) return *m.c0;
  const double factor = m.mach_factor.value_or(10.0);
  if (m.reference_speed) return factor * *m.reference_speed;
  if (m.reference_height) return sound_speed_from_height(factor, gravity_magnitude(s), *m.reference_height);
  return 0.0;
}

namespace {
int region_finest_level(const Scene& s, const FluidRegion& f) {
  int l = f.level + (s.effects.static_refinement ? 1 : 0);
  if (s.effects.refinement) l = std::max(l, s.effects.refinement->max_level);
  return l;
}
}  // namespace

int finest_level(const Scene& s) {
  int l = 0;
  for (const auto& f : s.fluid) l = std::max(l, region_finest_level(s, f));
  return l;
}

double finest_spacing(const Scene& s) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& f : s.fluid) d = std::min(d, f.spacing / std::pow(2.0, region_finest_level(s, f)));
  return d;
}

double coarsest_spacing(const Scene& s) {
  double d = 0.0;
  for (const auto& f : s.fluid) d = std::max(d, f.spacing);
  return d;
}

double wall_spacing(const Scene& s) {
  if (s.effects.lennard_jones_wall && s.effects.lennard_jones_wall->spacing) return *s.effects.lennard_jones_wall->spacing;
  return finest_spacing(s) / 2;
}

double estimated_particles(const Scene& s) {
  double fluid = 0.0;
  for (const auto& f : s.fluid) fluid += estimated_particles(f);
  if (s.effects.static_refinement) fluid *= 4.0;
  double walls = 0.0;
  if (s.effects.lennard_jones_wall) {
    double extent = 2.0 * (s.container.box.hi - s.container.box.lo).sum();
    for (const auto& o : s.obstacles) extent += 2.0 * (o.hi - o.lo).sum();
    walls = extent / wall_spacing(s);
  }
  return fluid + walls;
}

double lennard_jones_strength(const Scene& s) {
  if (!s.effects.lennard_jones_wall) return 0.0;
  const LennardJonesWall& w = *s.effects.lennard_jones_wall;
  if (w.strength) return *w.strength;
  return 5.0 * gravity_magnitude(s) * w.reference_height.value_or(0.0);
}

const char* to_string(Shape v) { return v == Shape::rectangle ? "rectangle" : "circle"; }
const char* to_string(Slip v) { return v == Slip::free_slip ? "free-slip" : "no-slip"; }
const char* to_string(Criterion v) {
  switch (v) {
    case Criterion::velocity: return "velocity";
    case Criterion::zone: return "zone";
    case Criterion::few_neighbours: return "few_neighbours";
  }
  return "?";
}
const char* to_string(Pattern v) { return v == Pattern::aap ? "aap" : "rsp"; }
const char* to_string(ProbeKind v) {
  switch (v) {
    case ProbeKind::water_height: return "water_height";
    case ProbeKind::surge_front: return "surge_front";
    case ProbeKind::surface_elevation: return "surface_elevation";
    case ProbeKind::pressure: return "pressure";
  }
  return "?";
}

std::vector<std::string> particle_field_names() {
  std::vector<std::string> names;
  ParticleStore<2> store;
  store.for_each_field([&](const auto& f) { names.emplace_back(f.name()); });
  return names;
}

double estimated_particles(const FluidRegion& f) {
  const double d = f.lattice_spacing();
  if (f.shape == Shape::rectangle) {
    return std::floor((f.rect.hi[0] - f.rect.lo[0]) / d + 1e-9) * std::floor((f.rect.hi[1] - f.rect.lo[1]) / d + 1e-9);
  }
  return std::numbers::pi * (f.radius / d + 1.0) * (f.radius / d + 1.0);
}

}  // namespace sph::scene
