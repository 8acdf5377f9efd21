#include "core/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "parallel/parallel_for.hpp"

namespace sph {

Simulation::Simulation(SolverSettings settings) : settings_(std::move(settings)) {
  if (settings_.ghosts) {
    ghosts_.emplace(settings_.geometry.walls(), *settings_.ghosts, settings_.ghost_pressure,
                    settings_.gravity.value_or(Vec<2>::Zero()), settings_.eos);
  }
  sweep_ = make_sweep(settings_);
}

void Simulation::prepare_neighbours() {
  const auto view = store_.view();
  const std::size_t n = view.n;
  // 1. The expansion: each particle's outputs (ghosts 0, walls 1, fluid 1 + its images).
  expand_offsets_.resize(n + 1);
  if (ghosts_) {
    par::parallel_for(n, [&](std::size_t i) { expand_offsets_[i] = ghosts_->output_count(view, i); });
  } else {
    par::parallel_for(n, [&](std::size_t i) { expand_offsets_[i] = 1; });
  }
  expand_offsets_[n] = par::exclusive_scan(expand_offsets_.data(), expand_offsets_.data(), n);
  const std::size_t m = expand_offsets_[n];
  expand_src_.resize(m);
  expand_image_.resize(m);
  expand_x_.resize(m);
  par::parallel_for(n, [&](std::size_t i) {
    const std::uint32_t first = expand_offsets_[i], count = expand_offsets_[i + 1] - first;
    if (count == 0) return;
    expand_src_[first] = static_cast<std::uint32_t>(i);
    expand_image_[first] = -1;
    expand_x_[first] = view.x[i];
    if (count == 1) return;
    const GhostBuilder::Images im = ghosts_->images(view.x[i], view.v[i], view.h[i]);
    for (std::uint32_t g = 1; g < count; ++g) {
      expand_src_[first + g] = static_cast<std::uint32_t>(i);
      expand_image_[first + g] = static_cast<std::int8_t>(g - 1);
      expand_x_[first + g] = im.x[g - 1];
    }
  });
  // 2. The cell sort of the expanded set, composed with the expansion into one source map.
  // Cells as wide as the finest support present (2 h_min); each particle's query reaches h_i + h_max
  // (CellGrid). A uniform set gets the classic support-sized cells.
  const auto h = view.h;
  struct Range {
    double lo, hi;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const Range hr = par::reduce(
      n, Range{inf, 0.0},
      [&](std::size_t i) { return view.kind[i] == Kind::ghost ? Range{inf, 0.0} : Range{h[i], h[i]}; },
      [](const Range& a, const Range& b) { return Range{std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; });
  grid_.build(expand_x_.data(), m, std::max(2.0 * std::min(hr.lo, hr.hi), 1e-12), hr.hi);
  const auto& order = grid_.order();
  gather_src_.resize(m);
  gather_image_.resize(m);
  par::parallel_for(m, [&](std::size_t k) {
    gather_src_[k] = expand_src_[order[k]];
    gather_image_[k] = expand_image_[order[k]];
  });
  // 3. One gather of every field, then the copies that are ghosts become ghosts.
  store_.gather(gather_src_);
  if (ghosts_) {
    auto s = store_.view();
    par::parallel_for(m, [&](std::size_t k) {
      if (gather_image_[k] >= 0) ghosts_->make_ghost(s, k, gather_image_[k]);
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
  if (watch) {
    last_good_.assign_from(store_);  // reuses capacity: no allocation once the sizes are stable
    last_good_limits_ = limits_;
    last_good_removed_ = removed_;
  }
  const double half = 0.5 * dt;
  const TaitEquationOfState eos = settings_.eos;
  {
    auto s = store_.view();
    par::parallel_for(s.n, [&](std::size_t i) {
      if (s.kind[i] != Kind::fluid) return;
      s.vh[i] = s.v[i] + half * s.a[i];
      s.rhoh[i] = s.rho[i] + half * s.drho[i];
      s.x[i] += dt * s.vh[i];
      s.v[i] = s.vh[i] + half * s.a[i];
      s.rho[i] = s.rhoh[i] + half * s.drho[i];
      s.p[i] = eos.pressure(s.rho[i]);
    });
  }
  if (settings_.geometry.outflow == Outflow::remove) removed_.add(remove_outflow(store_, settings_.geometry));
  // The drift can already have produced a non-finite position, which the grid refuses: with the watchdog on,
  // that is reported (and undone) like any other failure of the step, naming the particle.
  std::string step_error;
  try {
    prepare_neighbours();
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
