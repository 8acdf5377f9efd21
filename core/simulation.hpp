#pragma once
// The simulation driver: owns the particle store and runs the step pipeline of ARCHITECTURE.md:
//   kick + drift -> ghosts -> cell grid (reorders the store) -> pair sweep -> kick, variable dt;
//   between steps, the run-time stages (refinement, probes, output) get one call each.
//
// Time integration is core/integrator.hpp: kick-drift-kick, with one global step (time.stepping = "global",
// the default) or power-of-two steps per refinement level ("per_level"). A step is dt0 for the coarsest bin, in
// 2^B substeps; the driver runs the loops and the force evaluations the integrator asks for.
//
// Parallel regions per substep (each a fork and a join, and on busy cores each can cost a scheduler time
// slice): 1. the watchdog's copy (first substep), the kick of the previous substep, drift and prediction,
// output counts and h range (one loop); 2. the scan of the counts; 3. the expansion with its bounding box; 4. the
// cell sort (one region, its phases separated by barriers); 5. the gather of every field through the composed
// map; 6. the ghosts' values; 7. the pair sweep. Then per step: 8. the closing kick; 9. the watchdog's scan.
// With one global step that is 9 regions per step (there were 19). With one thread there are none: each runs on
// the calling thread (par::serial).
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "core/boundary/ghosts.hpp"
#include "core/boundary/outflow.hpp"
#include "core/cell_grid.hpp"
#include "core/diagnostics.hpp"
#include "core/domain.hpp"
#include "core/integrator.hpp"
#include "core/neighbour_cells.hpp"
#include "core/particle_store.hpp"
#include "core/solver_settings.hpp"
#include "core/sweep_factory.hpp"

namespace sph {

template <int D>
class SimulationT;

/// A per-stage effect (refinement, probes, output): one call between steps, never one per particle.
template <int D>
class StageT {
 public:
  virtual ~StageT() = default;
  virtual const char* name() const = 0;
  /// Called after every step. Returns true when it changed the particle set (the solver then rebuilds
  /// ghosts and grid and re-evaluates the rates before the next step).
  virtual bool after_step(SimulationT<D>& sim) = 0;
};

/// The work of the steps taken so far (this process; not part of the state): what accuracy costs, counted.
struct Work {
  static constexpr int kLevels = 16;                 // levels beyond share the last entry
  std::array<std::uint64_t, kLevels> evaluations{};  // particle force evaluations (the particle due), per level
  std::uint64_t pairs = 0;                           // pair interactions evaluated (each side of a pair counts)
  std::uint64_t candidates = 0;                      // neighbour candidates checked
  std::uint64_t substeps = 0;                        // force evaluations of the whole set (sweeps)
};

struct StepInfo {
  double dt = 0.0;
  SweepLimits limits;  // over the step's evaluations: smallest limits, pairs summed, finest bin
  int substeps = 1;    // 2^B
};

/// The driver in D = 2 or 3 dimensions (both are compiled; the scene's container fixes which one runs).
template <int D>
class SimulationT {
 public:
  using Settings = SolverSettingsT<D>;
  using Stage = StageT<D>;
  using Ghosts = GhostBuilderT<D>;

  explicit SimulationT(Settings settings);

  const Settings& settings() const { return settings_; }
  /// How levels interact from now on (effects.refinement.coupling; the refinement stage sets it when added).
  void set_coupling(LevelCoupling coupling) { settings_.coupling = coupling; }
  bool buffered() const { return settings_.coupling == LevelCoupling::buffered; }
  ParticleStore<D>& store() { return store_; }
  const ParticleStore<D>& store() const { return store_; }
  const CellGrid<D>& grid() const { return grid_; }
  const Ghosts* ghosts() const { return ghosts_ ? &*ghosts_ : nullptr; }
  const Integrator& integrator() const { return integrator_; }
  const Work& work() const { return work_; }

  double time() const { return time_; }
  std::uint64_t step_count() const { return step_; }
  double dt() const { return dt_; }
  /// Sets the clock; the finest bin's step count becomes `step` (as with one global step: a resumed per-level
  /// run sets it with set_fine_step_count after).
  void set_clock(double time, std::uint64_t step, double dt) {
    time_ = time;
    step_ = step;
    fine_steps_ = step;
    dt_ = dt;
  }
  /// Steps of the finest bin taken so far (the sweeps: equal to step_count() with one global step); part of the
  /// state (checkpoints). Refinement checks count these, so check_interval means the same with either stepping.
  std::uint64_t fine_step_count() const { return fine_steps_; }
  /// Substeps of the last step (1 with one global step).
  int last_substeps() const { return last_substeps_; }
  void set_fine_step_count(std::uint64_t n) { fine_steps_ = n; }
  /// After the store was replaced without an evaluation (a checkpoint read: the stored rates are the ones the
  /// next step opens with), re-derives what the step takes from the last evaluation: the finest time bin.
  void store_restored();

  /// Fluid removed so far through the open top (geometry.outflow = remove); part of the state (checkpoints).
  const RemovedFluid& removed() const { return removed_; }
  void set_removed(const RemovedFluid& removed) { removed_ = removed; }

  /// Evaluates pressures, ghosts, grid and rates for the current state, and the next dt. Call once after
  /// set-up and after anything changes the particle set.
  void refresh();

  /// One time step (no stages). dt is min(next dt, dt_cap). With outflow = remove, fluid that left through the
  /// open top is removed after the drift (remove_outflow). With the watchdog on, a step that produces a
  /// NaN/Inf, a density error past the limit or a particle outside the domain is undone (the simulation is
  /// back at the last good state, removals included) and SimulationFailure is thrown.
  StepInfo step(double dt_cap = std::numeric_limits<double>::infinity());

  /// Steps (running the stages after each) until time() reaches t_end.
  void run_until(double t_end);

  void add_stage(std::unique_ptr<Stage> stage) { stages_.push_back(std::move(stage)); }
  const std::vector<std::unique_ptr<Stage>>& stages() const { return stages_; }
  /// Runs every stage once; refreshes if one changed the particles.
  void run_stages();

  DiagnosticsT<D> diagnostics() const;
  const SweepLimits& last_limits() const { return limits_; }
  const char* sweep_name() const { return sweep_->name(); }

  /// Runs across the ranks of `comm` (issue #19, core/domain.hpp): the cells are cut between the ranks, each keeps its
  /// own fluid (and every wall particle) with its rates as they are, and the neighbours are rebuilt with the halos.
  /// With `replicated`, every rank holds the same whole set (a set-up built whole, as the tests do) and keeps its
  /// share; without, the ranks hold disjoint parts of the fluid (a set-up built in shares, a checkpoint read in
  /// slabs), and every wall particle, and the fluid moves to its owners. Collective; with one rank nothing changes.
  /// Call it again to recut from scratch (the cells follow the largest smoothing length).
  void distribute(const par::Comm& comm, bool replicated = true);
  /// The decomposition when the run is distributed (nullptr in one process).
  const DomainT<D>* domain() const { return domain_.get(); }
  const par::Comm& comm() const { return domain_ ? domain_->comm() : par::Comm::world(); }
  /// Recuts the cells when the ranks' loads (force evaluations per step: max / mean) pass `threshold` and are worse
  /// than the last recut left them; the particles move to their new owners at the next step's exchange, with their
  /// rates, so the run's results do not change. Returns the recut, or nothing. Collective. Call it before a step:
  /// until that step's exchange, the store is laid out by the old cut.
  std::optional<RebalanceRecord> rebalance(double threshold);
  /// What the exchanges moved so far on this rank (halo copies, migrations, bytes).
  const ExchangeCounts& exchanged() const { return exchanged_; }
  /// Ghosts of this rank's own fluid in the current store (as one process would count them).
  std::size_t own_ghosts() const { return own_ghosts_; }

  /// Drops ghost particles from the store (for output and checkpoints); refresh() brings them back.
  void remove_ghosts() { Ghosts::remove(store_); }

  /// Rebuilds the ghosts and the cell grid and reorders the store into cell order, with one gather of
  /// every field: old ghosts dropped and new ones added (a stream expansion) and the cell sort composed
  /// into a single source map.
  void prepare_neighbours();

 private:
  double next_dt() const;
  /// The step's limits over every rank (the same on all); the limits as they are in one process.
  SweepLimits global(const SweepLimits& lim) const;
  /// The activity of substep k, with its due_prefix filled when only some bins are due.
  Activity activity(int k, int finest);
  /// Adds a finished step's work (finest bin, summed limits of its sweeps) to work_.
  void count_work(int finest, const SweepLimits& lim);
  /// Sets every fluid particle's next_bin for the coarse step the cheapest of the candidate shares of the levels'
  /// target step gives: from its own dt_limit (Integrator::bin_for), or with `neighbourhoods` from the smallest
  /// over its neighbourhood on grid_ as built (Integrator::neighbourhood_bins); true where any differs from its
  /// bin (on any rank).
  bool choose_bins(bool neighbourhoods = false);
  /// The bin limiter (Integrator::limit_bins) on the grid as built, pass after pass until no next bin changes on
  /// any rank (across ranks, with the halos and ghosts refreshed between passes; in one process the passes read
  /// only the fluid's own bins, and the ghosts copy theirs once at the end); skipped when the fluid's next bins
  /// span no more than bin_jump. True where it raised any.
  bool limit_bins();
  /// One process: every ghost's next bin from its source, through the last build's maps (expand_src_,
  /// expand_image_ and the grid's order), instead of a rebuild.
  void copy_next_bins_to_ghosts();
  /// Per-level steps, on the grid just built: choose_bins() from each particle's limit over its neighbourhood,
  /// the ghosts' and halos' copies of the next bins, and the limiter. True where any next bin differs from its
  /// bin (on any rank).
  bool choose_bins_on_grid();
  /// Whether any fluid particle's next bin differs from its bin (on any rank).
  bool next_bins_differ();
  /// How many entries particle i has in the expanded set: ghosts 0, walls 1, fluid 1 + its images.
  std::uint32_t output_count(const ParticleView<D>& view, std::size_t i) const;
  /// prepare_neighbours() from its second pass on: expand_offsets_[0..n) holds the output counts and hr the
  /// fluid's smoothing-length range (the step computes both in its kick loop).
  void build_neighbours(const SmoothingRange& hr);

  Settings settings_;
  std::vector<Wall<D>> walls_;  // settings_.geometry.walls(), built once (the settings do not change after construction)
  ParticleStore<D> store_;
  CellGrid<D> grid_;
  std::optional<Ghosts> ghosts_;
  Integrator integrator_;
  std::unique_ptr<SweepBase<D>> sweep_;
  std::vector<std::unique_ptr<Stage>> stages_;
  SweepLimits limits_;
  ParticleStore<D> last_good_;
  SweepLimits last_good_limits_;  // limits_ of the last good state (restored with it)
  RemovedFluid removed_, last_good_removed_;
  // Step workspace of prepare_neighbours (reused, so a step allocates nothing once sizes settle).
  std::vector<std::uint32_t> expand_src_, expand_offsets_;
  std::vector<std::uint32_t> gather_from_;  // build_neighbours: each slot's store index before the build
  std::vector<std::uint32_t> due_prefix_;  // Activity::due_prefix of the current substep
  std::vector<std::uint32_t> due_index_;   // Activity::due_index of the current substep
  Integrator::BinLimiterWork bin_limiter_;  // Integrator::limit_bins' workspace
  std::vector<std::uint32_t> ghost_source_;  // copy_next_bins_to_ghosts: each source's index after the build
  Integrator::NeighbourhoodWork neighbourhood_work_;  // Integrator::neighbourhood_bins' workspace
  std::vector<std::int8_t> expand_image_;
  std::vector<std::uint8_t> expand_layer_;  // each expanded particle's grid layer (its source's level)
  std::vector<Vec<D>> expand_x_;  // the state before the current step (watchdog rollback)
  Work work_;
  std::unique_ptr<DomainT<D>> domain_;
  double last_cut_ = 0.0;  // the loads (max / mean) the last recut made
  ExchangeCounts exchanged_;
  std::size_t own_ghosts_ = 0;
  double time_ = 0.0;
  std::uint64_t step_ = 0;
  std::uint64_t fine_steps_ = 0;
  int last_substeps_ = 1;
  double dt_ = 0.0;
};

extern template class SimulationT<2>;
extern template class SimulationT<3>;
using Simulation = SimulationT<2>;
using Stage = StageT<2>;

}  // namespace sph
