#pragma once
// Buffered levels (effects.refinement.coupling = "buffered"; docs/METHOD.md, "Buffered levels").
//
// With the paper's mixed pairs, a refined zone in still water cannot stay at rest: the symmetric pressure term's
// zeroth-order error at the jump in spacing leaves 4-99 m/s^2 that no pressure field balances, and the jump's
// interface energy is negative (docs/METHOD.md, "Still water across a level jump"). With buffered levels no pair
// mixes levels, so each level's sums are taken on a lattice of its own spacing:
//   - a split keeps its parent, as a passive `shadow` among its active daughters, so the coarse level's lattice
//     stays whole inside a refined zone;
//   - an active particle within a fine particle's support of where the next level is active gets passive `buffer`
//     daughters (it becomes a `host`), so the fine level's lattice reaches a support beyond its zone;
//   - a passive particle takes its velocity and density from the active particles of the other levels (and their
//     ghosts) by a linear moving least-squares fit; a shadow moves with that velocity, a buffer particle keeps its
//     place beside its host (tie_buffers);
//   - daughters take their parent's density carried along its pressure gradient (split_pass.hpp, DaughterDensityIn),
//     so that a split leaves a still tank's hydrostatic field as it was;
//   - where a flow mixes fine fluid into coarse, the coarse particles it reaches are refined (kIntermixReach), so that
//     the band's buffer particles never lie on top of active fine ones.
// Active particles meet only their own level (the pair sweep, core/sweep.hpp). Passive ones are not fluid of their
// own: the diagnostics, the probes and the output counts leave them out; frames keep them with their role.
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "core/cell_grid.hpp"
#include "core/equation_of_state.hpp"
#include "core/kernel.hpp"
#include "core/particle_store.hpp"
#include "core/refinement/split_pass.hpp"
#include "core/refinement/merge_pass.hpp"
#include "parallel/parallel_for.hpp"

namespace sph::refine {

/// Where the fit's sources do not span a plane (fewer than D + 1 in general position), or its matrix is this badly
/// conditioned, the passive particle takes the Shepard mean instead: the fit's coefficients would be noise.
inline constexpr double kFitMinReciprocalCondition = 1e-6;

/// How far a fitted value may lie beyond its sources' values, in units of their range (max - min over the sources
/// in reach): the fit extrapolates a linear field at most as far beyond its sources as they extend. A linear field
/// sampled over an extent L changes by its range over L, so at a place within L beyond the samples it lies within one
/// range of them, and the fit is exact for linear fields there. The places a still zone gives passive particles are
/// within that: `still_water_report.py --coupling buffered` gives the same table with and without the bound, to every
/// digit printed. Where a flow has carried a passive particle out among two or three sources of different
/// velocities, the unbounded fit extrapolated their differences: a dam break's buffer particles took 160-264 m/s
/// beside sources below 40 m/s, and densities of 1256-1472 kg/m^3 (docs/METHOD.md, "Buffered levels").
inline constexpr double kFitRangeMargin = 1.0;

/// One passive particle's fit: its density and velocity from the active particles j of other levels within
/// h_i + h_j, weighted by V_j W(r_ij, h_ij), exact for fields linear in x (also where the sources lie on one
/// side, as at a buffer band's outer edge or by a wall), within kFitRangeMargin of its sources' values. Returns false
/// when no source is within reach.
template <int D, class Neighbours>
bool fit_passive(const ParticleView<D>& s, std::size_t i, Neighbours&& for_each_neighbour, double& rho, Vec<D>& v) {
  using Mat = Eigen::Matrix<double, D + 1, D + 1>;
  using Row = Eigen::Matrix<double, 1, D + 1>;
  Mat M = Mat::Zero();
  Mat F = Mat::Zero();  // columns: rho, v_0 .. v_{D-1}
  Row lo = Row::Constant(std::numeric_limits<double>::infinity());
  Row hi = -lo;
  for_each_neighbour([&](std::size_t j, double r2) {
    if (s.kind[j] != Kind::fluid && s.kind[j] != Kind::ghost) return;
    if (is_passive(s.role[j]) || s.level[j] == s.level[i]) return;
    const double w = CubicSpline<D>::value(std::sqrt(r2), 0.5 * (s.h[i] + s.h[j])) * s.m[j] / s.rho[j];
    Eigen::Matrix<double, D + 1, 1> P;
    P(0) = 1.0;
    P.template tail<D>() = (s.x[j] - s.x[i]) / s.h[i];  // in units of h_i: the matrix's entries of one order
    M += w * P * P.transpose();
    F.col(0) += (w * s.rho[j]) * P;
    for (int k = 0; k < D; ++k) F.col(1 + k) += (w * s.v[j][k]) * P;
    if (w > 0.0) {
      Row value;
      value(0) = s.rho[j];
      value.template tail<D>() = s.v[j].transpose();
      lo = lo.cwiseMin(value);
      hi = hi.cwiseMax(value);
    }
  });
  if (!(M(0, 0) > 0.0)) return false;
  Row f;
  // M is symmetric and positive semi-definite: a Cholesky factorisation (LDL^T, pivoted), with its diagonal as the
  // conditioning test (the ratio of the smallest to the largest pivot bounds the reciprocal condition from above).
  const Eigen::LDLT<Mat> ldlt(M);
  const auto pivots = ldlt.vectorD();
  if (ldlt.info() == Eigen::Success && pivots.minCoeff() > kFitMinReciprocalCondition * pivots.maxCoeff()) {
    f = ldlt.solve(F).row(0);
    const Row range = hi - lo;
    f = f.cwiseMax(lo - kFitRangeMargin * range).cwiseMin(hi + kFitRangeMargin * range);
  } else {
    f = F.row(0) / M(0, 0);
  }
  rho = f(0);
  for (int k = 0; k < D; ++k) v[k] = f(1 + k);
  return true;
}

/// Every passive fluid particle's v, rho (and p, and the half-step copies vh, rhoh) from its fit (fit_passive), on
/// the grid built for the store as it is: once before each evaluation (Simulation::step, Simulation::refresh), so
/// the active particles meet the other levels' state as predicted for it. A passive particle with no source in reach
/// keeps its values. The grid has one layer, or one per level as the solver builds it (build_level_grid: layer l
/// holds level l alone for l < kGridLayers - 1); in the latter the fit skips its own level's layer, which holds no
/// source (the same sources in the same order, so the same bits, with fewer candidates).
template <int D>
void interpolate_passive(const ParticleView<D>& s, const CellGrid<D>& grid, const TaitEquationOfState& eos) {
  const bool layered = grid.layer_count() > 1;
  par::parallel_for(s.n, [&](std::size_t i) {
    if (s.kind[i] != Kind::fluid || !is_passive(s.role[i])) return;
    double rho = 0.0;
    Vec<D> v = Vec<D>::Zero();
    const bool skip_own = layered && s.level[i] < kGridLayers - 1;
    const auto other_layers = [&](std::uint32_t b, std::uint32_t e) { return !(skip_own && b <= i && i < e); };
    const auto every_run = [](std::uint32_t, std::uint32_t) { return true; };
    const auto neighbours = [&](auto&& f) { grid.for_each_neighbour_in_layers(i, s.x, s.h, other_layers, every_run, f); };
    if (!fit_passive(s, i, neighbours, rho, v)) return;
    s.rho[i] = rho;
    s.v[i] = v;
    s.p[i] = eos.pressure(rho);
    s.vh[i] = v;
    s.rhoh[i] = rho;
  });
}

/// Puts every buffer particle back at its place beside its host (x_host + tie), level by level from the coarsest, so
/// that a buffer whose host is itself a buffer follows it. Called after each drift: a buffer particle keeps its
/// pattern around its host, which the active level's pressure holds in place. (Carried with its fitted velocity
/// instead, the buffer lattice drifts from the fine level's: the still tank's wall zone at two levels then moved at
/// 1.76x the unrefined tank's speed, tied at 1.32x; docs/METHOD.md, "Buffered levels".) A buffer whose host is not
/// in the store keeps the place the drift gave it.
template <int D>
void tie_buffers(ParticleStore<D>& store);

/// How far inside every wall a passive particle of spacing d is kept (keep_passive_inside_walls): a quarter of its
/// spacing. Half the distance at which particles of that spacing sit at a wall at rest (d / 2, where the set-up and
/// the wall rule put them), so a still lattice is never moved; and the particle and its ghost image stay half a
/// spacing apart, as close as the fluid's own compressed neighbours, not on top of each other.
inline double passive_wall_margin(double spacing) { return 0.25 * spacing; }

/// Keeps every passive fluid particle at least passive_wall_margin(d) inside each wall it is near (projects onto,
/// and lies less than the margin inside or behind by at most its spacing), moving it along the wall's normal. Called
/// after each drift, after tie_buffers. Nothing else holds a passive particle in the domain: no force acts on it, a
/// shadow moves with its fitted velocity and a buffer particle beside its host. A shadow at the edge of a thin jet up
/// a wall, fitted from two fine particles and one ghost, took 0.8 m/s into the wall and left the domain, which
/// stopped the dam break (docs/METHOD.md, "Buffered levels"). Passive particles are not counted, so mass, momentum
/// and energy do not change. Returns how many it moved.
template <int D>
std::size_t keep_passive_inside_walls(ParticleStore<D>& store, const std::vector<Wall<D>>& walls);

/// How close (in its own spacing d_l) an active particle of level l may come to an active particle of level l + 1
/// before the pass gives its place to the finer level (prepare_buffered_marks). Each level's lattice is completed by
/// passive particles of the other, so fluid of two levels that a flow mixes (fine particles carried out of their
/// zone among coarse ones) puts two lattices of one level on top of each other: the band's buffer particles beside
/// active fine ones. The dam break with a zone stopped so, at 2.1-3.2 s (docs/METHOD.md, "Buffered levels"). Where a
/// zone's edge stays still, no active particle of level l has one of level l + 1 nearer than 0.75 d_l with AAP (a
/// daughter sits d_l / 4 from its parent in each axis, and the parent, a shadow, d_l from the nearest active particle
/// of level l). 0.6 is a tuned value: 0.5 left two of the four AAP dam-break zones stopping (at 2.67 s and 3.39 s),
/// 0.6 let all four complete, and the still tanks (RSP too) are unchanged.
inline constexpr double kIntermixReach = 0.6;

/// Turns the criterion's marks (1: refine) into a buffered pass's (split_marked with buffered = true), on the store
/// between steps (fluid, ghosts dropped or not):
///   - an active particle of level l within kIntermixReach d_l of an active particle of level l + 1 is marked;
///   - a marked host becomes a shadow and its buffer daughters active (its zone grew over it; Origin::fresh_split),
///     with its state (flip_daughter), or hosts where they have buffer daughters of their own: no split;
///   - a mark on a particle that is passive or already has daughters is dropped;
///   - an unmarked active or buffer particle of level l < max_level without daughters, within h_l + d_l (a daughter's
///     support 2 h_{l+1}, plus how far its own daughters sit from it) of an active particle of level l + 1, or within
///     that plus sqrt(D) d_l / 2 of a particle marked at level l (whose daughters are not there yet), is marked 2
///     (buffer daughters).
/// Returns the number of hosts that became shadows. Deterministic: no mark depends on the store's order.
template <int D>
std::size_t prepare_buffered_marks(ParticleStore<D>& store, std::vector<std::uint8_t>& marks, int max_level,
                                   const DaughterDensityIn<D>& density);

/// A host's flip, for its buffer daughter k: k takes the host's velocity and rates (v, its half-step and step-start
/// copies, a, drho and the sweep's sums, the jerks), as a split's daughter takes its parent's, and the host's density
/// carried along the hydrostatic gradient to k's place (daughter_density_gradient with a = 0; the host's own with the
/// `parent` rule). So the flip keeps mass, linear momentum and kinetic energy exactly, and potential energy where the
/// tie offsets' centroid is the host (all but wall-shifted patterns); the elastic energy changes at second order in
/// the hydrostatic step across the family. Until 2026-12-06 a flip kept the daughters' fitted state: each pass then
/// changed the dam break's total energy by up to 4.7e-4 E(0) (issue #15's target: 1e-6). With the gradient the
/// host's last acceleration balanced, as a split uses, a flip inside an impact gave a family densities several per
/// cent apart: passes changed the energy by up to 1.5e-6 E(0) (docs/METHOD.md, "Buffered levels").
template <int D>
void flip_daughter(ParticleStore<D>& store, std::size_t host, std::size_t k, const DaughterDensityIn<D>& density);

/// How far (beyond the reach h_l + d_l at which prepare_buffered_marks gives a particle of level l its buffer
/// daughters) the finer level's active particles must have gone before a host gives its buffer daughters up
/// (retract_buffered): the band is taken away only where no active particle of level l + 1 is within
/// kUnbufferReach (h_l + d_l), so that a host does not flip between having a band and not from one check to the next.
/// A particle moves at most about 0.02 h a step (dt <= C h / c0 with C = 0.2, speeds below c0 / 10 in a
/// weakly-compressible flow), 2 h_{l+1} = h_l over a check interval of 100 steps: within the margin of h_l + d_l that
/// a factor 2 leaves.
inline constexpr double kUnbufferReach = 2.0;

/// What a buffered retraction did (retract_buffered).
template <int D>
struct RetractResultIn {
  std::size_t merged = 0;          // shadows that took their daughters' place back (2^D active particles into one)
  std::size_t kept_as_buffers = 0; // of those, the ones whose daughters stayed as its buffer daughters (finer fluid near)
  std::size_t unbuffered = 0;      // particles whose buffer daughters left: no active finer fluid within reach
  std::size_t kept_off_walls = 0;  // families that may merge, left alone: their centre too close to a wall
  std::size_t kept_by_criterion = 0;  // ... the merged particle would be split again at once
  std::size_t kept_dispersed = 0;  // ... a member outside the merged particle's square
  std::size_t kept_intermixed = 0; // ... an active particle of level l + 1 that stays, within the intermix reach
  double d_kinetic = 0.0;          // kinetic energy after - before (<= 0), the merges'
  Angular<D> d_angular = zero_angular<D>();
};

/// Coarsening with buffered levels, on the store between steps (after the pass's splits):
///   - a shadow of level l whose 2^D daughters are all active and may merge (may[i] != 0) takes their place back: it
///     becomes active with their merged state (merged_state: mass and momentum kept, the family's motion about its
///     centre of mass reported as removed), unless merge_verdict keeps the family apart or an active particle of level
///     l + 1 outside the merging families lies within kIntermixReach d_l + horizon (|v_merged| + the fastest such
///     particle's speed) of the merged place (prepare_buffered_marks would split it again at once, or at the next
///     check, `horizon` seconds on, if they keep their speeds). Where active fluid of level l + 1 stays within h_l + d_l of it, it becomes a host
///     and its daughters its buffer daughters, where they stand; otherwise they leave;
///   - then, finest level first, a particle of level l whose daughters are all buffer particles without daughters of
///     their own, with no active particle of level l + 1 within kUnbufferReach (h_l + d_l), loses them (a host
///     becomes active).
/// `time` is written as a merged particle's level_time. Deterministic: no outcome depends on the store's order, and
/// the sums run in sibling order.
template <int D>
RetractResultIn<D> retract_buffered(ParticleStore<D>& store, const std::vector<std::uint8_t>& may,
                                    const Geometry<D>& geometry, double time, double horizon,
                                    const std::function<bool(const Vec<D>&, const Vec<D>&)>& would_split, int max_level);

}  // namespace sph::refine
