#pragma once
// Runs a scene to its end time with its outputs: the time series (diagnostics and probes) every
// output_interval, HDF5 frames with an XDMF index every frame_interval, checkpoints on request, and a
// run summary. Outputs only read the particles (ghosts are skipped, never removed), and output times never
// cap the time step, so a run that writes output is bitwise identical to one that does not; a run resumed
// from a checkpoint continues bitwise identically to the uninterrupted run.
//
// Output times: row k is written at the first step whose time reaches k * output_interval (t = 0 included),
// and a last row at the end; frames likewise with frame_interval.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/diagnostics.hpp"
#include "core/io/output_folder.hpp"
#include "core/io/xdmf.hpp"
#include "core/scene/probes.hpp"
#include "core/scene/scene.hpp"
#include "core/simulation.hpp"

namespace sph::io {
class TimeSeriesWriter;
}

namespace sph::scene {

struct RunOptions {
  std::filesystem::path folder;                 // output folder; empty: the run writes nothing
  std::optional<std::filesystem::path> resume;  // continue from this checkpoint
  std::optional<double> checkpoint_interval;    // simulated seconds between checkpoints (and one at the end:
                                                // the state before the last step if that step was shortened
                                                // to land on the end time, so that an extended run continues
                                                // the uninterrupted one)
  /// false: OpenMP's thread count is left as the caller set it. true: the runner picks it from the fluid
  /// count (par::threads_for, parallel/threads.hpp) whenever the count changes, up to the threads OpenMP
  /// offers when the runner is made. Results are the same either way; only speed differs.
  bool threads_from_work = false;
};

struct Progress {
  double time = 0.0;
  double end = 0.0;
  std::uint64_t step = 0;          // the simulation's step counter
  std::uint64_t steps_run = 0;     // steps taken by this invocation
  std::size_t fluid = 0;           // fluid particles
  double wall_seconds = 0.0;       // since run() started
};

/// A run the watchdog stopped. By the time it is thrown the runner has written the last good state (the
/// state before the failing step): a time-series row, a frame and a checkpoint, and run.json with
/// "status": "failed" and the report. what() is one line: the report and where the last good state went.
class RunFailure : public std::runtime_error {
 public:
  RunFailure(const std::string& message, FailureReport report)
      : std::runtime_error(message), report_(std::move(report)) {}
  const FailureReport& report() const { return report_; }

 private:
  FailureReport report_;
};

template <int D>
struct RunSummaryT {
  double wall_seconds = 0.0;
  std::uint64_t steps = 0;           // taken by this invocation
  std::uint64_t particle_steps = 0;  // sum over those steps of the fluid particle count
  DiagnosticsT<D> final;
  double initial_mass = 0.0;
  Vec<D> initial_momentum = Vec<D>::Zero();
  double mass_drift = 0.0;      // (M + removed mass - M0) / M0: fluid removed through the open top is accounted
  double momentum_change = 0.0; // |P - P0| (kg m/s); walls and gravity change it physically
  std::uint64_t rows = 0, frames = 0, checkpoints = 0;
};
using RunSummary = RunSummaryT<2>;

/// The runner of a scene of dimension D (with_dimension picks it; the constructor refuses another).
template <int D>
class RunnerT {
 public:
  using Summary = RunSummaryT<D>;

  /// Builds the simulation (or loads the checkpoint). Does not create the folder: call start().
  RunnerT(Scene scene, RunOptions options);
  ~RunnerT();
  RunnerT(const RunnerT&) = delete;
  RunnerT& operator=(const RunnerT&) = delete;

  const Scene& scene() const { return scene_; }
  SimulationT<D>& simulation() { return sim_; }
  const SimulationT<D>& simulation() const { return sim_; }
  double end_time() const { return scene_.time.end; }
  bool finished() const;

  /// Creates the output folder, writes the resolved scene and the first outputs (not when resuming).
  void start();
  /// One step, the stages, and the outputs that fall due. Throws RunFailure when the watchdog stops the run
  /// (after writing the last good state), std::runtime_error if the run diverges otherwise.
  void advance();
  /// The last outputs, a checkpoint if requested, run.json; returns the summary.
  Summary finish();
  /// start(), advance() until the end (calling on_step after each step), finish().
  Summary run(const std::function<void(const Progress&)>& on_step = {});

  /// The time-series column names.
  std::vector<std::string> columns() const;

 private:
  void write_due_outputs(bool final);
  void write_row();
  void write_frame();
  void write_checkpoint();
  Summary summary() const;
  void write_summary(const Summary& r, const FailureReport* failure);
  [[noreturn]] void fail(const FailureReport& report);
  std::size_t fluid_count() const;
  void fit_threads(std::size_t fluid);

  Scene scene_;
  RunOptions options_;
  io::RunFiles files_;
  SimulationT<D> sim_;
  Probes probes_;
  std::unique_ptr<io::TimeSeriesWriter> series_;
  std::vector<io::XdmfEntry> frames_;
  std::uint64_t next_row_ = 0, next_frame_ = 0, frame_count_ = 0, next_checkpoint_ = 1;
  std::uint64_t last_row_step_ = UINT64_MAX, last_frame_step_ = UINT64_MAX, last_checkpoint_step_ = UINT64_MAX;
  std::uint64_t particle_steps_ = 0, steps_run_ = 0, rows_ = 0, frames_written_ = 0, checkpoints_ = 0;
  std::vector<RebalanceRecord> rebalances_;  // distributed: the recuts of the cells
  std::uint64_t last_recut_check_ = 0;
  std::size_t last_fluid_ = 0;  // fluid particles after the last step (this rank's own)
  std::size_t last_fluid_total_ = 0;  // ... on every rank
  int thread_limit_ = 0;        // threads_from_work: the most threads the runner may use
  double initial_mass_ = 0.0;
  Vec<D> initial_momentum_ = Vec<D>::Zero();
  bool resumed_ = false;
  bool final_step_shortened_ = false;  // the checkpoint holds the state before the shortened last step
  bool started_ = false;
  double wall_start_ = 0.0;
};

using Runner = RunnerT<2>;
using Runner3 = RunnerT<3>;

}  // namespace sph::scene
