// The scene key registry: every key of a scene file, declared once, in the order messages and written scenes
// list them (the effects' keys are in scene_keys_effects.cpp). Each declaration names the key, binds it to the member it fills, and gives its unit, range or
// choices, and meaning. Its default is the member's initial value (scene_schema.hpp says why); a default that
// is derived from other keys is described with default_text and applied where noted. Rules across keys
// (overlaps, gravity for hydrostatic starts, wall resolution, memory) are the validator's
// (scene_validator.cpp); `note` only shows them in the tables.
#include "core/scene/scene_schema.hpp"

namespace sph::scene::schema {

namespace {

using detail::kMaxLevel;

template <class T>
using S = Section<T>;

const S<Container>& container_section() {
  static const S<Container> s = [] {
    S<Container> d;
    d.add(value<Container>("lo", [](auto& c) -> auto& { return c.box.lo; })
              .required()
              .unit("m")
              .note("its two or three numbers make the scene 2D or 3D")
              .means("lowest corner"));
    d.add(value<Container>("hi", [](auto& c) -> auto& { return c.box.hi; })
              .required()
              .unit("m")
              .note("greater than `lo` on every axis")
              .means("highest corner"));
    d.add(value<Container>("open_top", member(&Container::open_top)).means("false adds a wall along the top"));
    d.add(value<Container>("outflow", member(&Container::outflow))
              .note("`remove` needs `open_top`")
              .means("what happens to fluid that leaves over the open top's rim"));
    return d;
  }();
  return s;
}

const S<FluidRegion>& region_section() {
  static const S<FluidRegion> s = [] {
    S<FluidRegion> d;
    d.info.discriminator = "shape";
    d.info.phrase = "a {}";
    d.variant = [](const FluidRegion& f) { return std::string(to_string(f.shape)); };
    d.add(value<FluidRegion>("shape", member(&FluidRegion::shape)).required().means("the region's shape"));
    d.add(value<FluidRegion>("lo", [](auto& f) -> auto& { return f.rect.lo; })
              .required()
              .only_for({"rectangle"})
              .unit("m")
              .note("inside the container, outside every obstacle")
              .means("lowest corner"));
    d.add(value<FluidRegion>("hi", [](auto& f) -> auto& { return f.rect.hi; })
              .required()
              .only_for({"rectangle"})
              .unit("m")
              .note("greater than `lo` on every axis")
              .means("highest corner"));
    d.add(value<FluidRegion>("centre", member(&FluidRegion::centre))
              .required()
              .only_for({"circle"})
              .unit("m")
              .note("the circle inside the container, outside every obstacle")
              .means("centre (a disc in 2D, a ball in 3D); the lattice passes through it"));
    d.add(value<FluidRegion>("radius", member(&FluidRegion::radius))
              .required()
              .only_for({"circle"})
              .unit("m")
              .range(Range::positive())
              .means("radius"));
    d.add(value<FluidRegion>("spacing", member(&FluidRegion::spacing))
              .required()
              .unit("m")
              .range(Range::positive())
              .means("`d^0`, the level-0 spacing"));
    d.add(value<FluidRegion>("level", member(&FluidRegion::level))
              .range(Range::between(0, kMaxLevel))
              .means("initial level: the lattice spacing is `spacing / 2^level`"));
    d.add(value<FluidRegion>("velocity", member(&FluidRegion::velocity)).unit("m/s").means("initial velocity"));
    d.add(value<FluidRegion>("hydrostatic", member(&FluidRegion::hydrostatic))
              .note("needs `effects.gravity` = [0, -g] (2D) or [0, 0, -g] (3D)")
              .means("density from `p = rho0 g (surface - height)` through the equation of state; otherwise `rho = rho0`"));
    d.add(value<FluidRegion>("surface", member(&FluidRegion::surface))
              .unit("m")
              .default_text("the rectangle's top")
              .note("only with `hydrostatic`; **required** for a hydrostatic circle")
              .means("height of the free surface"));
    return d;
  }();
  return s;
}

const S<Material>& material_section() {
  static const S<Material> s = [] {
    S<Material> d;
    d.add(value<Material>("rho0", member(&Material::rho0))
              .required()
              .unit("kg/m^3")
              .range(Range::positive())
              .means("rest density"));
    d.add(value<Material>("gamma", member(&Material::gamma)).range(Range::at_least(1)).means("Tait exponent, eq. (7)"));
    d.add(value<Material>("c0", member(&Material::c0))
              .unit("m/s")
              .range(Range::positive())
              .means("sound speed, eq. (8) `B = c0^2 rho0 / gamma`"));
    d.add(value<Material>("mach_factor", member(&Material::mach_factor))
              .range(Range::positive())
              .default_text(detail::num(kDefaultMachFactor))
              .means("with a reference speed: `c0 = mach_factor * v_ref`"));
    d.add(value<Material>("reference_speed", member(&Material::reference_speed))
              .unit("m/s")
              .range(Range::positive())
              .means("`v_ref`"));
    d.add(value<Material>("reference_height", member(&Material::reference_height))
              .unit("m")
              .range(Range::positive())
              .note("needs gravity")
              .means("`v_ref = sqrt(2 g H)` (the free-fall speed from `H`)"));
    return d;
  }();
  return s;
}

const S<Time>& time_section() {
  static const S<Time> s = [] {
    S<Time> d;
    d.add(value<Time>("end", member(&Time::end))
              .required()
              .unit("s")
              .range(Range::positive())
              .means("the run stops exactly here (the last step is shortened)"));
    d.add(value<Time>("cfl", member(&Time::cfl))
              .range(Range::above_up_to(0, 1))
              .means("`C` of the time-step rule (PHYSICS.md)"));
    d.add(value<Time>("output_interval", member(&Time::output_interval))
              .unit("s")
              .range(Range::positive())
              .default_text("`end / 100`")
              .note("at most 1e6 outputs")
              .means("time-series interval"));
    d.add(value<Time>("dt_max", member(&Time::dt_max))
              .unit("s")
              .range(Range::positive())
              .note("`end / dt_max` <= 1e9")
              .means("upper bound on the step"));
    d.add(value<Time>("stepping", member(&Time::stepping))
              .means("`global`: one step for every particle; `per_level`: level `l` steps `dt0 / 2^l`"));
    d.add(value<Time>("bin_jump", member(&Time::bin_jump))
              .range(Range::between(1, kBinCount - 1))
              .note("`per_level` only")
              .means("the most a particle's time bin may differ from a neighbour's: a particle steps at least "
                     "`2^-bin_jump` as often as its most frequent neighbour (a limiter, docs/METHOD.md)"));
    d.add(value<Time>("predictor", member(&Time::predictor))
              .means("how `v` and `rho` are predicted for an evaluation: `extrapolated` from the last two "
                     "evaluations' rates, `last_rate` from the last one's, with the step shortened where the "
                     "neighbours are stiffer than the particle's lattice (docs/METHOD.md, \"The predictor\")"));
    return d;
  }();
  return s;
}

const S<Probe>& probe_section() {
  static const S<Probe> s = [] {
    const std::vector<std::string> column{"water_height", "surface_elevation"};
    S<Probe> d;
    d.info.discriminator = "type";
    d.info.phrase = "a {} probe";
    d.variant = [](const Probe& p) { return std::string(to_string(p.kind)); };
    d.add(value<Probe>("type", member(&Probe::kind)).required().means("what is measured"));
    d.add(value<Probe>("name", member(&Probe::name))
              .default_text("`<type>_<index>`")
              .note("letters, digits, `_`; unique")
              .means("its column in the time series"));
    d.add(value<Probe>("x", member(&Probe::x))
              .required()
              .only_for(column)
              .unit("m")
              .note("within the container's x range")
              .means("the column sampled (2D: the vertical line at x)"));
    d.add(value<Probe>("y", member(&Probe::y))
              .only_for(column)
              .unit("m")
              .note("**required** in 3D, not in 2D; within the container's y range")
              .means("3D: the gauge is the vertical line at (x, y)"));
    d.add(value<Probe>("band", member(&Probe::band))
              .only_for(column)
              .unit("m")
              .range(Range::positive())
              .default_text("the largest `spacing`")
              .means("half-width of the sampled column (a square column in 3D)"));
    d.add(value<Probe>("datum", member(&Probe::datum))
              .only_for({"surface_elevation"})
              .unit("m")
              .means("the elevation is measured from this height"));
    d.add(value<Probe>("origin", member(&Probe::origin))
              .only_for({"surge_front"})
              .unit("m")
              .default_text("`container.lo.x`")
              .means("where the front `Z` is measured from"));
    d.add(value<Probe>("position", member(&Probe::position))
              .required()
              .only_for({"pressure"})
              .unit("m")
              .note("inside the container")
              .means("the point sampled"));
    return d;
  }();
  return s;
}

const S<Output>& output_section() {
  static const S<Output> s = [] {
    S<Output> d;
    d.add(value<Output>("folder", member(&Output::folder))
              .default_text("`out/<name>`")
              .means("output folder (relative to the working directory); `-o` overrides it"));
    d.add(value<Output>("frames", member(&Output::frames)).means("write HDF5 frames"));
    d.add(value<Output>("frame_interval", member(&Output::frame_interval))
              .unit("s")
              .range(Range::positive())
              .default_text("`time.output_interval`")
              .note("at most 1e6 frames")
              .means("time between frames"));
    d.add(strings<Output>("fields", member(&Output::fields), "field names")
              .default_text("every field")
              .note("field names below")
              .means("which particle fields frames hold (`position` always)"));
    return d;
  }();
  return s;
}

}  // namespace

const Section<Rect>& box_section() {
  static const S<Rect> s = [] {
    S<Rect> d;
    d.add(value<Rect>("lo", member(&Rect::lo)).required().unit("m").means("lowest corner"));
    d.add(value<Rect>("hi", member(&Rect::hi))
              .required()
              .unit("m")
              .note("greater than `lo` on every axis")
              .means("highest corner"));
    return d;
  }();
  return s;
}

const Section<Scene>& scene_section() {
  static const S<Scene> s = [] {
    S<Scene> d;
    d.add(value<Scene>("name", member(&Scene::name))
              .default_text("the file name without `.json`")
              .note("letters, digits, `_ - .`")
              .means("names the run and the default output folder"));
    d.add(value<Scene>("description", member(&Scene::description)).means("free text"));
    d.add(object<Scene>("container", member(&Scene::container), container_section).required().means("the tank"));
    d.add(array<Scene>("obstacles", member(&Scene::obstacles), box_section, "boxes")
              .note("each inside the container")
              .means("solid boxes (fluid outside)"));
    d.add(array<Scene>("fluid", member(&Scene::fluid), region_section, "regions")
              .required()
              .note("at least one")
              .means("the initial fluid"));
    d.add(value<Scene>("h_factor", member(&Scene::h_factor))
              .range(Range::between(0.5, 3))
              .note("in 3D the cubic lattice's alternating-layer shear mode grows under pressure for h_factor in "
                    "about 0.5-0.9, 1.03-1.26, 1.51-1.70, 1.79-2.19 and 2.52-3, 1.2 among them: still water stays still there only "
                    "while nothing disturbs it, and a refinement pass does (docs/METHOD.md, \"Three dimensions: a "
                    "lattice mode\"); 1.3 is stable")
              .means("smoothing length `h = h_factor * d` (PHYSICS.md `r`)"));
    d.add(object<Scene>("material", member(&Scene::material), material_section)
              .required()
              .means("density and sound speed"));
    d.add(object<Scene>("effects", member(&Scene::effects), effects_section)
              .default_text("`{}`")
              .means("the physics beyond pressure and continuity; an absent effect is not computed"));
    d.add(object<Scene>("time", member(&Scene::time), time_section).required().means("time span and step control"));
    d.add(array<Scene>("probes", member(&Scene::probes), probe_section, "probes")
              .means("measurements written to the time series"));
    d.add(object<Scene>("output", member(&Scene::output), output_section)
              .default_text("defaults below")
              .means("what is written"));
    return d;
  }();
  return s;
}

}  // namespace sph::scene::schema

namespace sph::scene {

const SectionInfo& scene_keys() { return schema::scene_section().info; }

}  // namespace sph::scene
