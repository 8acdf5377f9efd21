// The scene key registry: every key of a scene file, declared once, in the order messages and written scenes
// list them. Each declaration names the key, binds it to the member it fills, and gives its unit, range or
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

const S<Rect>& box_section() {
  static const S<Rect> s = [] {
    S<Rect> d;
    d.add(value<Rect>("lo", member(&Rect::lo)).required().unit("m").means("lower-left corner"));
    d.add(value<Rect>("hi", member(&Rect::hi))
              .required()
              .unit("m")
              .note("greater than `lo` in x and y")
              .means("upper-right corner"));
    return d;
  }();
  return s;
}

const S<Container>& container_section() {
  static const S<Container> s = [] {
    S<Container> d;
    d.add(value<Container>("lo", [](auto& c) -> auto& { return c.box.lo; })
              .required()
              .unit("m")
              .means("lower-left corner"));
    d.add(value<Container>("hi", [](auto& c) -> auto& { return c.box.hi; })
              .required()
              .unit("m")
              .note("greater than `lo` in x and y")
              .means("upper-right corner"));
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
              .means("lower-left corner"));
    d.add(value<FluidRegion>("hi", [](auto& f) -> auto& { return f.rect.hi; })
              .required()
              .only_for({"rectangle"})
              .unit("m")
              .note("greater than `lo` in x and y")
              .means("upper-right corner"));
    d.add(value<FluidRegion>("centre", member(&FluidRegion::centre))
              .required()
              .only_for({"circle"})
              .unit("m")
              .note("the circle inside the container, outside every obstacle")
              .means("centre; the lattice passes through it"));
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
              .note("needs `effects.gravity` = [0, -g]")
              .means("density from `p = rho0 g (surface - y)` through the equation of state; otherwise `rho = rho0`"));
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

const S<ArtificialViscosity>& viscosity_section() {
  static const S<ArtificialViscosity> s = [] {
    S<ArtificialViscosity> d;
    d.add(value<ArtificialViscosity>("alpha", member(&ArtificialViscosity::alpha))
              .range(Range::non_negative())
              .means("`alpha` of `Pi_ij`: the linear (bulk) term"));
    d.add(value<ArtificialViscosity>("beta", member(&ArtificialViscosity::beta))
              .range(Range::non_negative())
              .means("`beta` of `Pi_ij`: the quadratic (shock) term"));
    return d;
  }();
  return s;
}

const S<ArtificialStress>& stress_section() {
  static const S<ArtificialStress> s = [] {
    S<ArtificialStress> d;
    d.add(value<ArtificialStress>("epsilon", member(&ArtificialStress::epsilon))
              .range(Range::above_up_to(0, 1))
              .means("`R_i = epsilon abs(p_i) / rho_i^2` when `p_i < 0`, else 0"));
    d.add(value<ArtificialStress>("exponent", member(&ArtificialStress::exponent))
              .range(Range::between(1, 16))
              .means("`n` in `f_ij^n`, `f_ij = W(r_ij, h_ij) / W(d_ij, h_ij)`, `d_ij = (d_i + d_j) / 2`"));
    return d;
  }();
  return s;
}

const S<DensityDiffusion>& diffusion_section() {
  static const S<DensityDiffusion> s = [] {
    S<DensityDiffusion> d;
    d.add(value<DensityDiffusion>("delta", member(&DensityDiffusion::delta))
              .range(Range::above_up_to(0, 1))
              .means("`delta` in `drho_i/dt += 2 delta h_ij c0 sum_j psi_ij (x_ji . grad_i W) / (r_ij^2 + 0.01 h_ij^2) "
                     "m_j / rho_j`"));
    return d;
  }();
  return s;
}

const S<LennardJonesWall>& lennard_jones_section() {
  static const S<LennardJonesWall> s = [] {
    S<LennardJonesWall> d;
    d.add(value<LennardJonesWall>("strength", member(&LennardJonesWall::strength))
              .unit("m^2/s^2")
              .range(Range::positive())
              .means("`D` in eq. (10)"));
    d.add(value<LennardJonesWall>("reference_height", member(&LennardJonesWall::reference_height))
              .unit("m")
              .range(Range::positive())
              .note("needs gravity")
              .means("`D = 5 g H` (PHYSICS.md)"));
    d.add(value<LennardJonesWall>("r0_factor", member(&LennardJonesWall::r0_factor))
              .range(Range::above_up_to(0, 2))
              .means("`r0 = r0_factor * d^{l_i}` of the fluid particle"));
    d.add(value<LennardJonesWall>("spacing", member(&LennardJonesWall::spacing))
              .unit("m")
              .range(Range::positive())
              .default_text("half the finest spacing the scene can reach")
              .means("wall-particle spacing"));
    return d;
  }();
  return s;
}

const S<Coarsening>& coarsening_section() {
  static const S<Coarsening> s = [] {
    S<Coarsening> d;
    d.info.phrase = "criterion {}";  // the variant is the enclosing refinement's criterion
    d.add(value<Coarsening>("v_threshold", member(&Coarsening::v_threshold))
              .only_for({"velocity"})
              .unit("m/s")
              .default_text("half the split `v_threshold`")
              .note("0 < v < split `v_threshold`")
              .means("a member passes with `|v_i| < v_threshold`"));
    d.add(value<Coarsening>("min_neighbours", member(&Coarsening::min_neighbours))
              .only_for({"few_neighbours"})
              .default_text("twice the split `min_neighbours`")
              .note("> split `min_neighbours`")
              .means("a member passes with at least this many fluid neighbours"));
    d.add(value<Coarsening>("hold_time", member(&Coarsening::hold_time))
              .unit("s")
              .range(Range::non_negative())
              .means("time at its level before a family may merge"));
    return d;
  }();
  return s;
}

/// The merge test's defaults follow the split test's: halfway to no refinement (half the split speed, twice
/// the split neighbour count), so a family does not flip between the two. Applied after the coarsening
/// object is read, to the keys it does not give.
void derive_coarsening_defaults(const Json& j, Refinement& r) {
  if (r.criterion == Criterion::velocity && !j.contains("v_threshold")) r.coarsening->v_threshold = 0.5 * r.v_threshold;
  if (r.criterion == Criterion::few_neighbours && !j.contains("min_neighbours")) {
    r.coarsening->min_neighbours = 2 * r.min_neighbours;
  }
}

const S<Refinement>& refinement_section() {
  static const S<Refinement> s = [] {
    S<Refinement> d;
    d.info.discriminator = "criterion";
    d.info.phrase = "criterion {}";
    d.variant = [](const Refinement& r) { return std::string(to_string(r.criterion)); };
    d.add(value<Refinement>("criterion", member(&Refinement::criterion)).means("which particles are marked"));
    d.add(value<Refinement>("v_threshold", member(&Refinement::v_threshold))
              .required()
              .only_for({"velocity"})
              .unit("m/s")
              .range(Range::positive())
              .means("marks `|v_i| > v_threshold`"));
    d.add(object<Refinement>("zone", member(&Refinement::zone), box_section)
              .required()
              .only_for({"zone"})
              .type_text("box")
              .unit("m")
              .means("marks particles inside"));
    d.add(value<Refinement>("min_neighbours", member(&Refinement::min_neighbours))
              .only_for({"few_neighbours"})
              .range(Range::at_least(1))
              .means("marks particles with fewer fluid neighbours"));
    d.add(value<Refinement>("pattern", member(&Refinement::pattern))
              .means("daughters' square: axis-aligned, or rotated and scaled"));
    d.add(value<Refinement>("rsp_k", member(&Refinement::rsp_k))
              .range(Range::above_up_to(0, 2))
              .means("RSP side `s = k d / F_ij` (1/2 is the paper's printed factor)"));
    d.add(value<Refinement>("check_interval", member(&Refinement::check_interval))
              .unit("steps")
              .range(Range::at_least(1))
              .means("steps between checks"));
    d.add(value<Refinement>("max_level", member(&Refinement::max_level))
              .range(Range::between(1, kMaxLevel))
              .note("above every particle's starting level")
              .means("particles at this level are never refined"));
    Key<Refinement> coarsening = object<Refinement>("coarsening", member(&Refinement::coarsening), coarsening_section,
                                                    [](const Refinement& r) { return std::string(to_string(r.criterion)); });
    coarsening.bind.read = [read = coarsening.bind.read](const Json& j, const std::string& path, Refinement& r) {
      read(j, path, r);
      derive_coarsening_defaults(j, r);
    };
    d.add(std::move(coarsening)
              .default_text("none (nothing merges)")
              .means("families merge back where the flow no longer needs them"));
    return d;
  }();
  return s;
}

const S<StaticRefinement>& static_refinement_section() {
  static const S<StaticRefinement> s = [] {
    S<StaticRefinement> d;
    d.add(object<StaticRefinement>("box", member(&StaticRefinement::box), box_section)
              .type_text("box")
              .unit("m")
              .default_text("absent: every fluid particle")
              .means("refine only the particles inside"));
    d.add(value<StaticRefinement>("pattern", member(&StaticRefinement::pattern)).means("daughters' square"));
    d.add(value<StaticRefinement>("rsp_k", member(&StaticRefinement::rsp_k))
              .range(Range::above_up_to(0, 2))
              .means("RSP side factor `k`"));
    return d;
  }();
  return s;
}

const S<Effects>& effects_section() {
  static const S<Effects> s = [] {
    S<Effects> d;
    d.add(value<Effects>("gravity", member(&Effects::gravity))
              .unit("m/s^2")
              .note("not zero")
              .means("body force `g` in eq. (6)"));
    d.add(object<Effects>("artificial_viscosity", member(&Effects::artificial_viscosity), viscosity_section)
              .means("Monaghan's `Pi_ij`, eq. (9)"));
    d.add(object<Effects>("artificial_stress", member(&Effects::artificial_stress), stress_section)
              .means("Monaghan's (2000) artificial stress against the pairing instability (not in the paper)"));
    d.add(object<Effects>("density_diffusion", member(&Effects::density_diffusion), diffusion_section)
              .means("delta-SPH with the hydrostatic correction of Fourtakas et al. (2019) (not in the paper)"));
    d.add(object<Effects>("lennard_jones_wall", member(&Effects::lennard_jones_wall), lennard_jones_section)
              .means("fixed wall particles with the repulsion of eq. (10)"));
    d.add(value<Effects>("ghost_walls", member(&Effects::ghost_walls))
              .means("mirrored ghost particles at every wall (section 2.4)"));
    d.add(value<Effects>("ghost_pressure", member(&Effects::ghost_pressure))
              .means("a ghost's pressure: the source's plus `rho_i g.(x_ghost - x_i)`, or the source's own"));
    d.add(object<Effects>("refinement", member(&Effects::refinement), refinement_section)
              .means("dynamic refinement between steps (section 3)"));
    d.add(object<Effects>("static_refinement", member(&Effects::static_refinement), static_refinement_section)
              .means("one refinement pass at set-up (fully refined runs)"));
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
              .means("the column sampled"));
    d.add(value<Probe>("band", member(&Probe::band))
              .only_for(column)
              .unit("m")
              .range(Range::positive())
              .default_text("the largest `spacing`")
              .means("half-width of the sampled column"));
    d.add(value<Probe>("datum", member(&Probe::datum))
              .only_for({"surface_elevation"})
              .unit("m")
              .means("the elevation is measured from this y"));
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
              .means("solid rectangles (fluid outside)"));
    d.add(array<Scene>("fluid", member(&Scene::fluid), region_section, "regions")
              .required()
              .note("at least one")
              .means("the initial fluid"));
    d.add(value<Scene>("h_factor", member(&Scene::h_factor))
              .range(Range::between(0.5, 3))
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
