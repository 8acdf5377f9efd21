#pragma once
// The scene model: a plain description of one run (geometry, fluid, material, effects, time, probes,
// output), exactly what a scene file (JSON, docs/SCENES.md) says, with the file's defaults filled in.
// Parsing (scene_parser.hpp) fills it and validates it; building (scene_builder.hpp) turns it into a
// ready Simulation. An effect absent from the scene is std::nullopt here and is not computed.
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "core/boundary/ghosts.hpp"
#include "core/boundary/wall.hpp"
#include "core/refinement/refinement_settings.hpp"
#include "core/solver_settings.hpp"
#include "core/types.hpp"

namespace sph::scene {

/// The scene's dimension, 2 or 3, is the container's: the number of coordinates of its corners. Every point and
/// vector of the scene has that many ("up" is the last axis: y in 2D, z in 3D), and is held as an AnyVec (an
/// absent vector with a zero default is empty) until the solver of that dimension is built.

/// Axis-aligned box [lo, hi] (m): a rectangle in 2D, a cuboid in 3D.
using Rect = AnyBox;

struct Container {
  Rect box;
  bool open_top = true;
  Outflow outflow = Outflow::stop;  // fluid leaving over the open top's rim: stop the run, or remove it
  bool operator==(const Container&) const = default;
};

enum class Shape { rectangle, circle };

/// A block of fluid filled with a square (cubic in 3D) lattice, particles at cell centres. A "circle" is a disc
/// in 2D and a ball in 3D.
struct FluidRegion {
  Shape shape = Shape::rectangle;
  Rect rect;                           // rectangle
  AnyVec centre;                       // circle
  double radius = 0.0;                 // circle (m)
  double spacing = 0.0;                // d^0: the level-0 spacing (m); the lattice is d^0 / 2^level
  int level = 0;                       // initial refinement level of the region's particles
  AnyVec velocity;                     // initial velocity (m/s); empty: at rest
  bool hydrostatic = false;            // hydrostatic initial density (needs gravity along -up)
  std::optional<double> surface;       // height of the free surface for the hydrostatic start (default: top)
  bool operator==(const FluidRegion&) const = default;

  double lattice_spacing() const;
};

/// rho0 and the sound speed: c0 given directly, or c0 = mach_factor * v_ref with v_ref a speed or the
/// free-fall speed sqrt(2 g H) from a reference height H.
inline constexpr double kDefaultMachFactor = 10.0;  // c0 = 10 v_ref: about 1 % density fluctuation

struct Material {
  double rho0 = 1000.0;
  double gamma = 7.0;
  std::optional<double> c0;
  std::optional<double> mach_factor;
  std::optional<double> reference_speed;
  std::optional<double> reference_height;
  bool operator==(const Material&) const = default;
};

// The effects' constants are the solver's own settings (core/solver_settings.hpp): one declaration of each key's
// default, which the parser reads.
using ArtificialViscosity = ViscositySettings;
/// Monaghan's artificial stress (optional, off by default): a repulsion between particles under tension.
using ArtificialStress = ArtificialStressSettings;
/// Density diffusion, delta-SPH with the hydrostatic correction (optional, off by default).
using DensityDiffusion = DensityDiffusionSettings;

/// Fixed wall particles with the Lennard-Jones repulsion, eq. (10). D given directly (strength) or as
/// 5 g H from a reference height.
struct LennardJonesWall {
  std::optional<double> strength;
  std::optional<double> reference_height;
  double r0_factor = 0.5;
  std::optional<double> spacing;  // default: half the finest fluid spacing the scene can reach
  bool operator==(const LennardJonesWall&) const = default;
};

using Slip = GhostSlip;
// Dynamic refinement and coarsening are the refinement stage's settings (core/refinement/refinement_settings.hpp).
using Criterion = refine::CriterionKind;
using Pattern = refine::Pattern;
using MergeGroups = refine::MergeGroups;
using DaughterDensity = refine::DaughterDensity;
using Coarsening = refine::CoarseningSettings;
using Refinement = refine::RefinementSettings;

/// Refinement once at set-up: every fluid particle (no box) or those inside the box.
struct StaticRefinement {
  std::optional<Rect> box;
  Pattern pattern = Pattern::aap;
  double rsp_k = 1.0;
  bool operator==(const StaticRefinement&) const = default;
};

struct Effects {
  std::optional<AnyVec> gravity;
  std::optional<ArtificialViscosity> artificial_viscosity;
  std::optional<ArtificialStress> artificial_stress;
  std::optional<DensityDiffusion> density_diffusion;
  std::optional<LennardJonesWall> lennard_jones_wall;
  std::optional<Slip> ghost_walls;
  GhostPressure ghost_pressure = GhostPressure::hydrostatic;
  std::optional<Refinement> refinement;
  std::optional<StaticRefinement> static_refinement;
  bool operator==(const Effects&) const = default;
};

struct Time {
  double end = 0.0;
  double cfl = 0.2;
  std::optional<double> output_interval;  // default end / 100
  double dt_max = 1.0;
  TimeStepping stepping = TimeStepping::global;  // "global" or "per_level" (core/integrator.hpp)
  int bin_jump = kDefaultBinJump;                // per_level: the bin limiter (Integrator::limit_bins)
  TimePredictor predictor = TimePredictor::extrapolated;  // Integrator::drift
  bool operator==(const Time&) const = default;

  double interval() const { return output_interval.value_or(end / 100.0); }
};

enum class ProbeKind { water_height, surge_front, surface_elevation, pressure };

/// A measurement written to the time series every output interval (docs/SCENES.md, "probes").
struct Probe {
  ProbeKind kind = ProbeKind::water_height;
  std::string name;
  double x = 0.0;                       // water_height, surface_elevation: the column sampled
  std::optional<double> y;              // its y in 3D (a gauge is the vertical line at (x, y)); not in 2D
  std::optional<double> band;           // half-width of the sampled column (default: largest d^0)
  std::optional<double> origin;         // surge_front: where Z is measured from (default container lo.x)
  double datum = 0.0;                   // surface_elevation: elevation measured from this y
  AnyVec position;                      // pressure
  bool operator==(const Probe&) const = default;
};

struct Output {
  std::string folder;                   // default "out/<name>"
  bool frames = true;
  std::optional<double> frame_interval;  // default time.output_interval
  std::vector<std::string> fields;      // empty: every field
  bool operator==(const Output&) const = default;
};

struct Scene {
  std::string name = "scene";
  std::string description;
  Container container;
  std::vector<Rect> obstacles;
  std::vector<FluidRegion> fluid;
  double h_factor = 1.2;
  Material material;
  Effects effects;
  Time time;
  std::vector<Probe> probes;
  Output output;
  bool operator==(const Scene&) const = default;
};

// Quantities derived from a scene (the rules are in docs/SCENES.md).

/// The scene's dimension: 2 or 3 (the container's coordinates).
int dimension(const Scene& s);
/// Calls f(std::integral_constant<int, D>{}) with D the scene's dimension, and returns what it returns.
template <class F>
decltype(auto) with_dimension(const Scene& s, F&& f) {
  if (dimension(s) == 3) return f(std::integral_constant<int, 3>{});
  return f(std::integral_constant<int, 2>{});
}
/// |g| along -up used for hydrostatic starts and reference heights (0 without gravity).
double gravity_magnitude(const Scene& s);
/// The sound speed c0 the scene resolves to.
double sound_speed(const Scene& s);
/// The deepest level any particle can reach (initial level, static and dynamic refinement).
int finest_level(const Scene& s);
/// The finest fluid spacing the scene can reach: min over regions of d^0 / 2^finest_level.
double finest_spacing(const Scene& s);
/// The Lennard-Jones wall-particle spacing (given, or half the finest spacing).
double wall_spacing(const Scene& s);
/// The Lennard-Jones strength D (given, or 5 g H_ref).
double lennard_jones_strength(const Scene& s);
/// About how many particles the scene starts with: fluid (after a static refinement pass, which at most
/// quadruples a region) and Lennard-Jones wall particles. What validation bounds, usable before building.
double estimated_particles(const Scene& s);
/// The lattice points of one fluid region at its lattice spacing (an upper estimate for a circle).
double estimated_particles(const FluidRegion& f);
/// The fluid particles the scene starts with: every region's lattice, quadrupled by a static refinement pass.
double estimated_fluid_particles(const Scene& s);
/// The Lennard-Jones wall particles (0 without them), a little above the count placed along the walls.
double estimated_wall_particles(const Scene& s);
/// An upper bound on the ghost particles at the start (0 without ghost walls), from the walls' lengths.
double estimated_ghost_particles(const Scene& s);

/// What a run of the scene holds in memory at its start: particles (fluid, ghosts, walls) and bytes.
struct MemoryEstimate {
  double particles = 0.0;
  double bytes = 0.0;
};
/// About how much memory a run of the scene needs at its start, with `threads` threads, before anything is
/// allocated (scene.cpp lists what it counts). Dynamic refinement can add particles later; this is the start.
MemoryEstimate estimated_memory(const Scene& s, int threads);
/// "about 13.4 GiB (31,096,143 particles at ~454 B each)".
std::string to_string(const MemoryEstimate& m);
/// A byte count in GiB (or MiB below one GiB): "13.4 GiB".
std::string memory_text(double bytes);
/// The refusal when a run needing `need` does not fit in `available_bytes` ("" when it fits):
/// "the scene needs about 41.3 GiB (...) but 22.8 GiB are available".
std::string memory_refusal(const MemoryEstimate& need, double available_bytes);
/// The largest level-0 spacing of the fluid regions (default probe band).
double coarsest_spacing(const Scene& s);

const char* to_string(Shape v);
const char* to_string(Slip v);
const char* to_string(Criterion v);
const char* to_string(Pattern v);
const char* to_string(MergeGroups v);
const char* to_string(DaughterDensity v);
const char* to_string(ProbeKind v);
const char* to_string(Outflow v);
const char* to_string(GhostPressure v);
const char* to_string(TimeStepping v);
const char* to_string(TimePredictor v);

}  // namespace sph::scene
