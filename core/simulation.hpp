#pragma once
// The simulation driver: owns the particle store and runs the step pipeline of ARCHITECTURE.md:
//   kick + drift -> ghosts -> cell grid (reorders the store) -> pair sweep -> kick, variable dt;
//   between steps, the run-time stages (refinement, probes, output) get one call each.
//
// Time integration (PHYSICS.md decision): kick-drift-kick with one force evaluation per step.
//   v_h = v_n + dt/2 a_n,  rho_h = rho_n + dt/2 drho_n,  x_{n+1} = x_n + dt v_h,
//   forces at x_{n+1} with the predicted v = v_h + dt/2 a_n and rho = rho_h + dt/2 drho_n,
//   v_{n+1} = v_h + dt/2 a_{n+1},  rho_{n+1} = rho_h + dt/2 drho_{n+1}.
// With central pair forces this conserves linear and angular momentum to rounding.
//
// Parallel regions per step (each a fork and a join, and on busy cores each can cost a scheduler time slice):
// 1. the watchdog's copy, kick and drift, output counts and h range (one loop); 2. the scan of the counts;
// 3. the expansion with its bounding box; 4. the cell sort (one region, its phases separated by barriers);
// 5. the gather of every field through the composed map; 6. the ghosts' values; 7. the pair sweep; 8. the
// closing kick; 9. the watchdog's scan. There were 19.
#include <memory>
#include <optional>
#include <vector>

#include "core/boundary/ghosts.hpp"
#include "core/boundary/outflow.hpp"
#include "core/cell_grid.hpp"
#include "core/diagnostics.hpp"
#include "core/neighbour_cells.hpp"
#include "core/particle_store.hpp"
#include "core/solver_settings.hpp"
#include "core/sweep_factory.hpp"

namespace sph {

class Simulation;

/// A per-stage effect (refinement, probes, output): one call between steps, never one per particle.
class Stage {
 public:
  virtual ~Stage() = default;
  virtual const char* name() const = 0;
  /// Called after every step. Returns true when it changed the particle set (the solver then rebuilds
  /// ghosts and grid and re-evaluates the rates before the next step).
  virtual bool after_step(Simulation& sim) = 0;
};

struct StepInfo {
  double dt = 0.0;
  SweepLimits limits;
};

class Simulation {
 public:
  explicit Simulation(SolverSettings settings);

  const SolverSettings& settings() const { return settings_; }
  ParticleStore<2>& store() { return store_; }
  const ParticleStore<2>& store() const { return store_; }
  const CellGrid<2>& grid() const { return grid_; }
  const GhostBuilder* ghosts() const { return ghosts_ ? &*ghosts_ : nullptr; }

  double time() const { return time_; }
  std::uint64_t step_count() const { return step_; }
  double dt() const { return dt_; }
  void set_clock(double time, std::uint64_t step, double dt) {
    time_ = time;
    step_ = step;
    dt_ = dt;
  }

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
  /// Runs every stage once; refreshes if one changed the particles.
  void run_stages();

  Diagnostics diagnostics() const;
  const SweepLimits& last_limits() const { return limits_; }
  const char* sweep_name() const { return sweep_->name(); }

  /// Drops ghost particles from the store (for output and checkpoints); refresh() brings them back.
  void remove_ghosts() { GhostBuilder::remove(store_); }

  /// Rebuilds the ghosts and the cell grid and reorders the store into cell order, with one gather of
  /// every field: old ghosts dropped and new ones added (a stream expansion) and the cell sort composed
  /// into a single source map.
  void prepare_neighbours();

 private:
  double next_dt() const;
  /// How many entries particle i has in the expanded set: ghosts 0, walls 1, fluid 1 + its images.
  std::uint32_t output_count(const ParticleView<2>& view, std::size_t i) const;
  /// prepare_neighbours() from its second pass on: expand_offsets_[0..n) holds the output counts and hr the
  /// fluid's smoothing-length range (the step computes both in its kick loop).
  void build_neighbours(const SmoothingRange& hr);

  SolverSettings settings_;
  ParticleStore<2> store_;
  CellGrid<2> grid_;
  std::optional<GhostBuilder> ghosts_;
  std::unique_ptr<SweepBase> sweep_;
  std::vector<std::unique_ptr<Stage>> stages_;
  SweepLimits limits_;
  ParticleStore<2> last_good_;
  SweepLimits last_good_limits_;  // limits_ of the last good state (restored with it)
  RemovedFluid removed_, last_good_removed_;
  // Step workspace of prepare_neighbours (reused, so a step allocates nothing once sizes settle).
  std::vector<std::uint32_t> expand_src_, expand_offsets_;
  std::vector<std::int8_t> expand_image_;
  std::vector<Vec<2>> expand_x_;  // the state before the current step (watchdog rollback)
  double time_ = 0.0;
  std::uint64_t step_ = 0;
  double dt_ = 0.0;
};

}  // namespace sph
