// Quantities derived from a scene (spacings, sound speed, particle estimates) and the enumerations' names.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>

#include "core/cell_grid.hpp"
#include "core/equation_of_state.hpp"
#include "core/particle_store.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_choices.hpp"
#include "core/scene/scene_parser.hpp"

namespace sph::scene {

// ---- derived quantities ---------------------------------------------------------------------------------------

double FluidRegion::lattice_spacing() const { return spacing / std::pow(2.0, level); }

int dimension(const Scene& s) { return s.container.box.lo.size() == 3 ? 3 : 2; }

double gravity_magnitude(const Scene& s) {
  if (!s.effects.gravity || s.effects.gravity->size() == 0) return 0.0;
  const AnyVec& g = *s.effects.gravity;
  const Eigen::Index up = g.size() - 1;
  return g.head(up).isZero(0.0) ? std::abs(g[up]) : g.norm();
}

double sound_speed(const Scene& s) {
  const Material& m = s.material;
  if (m.c0) return *m.c0;
  const double factor = m.mach_factor.value_or(kDefaultMachFactor);
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

double estimated_particles(const Scene& s) { return estimated_fluid_particles(s) + estimated_wall_particles(s); }

double estimated_fluid_particles(const Scene& s) {
  double fluid = 0.0;
  for (const auto& f : s.fluid) fluid += estimated_particles(f);
  // A static refinement pass splits each particle into 2^D daughters.
  return s.effects.static_refinement ? std::pow(2.0, dimension(s)) * fluid : fluid;
}

namespace {

/// For each wall face of the scene, the product over its in-plane axes of f(extent along that axis).
template <class F>
double sum_over_walls(const Scene& s, F per_axis) {
  return with_dimension(s, [&](auto dim) {
    constexpr int D = decltype(dim)::value;
    double total = 0.0;
    for (const Wall<D>& w : solver_settings<D>(s).geometry.walls()) {
      double face = 1.0;
      for (int a = 0; a < D; ++a)
        if (a != w.axis) face *= per_axis(w.hi[a] - w.lo[a]);
      total += face;
    }
    return total;
  });
}

}  // namespace

double estimated_wall_particles(const Scene& s) {
  if (!s.effects.lennard_jones_wall) return 0.0;
  // On each face, one particle every wall spacing from edge to edge: ceil(extent / spacing) + 1 of them along
  // each of its in-plane axes; extent / spacing + 2 is a little above it.
  const double ws = wall_spacing(s);
  return sum_over_walls(s, [ws](double extent) { return extent / ws + 2.0; });
}

double estimated_ghost_particles(const Scene& s) {
  if (!s.effects.ghost_walls) return 0.0;
  // A wall mirrors the particles within 2 h = 2 h_factor d of it (and projecting onto it); on the starting
  // lattices that is at most rows = ceil(2 h_factor) layers of (extent / d + 1) particles along each in-plane
  // axis, d the finest starting lattice spacing (halved by a static refinement pass). Particles near two or
  // three perpendicular walls also get edge and corner images: widening each face by `rows` along each of its
  // axes counts them, since there are no more edges or corners at a face than it has sides. No particle has
  // more than kMaxGhosts images (GhostBuilderT).
  double d = std::numeric_limits<double>::infinity();
  for (const auto& f : s.fluid) d = std::min(d, f.lattice_spacing());
  if (s.effects.static_refinement) d /= 2.0;
  const double rows = std::ceil(2.0 * s.h_factor);
  const double bound = rows * sum_over_walls(s, [&](double extent) { return extent / d + 1.0 + rows; });
  const double most_images = dimension(s) == 3 ? GhostBuilderT<3>::kMaxGhosts : GhostBuilderT<2>::kMaxGhosts;
  return std::min(bound, most_images * estimated_fluid_particles(s));
}

double lennard_jones_strength(const Scene& s) {
  if (!s.effects.lennard_jones_wall) return 0.0;
  const LennardJonesWall& w = *s.effects.lennard_jones_wall;
  if (w.strength) return *w.strength;
  return 5.0 * gravity_magnitude(s) * w.reference_height.value_or(0.0);
}

MemoryEstimate estimated_memory(const Scene& s, int threads) {
  // The store holds the fluid, ghost and wall particles, and each of them costs, in bytes:
  //  - the store's fields (ParticleStore::bytes_per_particle()) twice: every Field keeps a gather scratch as
  //    large as itself once the store has been reordered (every step reorders it);
  //  - the fields a third time: the watchdog's rollback copy of the store;
  //  - the step's neighbour workspace (Simulation::prepare_neighbours): expansion offsets, expansion and
  //    gather sources (three indices), their image numbers (two bytes) and the expanded positions.
  // The cell grid adds its order, keys and cells (CellGrid::bytes_bound: cells at the full budget).
  // This is the start. Dynamic refinement splits particles into four as the run goes (up to the scene's
  // max_level) and grows all of it; outputs take a field's worth more while they write.
  const double n = estimated_fluid_particles(s) + estimated_ghost_particles(s) + estimated_wall_particles(s);
  return with_dimension(s, [&](auto dim) {
    constexpr int D = decltype(dim)::value;
    constexpr double per_particle = 3.0 * ParticleStore<D>::bytes_per_particle() + 3.0 * sizeof(std::uint32_t) +
                                    2.0 * sizeof(std::int8_t) + sizeof(Vec<D>);
    const auto grid = static_cast<double>(CellGrid<D>::bytes_bound(static_cast<std::size_t>(std::min(n, 1e15)), threads));
    return MemoryEstimate{n, n * per_particle + grid};
  });
}

namespace {

/// 31096143 -> "31,096,143".
std::string grouped(double x) {
  const std::string digits = std::to_string(static_cast<unsigned long long>(std::llround(std::max(0.0, x))));
  std::string out;
  for (std::size_t k = 0; k < digits.size(); ++k) {
    if (k > 0 && (digits.size() - k) % 3 == 0) out += ',';
    out += digits[k];
  }
  return out;
}

/// x with one decimal ("13.4") or none ("454").
std::string decimals(double x, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}

/// "13.4 GiB (31,096,143 particles at ~454 B each)".
std::string amount(const MemoryEstimate& m) {
  const double each = m.particles > 0.0 ? m.bytes / m.particles : 0.0;
  return memory_text(m.bytes) + " (" + grouped(m.particles) + " particles at ~" +
         (each >= 1000.0 ? decimals(each / 1000.0, 1) + " kB" : decimals(each, 0) + " B") + " each)";
}

}  // namespace

std::string memory_text(double bytes) {
  constexpr double mib = 1024.0 * 1024.0, gib = 1024.0 * mib;
  return bytes >= gib ? decimals(bytes / gib, 1) + " GiB" : decimals(bytes / mib, 0) + " MiB";
}

std::string to_string(const MemoryEstimate& m) { return "about " + amount(m); }

std::string memory_refusal(const MemoryEstimate& need, double available_bytes) {
  if (need.bytes <= available_bytes) return "";
  return "the scene needs about " + amount(need) + " but " + memory_text(available_bytes) + " are available";
}

// The names live in one table per enumeration (scene_choices.hpp).
const char* to_string(Shape v) { return choice_name(v); }
const char* to_string(Slip v) { return choice_name(v); }
const char* to_string(Criterion v) { return choice_name(v); }
const char* to_string(Outflow v) { return choice_name(v); }
const char* to_string(Pattern v) { return choice_name(v); }
const char* to_string(MergeGroups v) { return choice_name(v); }
const char* to_string(DaughterDensity v) { return choice_name(v); }
const char* to_string(ProbeKind v) { return choice_name(v); }
const char* to_string(GhostPressure v) { return choice_name(v); }
const char* to_string(TimeStepping v) { return choice_name(v); }
const char* to_string(TimePredictor v) { return choice_name(v); }

std::vector<std::string> particle_field_names() {
  std::vector<std::string> names;
  ParticleStore<2> store;
  store.for_each_field([&](const auto& f) { names.emplace_back(f.name()); });
  return names;
}

double estimated_particles(const FluidRegion& f) {
  const double d = f.lattice_spacing();
  if (f.shape == Shape::rectangle) {
    double n = 1.0;
    for (Eigen::Index a = 0; a < f.rect.lo.size(); ++a) n *= std::floor((f.rect.hi[a] - f.rect.lo[a]) / d + 1e-9);
    return n;
  }
  const double r = f.radius / d + 1.0;
  return f.centre.size() == 3 ? 4.0 / 3.0 * std::numbers::pi * r * r * r : std::numbers::pi * r * r;
}

}  // namespace sph::scene
