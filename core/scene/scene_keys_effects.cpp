// The scene key registry, continued: the keys of `effects` (scene_keys.cpp has the rest and says how keys are
// declared). Each effect's defaults are the solver's own settings structs' (core/solver_settings.hpp,
// core/refinement/refinement_settings.hpp).
#include "core/scene/scene_schema.hpp"

namespace sph::scene::schema {

namespace {

using detail::kMaxLevel;

template <class T>
using S = Section<T>;

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
    d.add(value<Coarsening>("groups", member(&Coarsening::groups))
              .means("what merges: the daughters of one parent, or any of one level in a cell of the merged spacing"));
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
    d.add(value<Refinement>("coupling", member(&Refinement::coupling))
              .only_for({"zone", "velocity"})
              .note("`buffered`: one process, no static refinement, coarsening by families only, every fluid "
                    "region at one level, in 3D an `h_factor` where the lattice's layer shear mode is stable (1.3, not "
                    "1.2; docs/METHOD.md, \"Three dimensions: a lattice mode\"); fine fluid that leaves the zone stays fine until coarsening merges it "
                    "back, and coarse fluid it mixes with is refined; in a violent flow the energy can grow between "
                    "passes, and a run whose fine fluid meets an impact can stop (docs/METHOD.md, \"Buffered levels\")")
              .means("how levels interact: every pair (`mixed`, the paper's), or each level with its own, its lattice "
                     "completed by passive particles fitted to the other levels (`buffered`, docs/METHOD.md)"));
    d.add(value<Refinement>("daughter_density", member(&Refinement::daughter_density))
              .default_text("`pressure_gradient` with `buffered`, `parent` with `mixed`")
              .means("the daughters' density: the parent's (`parent`, the paper's), or the parent's carried to each "
                     "daughter along the pressure gradient its momentum balance gives (`pressure_gradient`; where a "
                     "buffered host hands its place to its buffer daughters, the hydrostatic gradient alone, "
                     "docs/METHOD.md)"));
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

}  // namespace

const Section<Effects>& effects_section() {
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

}  // namespace sph::scene::schema
