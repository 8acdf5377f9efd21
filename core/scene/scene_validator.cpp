// The value rules of a scene (validate_scene). Each key's own range is declared with the key (scene_keys.cpp) and
// checked first, through the registry; what follows here are the rules across keys: geometry, consistency
// between sections, resolution and size. A broken rule throws SceneError naming the key path; the parser
// (scene_parser.cpp) checks structure and types first.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "core/kernel.hpp"
#include "core/scene/scene_parser.hpp"
#include "core/scene/scene_rules.hpp"
#include "core/scene/scene_schema.hpp"

namespace sph::scene {

using detail::element;
using detail::fail;
using detail::join;
using detail::list;
using detail::num;

namespace {

// Every box and point here has the scene's dimension (checked first by validate_scene), so the loops run over the
// axes of whichever it is.

/// "[1, 2]" or "[1, 2, 3]".
std::string point(const AnyVec& p) {
  std::string s = "[";
  for (Eigen::Index a = 0; a < p.size(); ++a) s += (a ? ", " : "") + num(p[a]);
  return s + "]";
}

void valid_rect(const Rect& r, const std::string& path) {
  if (!(r.hi.array() > r.lo.array()).all()) {
    fail(join(path, "hi"), "must be greater than lo on every axis (lo = " + point(r.lo) + ", hi = " + point(r.hi) + ")");
  }
}

/// Whether the open boxes a and b, each shrunk by t, share a point.
bool rects_overlap(const Rect& a, const Rect& b, double t = 0.0) {
  return (a.lo.array() < b.hi.array() - t).all() && (b.lo.array() < a.hi.array() - t).all();
}

double distance_to_rect(const AnyVec& p, const Rect& r) {
  return (r.lo - p).cwiseMax(p - r.hi).cwiseMax(0.0).norm();
}

constexpr double kTol = 1e-9;
constexpr double kMaxParticles = 5.0e7;

bool inside(const Rect& inner, const Rect& outer) {
  const double t = kTol * std::max(1.0, (outer.hi - outer.lo).cwiseAbs().maxCoeff());
  return (inner.lo.array() >= outer.lo.array() - t).all() && (inner.hi.array() <= outer.hi.array() + t).all();
}

Rect bounds(const FluidRegion& f) {
  if (f.shape == Shape::rectangle) return f.rect;
  const AnyVec r = AnyVec::Base::Constant(f.centre.size(), f.radius);
  return Rect{f.centre - r, f.centre + r};
}

/// Every vector of the scene has the container's dimension (an empty one is a zero default). The container's
/// lo fixes it, and is read first.
void check_dimension(const Scene& s) {
  const Eigen::Index dim = s.container.box.lo.size();
  const std::string axes = dim == 3 ? "three numbers [x, y, z]" : "two numbers [x, y]";
  schema::for_each_vector(schema::scene_section(), s, "", [&](const std::string& path, const AnyVec& v) {
    if (v.size() != 0 && v.size() != dim) {
      fail(path, "has " + std::to_string(v.size()) + " numbers, but the scene is " + std::to_string(dim) +
                     "D (container.lo has " + std::to_string(dim) + "): write " + axes);
    }
  });
}

/// A region as the scene gives it, for messages: "rectangle [0, 0] .. [1, 2]", "circle at [8, 7] radius 1".
std::string describe(const FluidRegion& f) {
  if (f.shape == Shape::rectangle) return "rectangle " + point(f.rect.lo) + " .. " + point(f.rect.hi);
  return "circle at " + point(f.centre) + " radius " + num(f.radius);
}

/// Whether two fluid regions would share particles. Regions may touch: a rectangle's particles lie d/2 inside
/// its edges, so two rectangles sharing an edge tile without a common point, and a circle touching a
/// rectangle keeps its particles outside the rectangle's. Two circles may not touch: each lattice reaches its
/// circle, so both can hold the point of contact. `t` absorbs rounding in coordinates given as decimals.
bool regions_overlap(const FluidRegion& a, const FluidRegion& b, double t) {
  if (a.shape == Shape::rectangle && b.shape == Shape::rectangle) {
    return rects_overlap(a.rect, b.rect, t);
  }
  if (a.shape == Shape::circle && b.shape == Shape::circle) return (a.centre - b.centre).norm() < a.radius + b.radius + t;
  const FluidRegion& circle = a.shape == Shape::circle ? a : b;
  const FluidRegion& rect = a.shape == Shape::circle ? b : a;
  return distance_to_rect(circle.centre, rect.rect) < circle.radius - t;
}

void validate_region(const Scene& s, const FluidRegion& f, const std::string& path) {
  if (f.shape == Shape::rectangle) valid_rect(f.rect, path);
  const double d = f.lattice_spacing();
  if (!inside(bounds(f), s.container.box)) {
    fail(path, std::string("the ") + to_string(f.shape) + " reaches outside the container");
  }
  for (std::size_t k = 0; k < s.obstacles.size(); ++k) {
    const Rect& o = s.obstacles[k];
    const bool overlap = f.shape == Shape::rectangle ? rects_overlap(f.rect, o)
                                                     : distance_to_rect(f.centre, o) < f.radius - kTol;
    if (overlap) fail(path, "overlaps obstacles[" + std::to_string(k) + "] (fluid must start outside every obstacle)");
  }
  const double n = estimated_particles(f);
  if (f.shape == Shape::rectangle && n < 1.0) {
    fail(join(path, "spacing"), "the rectangle holds no particle at lattice spacing " + num(d) + " m");
  }
  if (n > kMaxParticles) {
    fail(join(path, "spacing"), "would create about " + num(n) + " particles (limit " + num(kMaxParticles) + ")");
  }
  if (f.hydrostatic) {
    if (!s.effects.gravity) fail(join(path, "hydrostatic"), "needs effects.gravity");
    const AnyVec& g = *s.effects.gravity;
    const Eigen::Index up = g.size() - 1;
    if (!g.head(up).isZero(0.0) || !(g[up] < 0.0)) {
      fail(join(path, "hydrostatic"), up == 2 ? "needs gravity pointing along -z ([0, 0, -g])"
                                              : "needs gravity pointing along -y ([0, -g])");
    }
    if (f.shape == Shape::circle && !f.surface) fail(join(path, "surface"), "required for a hydrostatic circle");
  } else if (f.surface) {
    fail(join(path, "surface"), "only used with \"hydrostatic\": true");
  }
}

void validate_probe(const Scene& s, const Probe& p, const std::string& path) {
  const Rect& c = s.container.box;
  if (p.kind == ProbeKind::water_height || p.kind == ProbeKind::surface_elevation) {
    if (p.x < c.lo[0] - kTol || p.x > c.hi[0] + kTol) fail(join(path, "x"), "must lie within the container's x range");
    if (dimension(s) == 3) {
      if (!p.y) fail(join(path, "y"), "missing required key in a 3D scene (the gauge is the vertical line at (x, y))");
      if (*p.y < c.lo[1] - kTol || *p.y > c.hi[1] + kTol) fail(join(path, "y"), "must lie within the container's y range");
    } else if (p.y) {
      fail(join(path, "y"), "only in a 3D scene (a 2D gauge is the vertical line at x)");
    }
  }
  if (p.kind == ProbeKind::pressure && !inside(Rect{p.position, p.position}, c)) {
    fail(join(path, "position"), "must lie inside the container");
  }
  if (p.name.empty()) fail(join(path, "name"), "must not be empty");
  for (char ch : p.name) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) {
      fail(join(path, "name"), "may hold only letters, digits and '_' (it names a CSV column; got '" + p.name + "')");
    }
  }
}

}  // namespace

void validate_scene(const Scene& s) {
  schema::check_section(schema::scene_section(), s, "");
  check_dimension(s);
  if (s.name.empty()) fail("name", "must not be empty");
  for (char ch : s.name) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.')) {
      fail("name", "may hold only letters, digits, '_', '-' and '.' (it names the output folder; got '" + s.name + "')");
    }
  }
  valid_rect(s.container.box, "container");
  if (s.container.outflow == Outflow::remove && !s.container.open_top) {
    fail("container.outflow", "\"remove\" needs an open top (open_top: true): a closed container has no opening to "
                              "leave through");
  }
  for (std::size_t k = 0; k < s.obstacles.size(); ++k) {
    const std::string path = element("obstacles", k);
    valid_rect(s.obstacles[k], path);
    if (!inside(s.obstacles[k], s.container.box)) fail(path, "must lie inside the container");
  }

  // Material and effects come first: the regions' rules (hydrostatic) depend on gravity.
  const Material& m = s.material;
  if (m.c0) {
    if (m.mach_factor || m.reference_speed || m.reference_height) {
      fail("material", "give either c0, or mach_factor with reference_speed or reference_height, not both");
    }
  } else {
    if (m.reference_speed && m.reference_height) {
      fail("material", "give reference_speed or reference_height, not both");
    }
    if (m.reference_height && gravity_magnitude(s) <= 0.0) {
      fail("material.reference_height", "needs effects.gravity (v_ref = sqrt(2 g H))");
    }
    if (!m.reference_speed && !m.reference_height) {
      fail("material.c0", "missing required key (or give mach_factor with reference_speed or reference_height)");
    }
  }

  const Effects& e = s.effects;
  if (e.gravity && !(e.gravity->norm() > 0.0)) fail("effects.gravity", "must not be zero (remove the key to turn gravity off)");
  if (e.refinement) {
    const Refinement& r = *e.refinement;
    const std::string p = "effects.refinement";
    if (r.criterion == Criterion::zone) valid_rect(r.zone, p + ".zone");
    if (r.coupling == LevelCoupling::buffered) {
      // A shadow takes its family's place back (retract_buffered): the families of one parent only.
      if (r.coarsening && r.coarsening->groups != refine::MergeGroups::family) {
        fail(p + ".coarsening.groups", "\"buffered\" merges a shadow's own daughters back into it: use \"family\" (or "
                                       "coupling \"mixed\")");
      }
      // In 3D the cubic lattice's alternating-layer shear mode grows under pressure at some h / d (1.2 among them), and
      // a split seeds it: the point of buffered levels, still water that stays still, then fails whatever the coupling
      // does (docs/METHOD.md, "Three dimensions: a lattice mode").
      if (dimension(s) == 3 && CubicSpline<3>::layer_shear_stiffness(s.h_factor) < 0.0) {
        fail("h_factor", num(s.h_factor) + " with \"buffered\" levels in 3D: at this h / d the cubic lattice's "
                         "alternating-layer shear mode grows under pressure, and a split sets it off (docs/METHOD.md, "
                         "\"Three dimensions: a lattice mode\"); use 1.3, where it is stable");
      }
      // No pair mixes levels, so particles of different levels that no split made (a static refinement, fluid regions
      // set up at other levels) would not meet at all: they have no shadows or buffer particles between them.
      if (e.static_refinement) fail(p + ".coupling", "\"buffered\" cannot follow effects.static_refinement (its splits leave no shadows); use \"mixed\"");
      for (std::size_t k = 1; k < s.fluid.size(); ++k) {
        if (s.fluid[k].level != s.fluid[0].level) {
          fail(p + ".coupling", "\"buffered\" needs every fluid region at one starting level (" + element("fluid", k) +
                                    " is at level " + std::to_string(s.fluid[k].level) + ", fluid[0] at " +
                                    std::to_string(s.fluid[0].level) + "): levels meet only through splits");
        }
      }
    }
    if (const auto& c = r.coarsening) {
      const std::string q = p + ".coarsening";
      if (r.criterion == Criterion::velocity && !(c->v_threshold > 0.0 && c->v_threshold < r.v_threshold)) {
        fail(q + ".v_threshold", "must be above 0 and below the split threshold " + num(r.v_threshold) +
                                     " m/s, or a family could split and merge at alternate checks (got " + num(c->v_threshold) + ")");
      }
      if (r.criterion == Criterion::few_neighbours && c->min_neighbours <= r.min_neighbours) {
        fail(q + ".min_neighbours", "must be above the split count " + std::to_string(r.min_neighbours) +
                                        ", or a family could split and merge at alternate checks (got " +
                                        std::to_string(c->min_neighbours) + ")");
      }
    }
  }
  if (e.static_refinement) {
    if (e.static_refinement->box) valid_rect(*e.static_refinement->box, "effects.static_refinement.box");
  }

  if (s.fluid.empty()) fail("fluid", "at least one fluid region is required");
  double total = 0.0;
  for (std::size_t k = 0; k < s.fluid.size(); ++k) {
    validate_region(s, s.fluid[k], element("fluid", k));
    total += estimated_particles(s.fluid[k]);
  }
  if (total > kMaxParticles) fail("fluid", "the regions would create about " + num(total) + " particles (limit " + num(kMaxParticles) + ")");
  // Overlapping regions would fill their common part twice (two particles, twice the mass, at each point).
  const double tol = kTol * std::max(1.0, (s.container.box.hi - s.container.box.lo).cwiseAbs().maxCoeff());
  for (std::size_t k = 0; k < s.fluid.size(); ++k) {
    for (std::size_t j = 0; j < k; ++j) {
      if (!regions_overlap(s.fluid[j], s.fluid[k], tol)) continue;
      const bool circles = s.fluid[j].shape == Shape::circle && s.fluid[k].shape == Shape::circle;
      fail(element("fluid", k), std::string(circles ? "overlaps or touches " : "overlaps ") + element("fluid", j) + " (" +
                                    element("fluid", k) + ": " + describe(s.fluid[k]) + "; " + element("fluid", j) +
                                    ": " + describe(s.fluid[j]) + "); fluid regions must not overlap" +
                                    (circles ? " and circles must not touch" : "") +
                                    ", or the common part would hold the particles of both");
    }
  }

  if (e.refinement) {
    int start = 0;
    for (const auto& f : s.fluid) start = std::max(start, f.level + (e.static_refinement ? 1 : 0));
    if (e.refinement->max_level <= start) {
      fail("effects.refinement.max_level",
           "must exceed the particles' starting level " + std::to_string(start) + ", or nothing is ever refined");
    }
  }
  if (e.lennard_jones_wall) {
    const LennardJonesWall& w = *e.lennard_jones_wall;
    const std::string p = "effects.lennard_jones_wall";
    if (w.strength && w.reference_height) fail(p, "give strength or reference_height, not both");
    if (!w.strength && w.reference_height && gravity_magnitude(s) <= 0.0) {
      fail(p + ".reference_height", "needs effects.gravity (D = 5 g H)");
    }
    if (!w.strength && !w.reference_height) fail(p + ".strength", "missing required key (or give reference_height, D = 5 g H)");
    // Resolution rule: at the finest level the scene can reach (spacing d), the repulsion range r0 =
    // r0_factor d must cover the wall-particle spacing, or particles of that level slip between them.
    const double d = finest_spacing(s);
    const double r0 = w.r0_factor * d;
    const double ws = wall_spacing(s);
    if (ws > r0 * (1.0 + 1e-9)) {
      // With an explicit spacing, a coarser finest level (max_level) or a finer wall spacing fixes it; with the
      // default spacing (d_min / 2) only r0_factor can be at fault.
      fail(w.spacing ? p + ".spacing" : p + ".r0_factor",
           "the walls cannot resolve level " + std::to_string(finest_level(s)) + ": wall-particle spacing " + num(ws) +
               " m exceeds the repulsion range r0 = r0_factor * d = " + num(r0) + " m of its particles (d = " + num(d) +
               (w.spacing ? " m); lower the refinement level or the wall spacing" : " m); raise r0_factor to 0.5 or more"));
    }
    if (estimated_wall_particles(s) > kMaxParticles) fail(p + ".spacing", "would create more than " + num(kMaxParticles) + " wall particles");
  }

  const Time& t = s.time;
  if (t.end / t.dt_max > 1e9) fail("time.dt_max", "would take more than 1e9 steps to reach time.end");
  if (t.output_interval) {
    if (t.end / *t.output_interval > 1e6) fail("time.output_interval", "would write more than a million outputs");
  }

  for (std::size_t k = 0; k < s.probes.size(); ++k) {
    validate_probe(s, s.probes[k], element("probes", k));
    for (std::size_t j = 0; j < k; ++j) {
      if (s.probes[j].name == s.probes[k].name) fail(element("probes", k) + ".name", "duplicate probe name '" + s.probes[k].name + "'");
    }
  }

  const Output& o = s.output;
  if (o.frame_interval) {
    if (t.end / *o.frame_interval > 1e6) fail("output.frame_interval", "would write more than a million frames");
  }
  const auto names = particle_field_names();
  for (std::size_t k = 0; k < o.fields.size(); ++k) {
    if (std::find(names.begin(), names.end(), o.fields[k]) == names.end()) {
      fail(element("output.fields", k), "unknown field '" + o.fields[k] + "'; fields: " + list(names));
    }
  }
}

}  // namespace sph::scene
