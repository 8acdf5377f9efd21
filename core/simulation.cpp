#include "core/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/neighbour_cells.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

Simulation::Simulation(SolverSettings settings) : settings_(std::move(settings)) {
  if (settings_.ghosts) {
    ghosts_.emplace(settings_.geometry.walls(), *settings_.ghosts, settings_.ghost_pressure,
                    settings_.gravity.value_or(Vec<2>::Zero()), settings_.eos);
  }
  sweep_ = make_sweep(settings_);
}

std::uint32_t Simulation::output_count(const ParticleView<2>& view, std::size_t i) const {
  if (ghosts_) return ghosts_->output_count(view, i);
  return view.kind[i] == Kind::ghost ? 0u : 1u;
}

void Simulation::prepare_neighbours() {
  const auto view = store_.view();
  expand_offsets_.resize(view.n + 1);
  const SmoothingRange hr = par::reduce(
      view.n, SmoothingRange{},
      [&](std::size_t i) {
        expand_offsets_[i] = output_count(view, i);
        return SmoothingRange::of(view.kind[i], view.h[i]);
      },
      [](const SmoothingRange& a, const SmoothingRange& b) { return a.merged(b); });
  build_neighbours(hr);
}

void Simulation::build_neighbours(const SmoothingRange& hr) {
  // Parallel regions here: the scan of the output counts, the expansion (with the bounding box of what it
  // writes), the cell sort, the gather of every field, the ghosts' own values. expand_offsets_[0..n) holds
  // each particle's output count (ghosts 0, walls 1, fluid 1 + its images), written by the caller's loop.
  const auto view = store_.view();
  const std::size_t n = view.n;
  expand_offsets_[n] = par::exclusive_scan(expand_offsets_.data(), expand_offsets_.data(), n);
  const std::size_t m = expand_offsets_[n];
  expand_src_.resize(m);
  expand_image_.resize(m);
  expand_x_.resize(m);
  using Box = CellGrid<2>::Box;
  const Box box = par::reduce(
      n, Box{},
      [&](std::size_t i) {
        const std::uint32_t first = expand_offsets_[i], count = expand_offsets_[i + 1] - first;
        Box b;
        if (count == 0) return b;
        expand_src_[first] = static_cast<std::uint32_t>(i);
        expand_image_[first] = -1;
        expand_x_[first] = view.x[i];
        b = Box::of(view.x[i]);
        if (count == 1) return b;
        const GhostBuilder::Images im = ghosts_->images(view.x[i], view.v[i], view.h[i]);
        for (std::uint32_t g = 1; g < count; ++g) {
          expand_src_[first + g] = static_cast<std::uint32_t>(i);
          expand_image_[first + g] = static_cast<std::int8_t>(g - 1);
          expand_x_[first + g] = im.x[g - 1];
          b = b.merged(Box::of(im.x[g - 1]));
        }
        return b;
      },
      [](const Box& a, const Box& b) { return a.merged(b); });
  // The cell sort of the expanded set, composed with the expansion into one source map. Cells sized by the
  // finest support present (core/neighbour_cells.hpp); each particle's query reaches h_i + h_max.
  grid_.build_in(box, expand_x_.data(), m, neighbour_cell_size(hr), hr.max);
  const std::uint32_t* order = grid_.order().data();
  const std::uint32_t* src = expand_src_.data();
  // One gather of every field, then the copies that are ghosts become ghosts.
  store_.gather(m, [order, src](std::size_t k) { return src[order[k]]; });
  if (ghosts_) {
    auto s = store_.view();
    par::parallel_for(m, [&](std::size_t k) {
      const std::int8_t image = expand_image_[order[k]];
      if (image >= 0) ghosts_->make_ghost(s, k, image);
    });
  }
}

void Simulation::refresh() {
  auto s = store_.view();
  const TaitEquationOfState eos = settings_.eos;
  par::parallel_for(s.n, [&](std::size_t i) {
    if (s.kind[i] == Kind::fluid) s.p[i] = eos.pressure(s.rho[i]);
  });
  prepare_neighbours();
  limits_ = sweep_->run(store_.view(), grid_);
  dt_ = next_dt();
}

double Simulation::next_dt() const {
  const double dt = settings_.cfl * std::min(limits_.dt_force, limits_.dt_cfl);
  return std::min(dt, settings_.dt_max);
}

StepInfo Simulation::step(double dt_cap) {
  const double dt = std::min(dt_, dt_cap);
  const bool watch = settings_.watchdog.enabled;
  const double half = 0.5 * dt;
  const TaitEquationOfState eos = settings_.eos;
  std::string step_error;
  // One parallel region for the rollback copy, the kick and drift, and the first pass of the neighbour
  // preparation (each particle's output count and the smoothing-length range): all per particle.
  if (watch) {
    last_good_.prepare_copy_of(store_);  // reuses capacity: no allocation once the sizes are stable
    last_good_limits_ = limits_;
    last_good_removed_ = removed_;
  }
  SmoothingRange hr;
  {
    auto s = store_.view();
    expand_offsets_.resize(s.n + 1);
    hr = par::reduce(
        s.n, SmoothingRange{},
        [&](std::size_t i) {
          if (watch) last_good_.copy_particle(store_, i);
          if (s.kind[i] == Kind::fluid) {
            s.vh[i] = s.v[i] + half * s.a[i];
            s.rhoh[i] = s.rho[i] + half * s.drho[i];
            s.x[i] += dt * s.vh[i];
            s.v[i] = s.vh[i] + half * s.a[i];
            s.rho[i] = s.rhoh[i] + half * s.drho[i];
            s.p[i] = eos.pressure(s.rho[i]);
          }
          expand_offsets_[i] = output_count(s, i);
          return SmoothingRange::of(s.kind[i], s.h[i]);
        },
        [](const SmoothingRange& a, const SmoothingRange& b) { return a.merged(b); });
  }
  // Fluid that left through an open top (container.outflow = "remove") goes now, before the neighbour search
  // and the watchdog. A removal renumbers the particles, so the counts and range of the loop above are redone.
  bool renumbered = false;
  if (settings_.geometry.outflow == Outflow::remove) {
    const RemovedFluid out = remove_outflow(store_, settings_.geometry);
    removed_.add(out);
    renumbered = out.particles > 0;
  }
  // The drift can already have produced a non-finite position, which the grid refuses: with the watchdog on,
  // that is reported (and undone) like any other failure of the step, naming the particle.
  try {
    if (renumbered) {
      prepare_neighbours();
    } else {
      build_neighbours(hr);
    }
    limits_ = sweep_->run(store_.view(), grid_);
  } catch (const std::exception& e) {
    if (!watch) throw;
    step_error = e.what();
  }
  if (step_error.empty()) {
    auto s = store_.view();
    par::parallel_for(s.n, [&](std::size_t i) {
      if (s.kind[i] != Kind::fluid) return;
      s.v[i] = s.vh[i] + half * s.a[i];
      s.rho[i] = s.rhoh[i] + half * s.drho[i];
      s.p[i] = eos.pressure(s.rho[i]);
    });
  }
  if (watch) {
    FailureReport report;
    if (find_failure(store_, settings_.geometry, eos.rho0, settings_.watchdog, report) || !step_error.empty() ||
        !(std::isfinite(dt) && dt > 0.0)) {
      if (report.quantity.empty() && !step_error.empty()) {
        report.quantity = "the step could not be completed (" + step_error + ")";
        report.cause = "a time step too large for the forces, or an invalid state";
      }
      if (report.quantity.empty()) {
        report.quantity = "the time step is not a positive finite number";
        report.cause = "an acceleration or velocity became NaN or Inf";
      }
      report.step = step_ + 1;
      report.time = time_ + dt;
      // Back to the last good state exactly: its particles with their rates (a, drho) and limits as they
      // were, so dt_ (not yet advanced) and the next step are those of a run that never took the failed step.
      // Only the grid is rebuilt for the restored particles (same order and ghosts; no rate re-evaluation).
      std::swap(store_, last_good_);
      limits_ = last_good_limits_;
      removed_ = last_good_removed_;
      prepare_neighbours();
      throw SimulationFailure(report);
    }
  }
  time_ += dt;
  ++step_;
  dt_ = next_dt();
  return {dt, limits_};
}

void Simulation::run_stages() {
  bool changed = false;
  for (auto& stage : stages_) changed = stage->after_step(*this) || changed;
  if (changed) refresh();
}

void Simulation::run_until(double t_end) {
  while (time_ < t_end * (1.0 - 1e-14)) {
    step(t_end - time_);
    run_stages();
  }
}

Diagnostics Simulation::diagnostics() const {
  Diagnostics d = compute_diagnostics(store_, settings_.eos, settings_.gravity.value_or(Vec<2>::Zero()));
  d.time = time_;
  d.step = step_;
  d.dt = dt_;
  d.removed = removed_.particles;
  d.removed_mass = removed_.mass.value();
  return d;
}

}  // namespace sph
