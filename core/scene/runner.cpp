#include "core/scene/runner.hpp"

#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/io/atomic_file.hpp"
#include "core/io/hdf5_frames.hpp"
#include "core/io/time_series.hpp"
#include "core/refinement/family.hpp"
#include "core/refinement/refinement_stage.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "parallel/comm.hpp"
#include "parallel/threads.hpp"

namespace sph::scene {

namespace {

constexpr double kTimeTolerance = 1e-9;  // relative to an interval: an output time reached up to rounding

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// The index of the first output strictly after time t.
std::uint64_t next_index(double t, double interval) {
  return static_cast<std::uint64_t>(std::floor(t / interval + kTimeTolerance)) + 1;
}

bool due(double t, std::uint64_t index, double interval) {
  return t / interval >= static_cast<double>(index) - kTimeTolerance;
}

double frame_interval(const Scene& s) { return s.output.frame_interval.value_or(s.time.interval()); }

/// The scene with what a resumed run may change (end time, outputs, probes, names, outflow) left out. The outflow
/// may change because a run stopped by fluid leaving over the rim (outflow "stop") has removed nothing up to its
/// checkpoint, exactly as a run with "remove" would have: resumed with "remove", it continues as that run.
Json physics_of(const Scene& s) {
  Json j = scene_to_json(s);
  for (const char* key : {"name", "description", "time", "probes", "output"}) j.erase(key);
  j["container"].erase("outflow");
  return j;
}

/// Distributed runs (issue #19): the loads are compared every this many steps, and the cells recut when the most
/// loaded rank carries more than this times the mean (force evaluations per step).
constexpr std::uint64_t kRebalanceEvery = 50;
constexpr double kRebalanceAbove = 1.10;

}  // namespace

template <int D>
RunnerT<D>::RunnerT(Scene scene, RunOptions options)
    : scene_(std::move(scene)),
      options_(std::move(options)),
      files_{options_.folder},
      sim_(build_simulation<D>(scene_, &par::Comm::world())),  // distributed: each rank builds its share
      probes_(scene_) {
  if (options_.resume) {
    // Distributed: each rank reads its slab of the rows (and every wall particle), then the fluid goes to its owners.
    io::CheckpointState state = io::read_checkpoint(*options_.resume, sim_.store(), &par::Comm::world());
    Scene original;
    try {
      original = scene_from_json(Json::parse(state.scene));
    } catch (const std::exception&) {
      throw SceneError("--resume", "the checkpoint does not hold a readable scene");
    }
    if (physics_of(original) != physics_of(scene_)) {
      throw SceneError("--resume", "the checkpoint was written by a different scene (only time, probes, output and container.outflow may change)");
    }
    // The first step after the checkpoint is the one it recorded; with a changed time.cfl (the way on after
    // a watchdog stop) or dt_max it follows the new settings at once (dt = cfl * limit, capped by dt_max).
    double dt = state.dt;
    if (original.time.cfl != scene_.time.cfl || original.time.dt_max != scene_.time.dt_max) {
      dt = std::min(state.dt / original.time.cfl * scene_.time.cfl, scene_.time.dt_max);
    }
    sim_.set_clock(state.time, state.step, dt);
    sim_.set_fine_step_count(state.fine_steps);
    sim_.distribute(par::Comm::world(), false);
    sim_.store_restored();
    next_row_ = state.next_row;
    next_frame_ = state.next_frame;
    frame_count_ = state.frame_count;
    next_checkpoint_ = state.next_checkpoint;
    particle_steps_ = state.particle_steps;
    initial_mass_ = state.initial_mass;
    initial_momentum_[0] = state.initial_momentum_x;
    initial_momentum_[1] = state.initial_momentum_y;
    if constexpr (D == 3) initial_momentum_[2] = state.initial_momentum_z;
    RemovedFluid removed;
    removed.particles = state.removed_particles;
    for (double part : state.removed_mass_parts) removed.mass.add(part);
    // Distributed, each rank counts what it removes, and the root carries what was removed before.
    if (par::Comm::world().root()) sim_.set_removed(removed);
    last_row_step_ = last_frame_step_ = last_checkpoint_step_ = state.step;
    resumed_ = true;
  }
  if (!resumed_) {
    const DiagnosticsT<D> d = sim_.diagnostics();
    initial_mass_ = d.mass;
    initial_momentum_ = d.momentum;
  }
  if (options_.threads_from_work) {
    thread_limit_ = omp_get_max_threads();
    fit_threads(fluid_count());
  }
}

template <int D>
void RunnerT<D>::fit_threads(std::size_t fluid) {
  if (thread_limit_ > 0) omp_set_num_threads(par::threads_for(fluid, thread_limit_));
}

template <int D>
RunnerT<D>::~RunnerT() = default;

template <int D>
bool RunnerT<D>::finished() const { return !(sim_.time() < scene_.time.end * (1.0 - 1e-14)); }

template <int D>
std::vector<std::string> RunnerT<D>::columns() const {
  std::vector<std::string> c{"time", "step", "dt", "fluid", "ghosts", "walls"};
  for (int l = 0; l <= finest_level(scene_); ++l) c.push_back("level_" + std::to_string(l));
  for (const char* name : {"mass", "removed", "removed_mass"}) c.emplace_back(name);
  const char* axes[] = {"x", "y", "z"};
  for (int a = 0; a < D; ++a) c.push_back(std::string("momentum_") + axes[a]);
  // Angular momentum about the origin: its z component in 2D, the vector in 3D.
  if constexpr (D == 2) {
    c.emplace_back("angular_momentum");
  } else {
    for (int a = 0; a < D; ++a) c.push_back(std::string("angular_momentum_") + axes[a]);
  }
  for (const char* name : {"kinetic", "potential", "elastic", "total_energy", "max_speed", "max_density_error"}) {
    c.emplace_back(name);
  }
  for (const auto& n : probes_.names()) c.push_back(n);
  return c;
}

template <int D>
std::size_t RunnerT<D>::fluid_count() const {
  const auto& kind = sim_.store().kind.values();
  std::size_t n = 0;
  for (const Kind k : kind) n += k == Kind::fluid ? 1 : 0;
  return n;
}

template <int D>
void RunnerT<D>::start() {
  if (started_) return;
  started_ = true;
  wall_start_ = now_seconds();
  if (options_.folder.empty()) return;
  if (!sim_.comm().root()) {  // distributed: the root writes; the others take part in the collective outputs
    if (!resumed_) write_due_outputs(false);
    return;
  }
  std::filesystem::create_directories(options_.folder);
  if (scene_.output.frames) std::filesystem::create_directories(files_.frames());
  if (resumed_) {
    // Continue the files of the interrupted run: drop the rows written after the checkpoint, and list the
    // frames written before it.
    if (std::filesystem::exists(files_.series())) {
      io::truncate_time_series(files_.series(), sim_.step_count());
      series_ = std::make_unique<io::TimeSeriesWriter>(files_.series(), columns(), true);
    } else {
      series_ = std::make_unique<io::TimeSeriesWriter>(files_.series(), columns(), false);
    }
    for (std::uint64_t f = 0; f < frame_count_; ++f) {
      const auto file = files_.frame(f);
      if (!std::filesystem::exists(file)) continue;
      frames_.push_back({"frames/" + io::RunFiles::frame_file_name(f), io::read_frame_header(file, io::RunFiles::frame_group(f))});
    }
    return;
  }
  io::write_file_atomic(files_.scene(), scene_to_json(scene_).dump(2) + "\n");
  series_ = std::make_unique<io::TimeSeriesWriter>(files_.series(), columns(), false);
  write_due_outputs(false);
}

template <int D>
void RunnerT<D>::advance() {
  if (!started_) start();
  // Distributed: a recut before the step, whose exchange then moves the particles to their new owners.
  if (sim_.comm().distributed() && sim_.step_count() > 0 && sim_.step_count() % kRebalanceEvery == 0 &&
      sim_.step_count() != last_recut_check_) {
    last_recut_check_ = sim_.step_count();
    if (const auto r = sim_.rebalance(kRebalanceAbove)) rebalances_.push_back(*r);
  }
  const double t0 = sim_.time();
  const double remaining = scene_.time.end - t0;
  if (sim_.dt() > remaining && options_.checkpoint_interval) {
    // The last step is shortened to land on the end time, which an uninterrupted longer run never does. The
    // checkpoint that ends this run is the state before that step, so that a run extended from it (--resume
    // with a later time.end) is bitwise the uninterrupted one; resumed with the same end, it replays this step.
    write_checkpoint();
    final_step_shortened_ = true;
  }
  try {
    sim_.step(remaining);
  } catch (const SimulationFailure& f) {
    fail(f.report());  // the simulation is back at the last good state
  }
  try {
    sim_.run_stages();
  } catch (const std::exception& e) {
    throw std::runtime_error("the simulation failed at t = " + std::to_string(t0) + " s (step " +
                             std::to_string(sim_.step_count()) + "): " + e.what());
  }
  const double dt = sim_.dt();
  if (!std::isfinite(dt) || !(dt > scene_.time.end * 1e-12)) {
    throw std::runtime_error("the simulation diverged at t = " + std::to_string(sim_.time()) + " s (step " +
                             std::to_string(sim_.step_count()) + "): the next time step is " + std::to_string(dt) +
                             " s; try a smaller time.cfl, a larger sound speed or more viscosity");
  }
  ++steps_run_;
  const std::size_t fluid = fluid_count();
  if (fluid != last_fluid_) fit_threads(fluid);
  last_fluid_ = fluid;
  last_fluid_total_ = sim_.comm().distributed() ? sim_.comm().sum(std::uint64_t{fluid}) : fluid;
  particle_steps_ += last_fluid_total_;
  write_due_outputs(false);
}

template <int D>
void RunnerT<D>::write_due_outputs(bool final) {
  if (options_.folder.empty()) return;
  const double t = sim_.time();
  const std::uint64_t step = sim_.step_count();
  const double interval = scene_.time.interval();
  if (final ? last_row_step_ != step : due(t, next_row_, interval)) {
    write_row();
    next_row_ = next_index(t, interval);
  }
  if (scene_.output.frames && (final ? last_frame_step_ != step : due(t, next_frame_, frame_interval(scene_)))) {
    write_frame();
    next_frame_ = next_index(t, frame_interval(scene_));
  }
  if (options_.checkpoint_interval && !final_step_shortened_) {
    const double ci = *options_.checkpoint_interval;
    if (final ? last_checkpoint_step_ != step : due(t, next_checkpoint_, ci)) {
      next_checkpoint_ = next_index(t, ci);
      write_checkpoint();
    }
  }
}

template <int D>
void RunnerT<D>::write_row() {
  const DiagnosticsT<D> d = sim_.diagnostics();
  std::vector<double> row{d.time, static_cast<double>(d.step), d.dt, static_cast<double>(d.fluid),
                          static_cast<double>(d.ghosts), static_cast<double>(d.walls)};
  for (int l = 0; l <= finest_level(scene_); ++l) {
    const auto k = static_cast<std::size_t>(l);
    row.push_back(k < d.per_level.size() ? static_cast<double>(d.per_level[k]) : 0.0);
  }
  for (const double v : {d.mass, static_cast<double>(d.removed), d.removed_mass}) row.push_back(v);
  for (int a = 0; a < D; ++a) row.push_back(d.momentum[a]);
  if constexpr (D == 2) {
    row.push_back(d.angular_momentum);
  } else {
    for (int a = 0; a < D; ++a) row.push_back(d.angular_momentum[a]);
  }
  for (const double v : {d.kinetic, d.potential, d.elastic, d.total_energy(), d.max_speed, d.max_density_error}) {
    row.push_back(v);
  }
  for (const double v : probes_.measure(sim_.store(), sim_.domain())) row.push_back(v);
  if (series_) series_->write(row);
  last_row_step_ = d.step;
  ++rows_;
}

template <int D>
void RunnerT<D>::write_frame() {
  const std::uint64_t index = frame_count_;
  // Distributed: every rank writes its rows of the one file (parallel HDF5); the root keeps the XDMF index.
  const io::FrameHeader h = io::write_frame(files_.frame(index), io::RunFiles::frame_group(index), sim_.store(),
                                            sim_.time(), sim_.step_count(), index, scene_.output.fields, &sim_.comm());
  if (sim_.comm().root()) {
    frames_.push_back({"frames/" + io::RunFiles::frame_file_name(index), h});
    io::write_xdmf(files_.xdmf(), frames_);
  }
  frame_count_ = index + 1;  // file numbering is dense: frame k is the k-th written; its time is an attribute
  last_frame_step_ = sim_.step_count();
  ++frames_written_;
}

template <int D>
void RunnerT<D>::write_checkpoint() {
  io::CheckpointState s;
  s.time = sim_.time();
  s.step = sim_.step_count();
  s.dt = sim_.dt();
  s.next_id = sim_.store().next_id();
  s.next_row = next_row_;
  s.next_frame = next_frame_;
  s.frame_count = frame_count_;
  s.next_checkpoint = next_checkpoint_;
  s.particle_steps = particle_steps_;
  s.fine_steps = sim_.fine_step_count();
  s.initial_mass = initial_mass_;
  s.initial_momentum_x = initial_momentum_[0];
  s.initial_momentum_y = initial_momentum_[1];
  if constexpr (D == 3) s.initial_momentum_z = initial_momentum_[2];
  s.scene = scene_to_json(scene_).dump();
  // Distributed: every rank's removals, and one file written by all (the one-process file: it resumes at any rank
  // count).
  const par::Comm& comm = sim_.comm();
  s.removed_particles = comm.sum(sim_.removed().particles);
  s.removed_mass_parts = comm.sum(sim_.removed().mass).parts();
  io::write_checkpoint(files_.checkpoint(), sim_.store(), s, &comm);
  last_checkpoint_step_ = s.step;
  ++checkpoints_;
}

template <int D>
typename RunnerT<D>::Summary RunnerT<D>::summary() const {
  Summary r;
  r.wall_seconds = now_seconds() - wall_start_;
  r.steps = steps_run_;
  r.particle_steps = particle_steps_;
  r.final = sim_.diagnostics();
  r.initial_mass = initial_mass_;
  r.initial_momentum = initial_momentum_;
  // Removed fluid left through the open top: it is accounted for, not lost (M + removed = M0).
  r.mass_drift = initial_mass_ > 0.0 ? (r.final.mass + r.final.removed_mass - initial_mass_) / initial_mass_ : 0.0;
  r.momentum_change = (r.final.momentum - initial_momentum_).norm();
  r.rows = rows_;
  r.frames = frames_written_;
  r.checkpoints = checkpoints_;
  return r;
}

template <int D>
void RunnerT<D>::write_summary(const Summary& r, const FailureReport* failure) {
  // Distributed: the work is every rank's (collective), and the root writes.
  const par::Comm& comm = sim_.comm();
  Work w = sim_.work();
  if (comm.distributed()) {
    for (auto& e : w.evaluations) e = comm.sum(e);
    w.pairs = comm.sum(w.pairs);
    w.candidates = comm.sum(w.candidates);
  }
  const std::uint64_t migrated = comm.sum(sim_.exchanged().migrated), halos = comm.sum(sim_.exchanged().halos),
                      bytes = comm.sum(sim_.exchanged().bytes);
  const double exchange_seconds = comm.max(sim_.exchanged().seconds);
  // The largest peak resident set of the ranks (the process's, in one process): what one machine must hold.
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double peak_rss = comm.max(static_cast<double>(usage.ru_maxrss) * 1024.0);
  // Dynamic refinement in this invocation: particles split, families merged, (across ranks) the families
  // merged with members lent by another rank, and the splits refused for want of room in a daughter's id.
  // And the families that could have merged but were left split, by reason (refine::MergesDeclined).
  std::optional<std::array<std::uint64_t, 4>> passes;
  std::array<std::uint64_t, 4> declined{};
  for (const auto& stage : sim_.stages()) {
    if (const auto* rs = dynamic_cast<const refine::RefinementStageIn<D>*>(stage.get())) {
      passes = std::array<std::uint64_t, 4>{comm.sum(std::uint64_t{rs->total_refined()}),
                                            comm.sum(std::uint64_t{rs->total_merged()}),
                                            comm.sum(std::uint64_t{rs->merged_across_ranks()}),
                                            comm.sum(std::uint64_t{rs->total_refused()})};
      const refine::MergesDeclined& d = rs->total_declined();
      declined = {comm.sum(std::uint64_t{d.walls}), comm.sum(std::uint64_t{d.criterion}),
                  comm.sum(std::uint64_t{d.dispersed}), comm.sum(std::uint64_t{d.intermixed})};
    }
  }
  if (passes && (*passes)[3] > 0 && comm.root()) {
    std::fprintf(stderr,
                 "sphrefine: warning: %llu particles marked for a split were left whole: their daughters' ids would "
                 "not fit (%d generations; with coarsening.groups = \"cell\" each split-merge cycle can add one)\n",
                 static_cast<unsigned long long>((*passes)[3]), refine::kMaxGenerationsIn<D>);
  }
  if (options_.folder.empty() || !comm.root()) return;
  Json j;
  j["scene"] = scene_.name;
  j["version"] = SPH_VERSION;
  j["build_type"] = SPH_BUILD_TYPE;
  j["threads"] = omp_get_max_threads();
  j["ranks"] = comm.size();
  if (comm.distributed()) {
    // Every rank's exchanges: particles that changed rank, halo copies, bytes sent, and the most time one rank spent
    // in them (waiting for the others included); the recuts with the loads before and after (max / mean).
    Json recuts = Json::array();
    for (const RebalanceRecord& rb : rebalances_) {
      recuts.push_back({{"step", rb.step}, {"imbalance_before", rb.before}, {"imbalance_after", rb.after},
                        {"seconds", rb.seconds}});
    }
    j["exchange"] = {{"migrated", migrated},          {"halo_copies", halos},
                     {"bytes_sent", bytes},           {"seconds_most", exchange_seconds},
                     {"rebalance_threshold", kRebalanceAbove}, {"rebalances", recuts}};
  }
  j["threads_rule"] = thread_limit_ > 0 ? "one per " + std::to_string(par::kMinItemsPerThread) +
                                              " fluid particles, at most " + std::to_string(thread_limit_)
                                        : std::string("as set");
  j["dimension"] = D;
  j["sweep"] = sim_.sweep_name();
  j["resumed"] = resumed_;
  j["status"] = failure ? "failed" : "completed";
  j["time"] = r.final.time;
  j["step"] = r.final.step;
  j["steps_this_run"] = r.steps;
  j["wall_seconds"] = r.wall_seconds;
  j["peak_rss_bytes"] = peak_rss;
  j["particle_steps"] = r.particle_steps;
  j["particle_steps_per_second"] = r.wall_seconds > 0.0 ? static_cast<double>(r.particle_steps) / r.wall_seconds : 0.0;
  j["fluid_per_level"] = r.final.per_level;
  // The work of this invocation: force evaluations per level (a particle evaluated when due), pair
  // interactions, neighbour candidates checked, and sweeps (substeps). With time.stepping = "global" a step is
  // one sweep of every particle.
  {
    std::size_t levels = 1;
    for (std::size_t l = 0; l < w.evaluations.size(); ++l)
      if (w.evaluations[l] > 0) levels = l + 1;
    j["stepping"] = to_string(scene_.time.stepping);
    j["force_evaluations_per_level"] =
        std::vector<std::uint64_t>(w.evaluations.begin(), w.evaluations.begin() + static_cast<std::ptrdiff_t>(levels));
    j["pair_interactions"] = w.pairs;
    j["neighbour_candidates"] = w.candidates;
    j["sweeps"] = w.substeps;
  }
  if (passes) {
    j["refinement"] = {{"split", (*passes)[0]}, {"merged_families", (*passes)[1]},
                       {"merged_families_across_ranks", (*passes)[2]}, {"splits_refused_no_id_room", (*passes)[3]},
                       {"merges_declined", {{"walls", declined[0]}, {"criterion", declined[1]},
                                            {"dispersed", declined[2]}, {"intermixed", declined[3]}}}};
  }
  j["removed_particles"] = r.final.removed;
  j["removed_mass"] = r.final.removed_mass;
  j["mass_drift"] = r.mass_drift;
  j["momentum_change"] = r.momentum_change;
  j["rows"] = r.rows;
  j["frames"] = r.frames;
  if (failure) {
    j["failure"] = {{"kind", to_string(failure->kind)},
                    {"step", failure->step},
                    {"time", failure->time},
                    {"particle", failure->id},
                    {"position", std::vector<double>(failure->position.data(), failure->position.data() + failure->position.size())},
                    {"quantity", failure->quantity},
                    {"cause", failure->cause},
                    {"last_good_step", r.final.step},
                    {"last_good_time", r.final.time},
                    {"checkpoint", files_.checkpoint().filename().string()}};
  }
  io::write_file_atomic(files_.summary(), j.dump(2) + "\n");
}

template <int D>
void RunnerT<D>::fail(const FailureReport& report) {
  std::string where;
  if (!options_.folder.empty()) {
    // The simulation holds the last good state: leave it behind, complete, for inspection and --resume (every rank
    // takes part in writing it; the root says where it is).
    const std::uint64_t step = sim_.step_count();
    if (last_row_step_ != step) write_row();
    if (scene_.output.frames && last_frame_step_ != step) write_frame();
    write_checkpoint();
    write_summary(summary(), &report);
    if (sim_.comm().root()) {
      char buf[96];
      std::snprintf(buf, sizeof buf, " The last good state (step %llu, t = %.6g s) is in ",
                    static_cast<unsigned long long>(step), sim_.time());
      where = buf;
      if (scene_.output.frames) where += (options_.folder / frames_.back().file).string() + " and ";
      where += files_.checkpoint().string() + (report.kind == FailureKind::left_open_top
                                                   ? " (continue with --resume and --set container.outflow=remove)."
                                                   : " (continue with --resume and a smaller time.cfl).");
    }
  }
  throw RunFailure(report.message() + "." + where, report);
}

template <int D>
typename RunnerT<D>::Summary RunnerT<D>::finish() {
  if (!started_) start();
  write_due_outputs(true);
  const Summary r = summary();
  write_summary(r, nullptr);
  return r;
}

template <int D>
typename RunnerT<D>::Summary RunnerT<D>::run(const std::function<void(const Progress&)>& on_step) {
  start();
  while (!finished()) {
    advance();
    if (on_step) {
      on_step(Progress{sim_.time(), scene_.time.end, sim_.step_count(), steps_run_, last_fluid_total_,
                       now_seconds() - wall_start_});
    }
  }
  return finish();
}

template class RunnerT<2>;
template class RunnerT<3>;

}  // namespace sph::scene
