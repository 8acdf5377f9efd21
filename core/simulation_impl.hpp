#pragma once
// The driver's definitions, instantiated once per dimension (simulation_2d.cpp, simulation_3d.cpp: two
// translation units, which a parallel build compiles side by side).
#include "core/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "core/neighbour_cells.hpp"
#include "core/refinement/buffer.hpp"
#include "parallel/parallel_for.hpp"
#include "parallel/scan.hpp"

namespace sph {

template <int D>
SimulationT<D>::SimulationT(Settings settings)
    : settings_(std::move(settings)),
      walls_(settings_.geometry.walls()),
      integrator_(settings_.stepping, settings_.eos, settings_.bin_jump, settings_.predictor) {
  if (settings_.ghosts) {
    ghosts_.emplace(walls_, *settings_.ghosts, settings_.ghost_pressure,
                    settings_.gravity.value_or(Vec<D>::Zero()), settings_.eos);
  }
  sweep_ = make_sweep(settings_);
}

template <int D>
std::uint32_t SimulationT<D>::output_count(const ParticleView<D>& view, std::size_t i) const {
  if (ghosts_) return ghosts_->output_count(view, i);
  return view.kind[i] == Kind::ghost ? 0u : 1u;
}

template <int D>
void SimulationT<D>::prepare_neighbours() {
  if (domain_) {  // distributed: halos and migration first
    const ExchangeCounts c = domain_->exchange(store_);
    exchanged_.migrated += c.migrated;
    exchanged_.halos += c.halos;
    exchanged_.bytes += c.bytes;
    exchanged_.seconds += c.seconds;
  }
  const auto view = store_.view();
  expand_offsets_.resize(view.n + 1);
  SmoothingRange hr = par::accumulate(
      view.n, SmoothingRange{},
      [&](SmoothingRange& r, std::size_t i) {
        expand_offsets_[i] = output_count(view, i);
        r.add(view.kind[i], view.h[i], view.level[i]);
      },
      [](const SmoothingRange& a, const SmoothingRange& b) { return a.merged(b); });
  // Distributed, the layers and their cell sizes come from every rank's fluid, as in one process.
  if (domain_) {
    for (const SmoothingRange& other : domain_->comm().all_gather_value(hr)) hr = hr.merged(other);
  }
  // The counts above used the ghosts' reach of the last build. The fluid's largest h changes only where its
  // particles change (a split or merge pass, the outflow, a restore: each ends here), so a step's own builds
  // keep it. Where it did change, the counts are taken again with the new reach.
  if (ghosts_ && hr.max() != ghosts_->largest_h() && !hr.empty()) {
    ghosts_->set_largest_h(hr.max());
    par::parallel_for(view.n, [&](std::size_t i) { expand_offsets_[i] = output_count(view, i); });
  }
  build_neighbours(hr);
}

template <int D>
SweepLimits SimulationT<D>::global(const SweepLimits& lim) const {
  if (!domain_) return lim;
  SweepLimits g;
  for (const SweepLimits& o : domain_->comm().all_gather_value(lim)) g = g.merged(o);
  return g;
}

template <int D>
void SimulationT<D>::distribute(const par::Comm& comm, bool replicated) {
  if (!comm.distributed()) return;
  remove_ghosts();
  // Decomposition cells as wide as the largest pair support of the set-up, 2 h_max: refinement only makes h smaller.
  const double reach = 2.0 * comm.max(smoothing_range(store_).max());
  domain_ = std::make_unique<DomainT<D>>(comm, settings_.geometry.container.lo, settings_.geometry.container.hi,
                                         reach > 0.0 ? reach : 1.0);
  domain_->partition(store_, integrator_, replicated);
  domain_->exchange(store_, replicated);
  // Each particle keeps its rates (the set-up's evaluation, or a checkpoint's: the rates the next step opens with),
  // and the limits are the whole set's already; only the grid is rebuilt, with the halos.
  prepare_neighbours();
}

template <int D>
std::optional<RebalanceRecord> SimulationT<D>::rebalance(double threshold) {
  if (!domain_) return std::nullopt;
  RebalanceRecord r;
  r.step = step_;
  r.before = domain_->imbalance(store_, integrator_);
  // Past the threshold, and worse than the last cut left it (cells are whole: a cut cannot always do better, and
  // recutting to the same loads every check would only cost).
  if (!(r.before > threshold) || (last_cut_ > 0.0 && r.before <= last_cut_ + 0.02)) return std::nullopt;
  const auto start = std::chrono::steady_clock::now();
  domain_->partition(store_, integrator_, false);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.after = domain_->imbalance(store_, integrator_);
  last_cut_ = r.after;
  // The particles move to their new owners at the next step's exchange, with their rates: the results do not
  // change, and the store between steps (ghosts, halos) stays the one the last step built, as in one process.
  return r;
}

template <int D>
void SimulationT<D>::build_neighbours(const SmoothingRange& hr) {
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
  expand_layer_.resize(m);
  // Each particle's grid layer is its level's (ghosts take their source's), as in build_level_grid(); the boxes
  // are reduced in the expansion loop, which writes the positions anyway.
  const int layers = hr.layers();
  using Box = typename CellGrid<D>::Box;
  using Boxes = LayerBoxes<D>;
  const Boxes boxes = par::accumulate(
      n, Boxes{},
      [&](Boxes& b, std::size_t i) {
        const std::uint32_t first = expand_offsets_[i], count = expand_offsets_[i + 1] - first;
        if (count == 0) return;
        const auto layer = static_cast<std::uint8_t>(grid_layer(view.level[i], layers));
        Box& box = b[layer];
        expand_src_[first] = static_cast<std::uint32_t>(i);
        expand_image_[first] = -1;
        expand_x_[first] = view.x[i];
        expand_layer_[first] = layer;
        box = box.merged(Box::of(view.x[i]));
        if (count == 1) return;
        const typename Ghosts::Images im = ghosts_->images(view.x[i], view.v[i], view.h[i]);
        for (std::uint32_t g = 1; g < count; ++g) {
          expand_src_[first + g] = static_cast<std::uint32_t>(i);
          expand_image_[first + g] = static_cast<std::int8_t>(g - 1);
          expand_x_[first + g] = im.x[g - 1];
          expand_layer_[first + g] = layer;
          box = box.merged(Box::of(im.x[g - 1]));
        }
      },
      [](const Boxes& a, const Boxes& b) { return merged<D>(a, b); });
  // The cell sort of the expanded set, composed with the expansion into one source map: one layer per level
  // present, each with cells sized by its finest support and queries reaching h_i + its largest h
  // (core/neighbour_cells.hpp).
  std::array<typename CellGrid<D>::LayerSpec, kGridLayers> spec;
  // Cells on a lattice fixed by the container (grid_anchor): a point's cell is a function of the point and the
  // scene, not of which particles the grid holds, so a grid over part of the particles (a rank's share and its
  // halo, issue #19) walks the cells they share in the same order.
  const Vec<D> anchor = grid_anchor(settings_.geometry.container);
  neighbour_layers<D>(hr, boxes, spec, &anchor);
  grid_.build_layers(spec.data(), layers, expand_x_.data(), layers > 1 ? expand_layer_.data() : nullptr, m);
  if (domain_) {  // the ghosts of this rank's own fluid (not of its halos), for the diagnostics' count
    std::size_t own = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (view.kind[i] == Kind::fluid) own += expand_offsets_[i + 1] - expand_offsets_[i] - 1;
    own_ghosts_ = own;
  }
  // Within a cell, by id, and a ghost after its source by image: the order, and so every pair sum, comes from
  // the particles alone, not from the store's order before the sort (core/cell_grid.hpp, order_cells_by).
  const std::uint32_t* src = expand_src_.data();
  const std::int8_t* images = expand_image_.data();
  grid_.order_cells_by([id = view.id, src, images](std::uint32_t a, std::uint32_t b) {
    const ParticleId ia = id[src[a]], ib = id[src[b]];
    return ia != ib ? ia < ib : images[a] < images[b];
  });
  const std::uint32_t* order = grid_.order().data();
  // One gather of every field, then the copies that are ghosts become ghosts. The two maps are composed once
  // here rather than in every field's loop: each of the ~30 fields would read src at a random place per item.
  gather_from_.resize(m);
  par::parallel_for(m, [&](std::size_t k) { gather_from_[k] = src[order[k]]; });
  store_.gather(m, [from = gather_from_.data()](std::size_t k) { return from[k]; });
  if (ghosts_) {
    auto s = store_.view();
    par::parallel_for(m, [&](std::size_t k) {
      const std::int8_t image = expand_image_[order[k]];
      if (image >= 0) ghosts_->make_ghost(s, k, image);
    });
  }
}

template <int D>
void SimulationT<D>::refresh() {
  auto s = store_.view();
  const TaitEquationOfState eos = settings_.eos;
  par::parallel_for(s.n, [&](std::size_t i) {
    if (s.kind[i] == Kind::fluid) s.p[i] = eos.pressure(s.rho[i]);
  });
  // Levels may have changed (a split or a merge): each particle's bin again, before the rates are evaluated. The
  // ghosts and halos carry their sources' next bins, so they take the same bins.
  prepare_neighbours();
  if (integrator_.bin_cap() > 0) {
    choose_bins_on_grid();
  } else {
    choose_bins();  // every next bin 0
  }
  const auto t = store_.view();
  par::parallel_for(t.n, [&](std::size_t i) {
    if (t.kind[i] != Kind::wall) t.bin[i] = t.next_bin[i];
  });
  if (buffered()) refine::interpolate_passive(store_.view(), grid_, settings_.eos);
  limits_ = global(sweep_->run(store_.view(), grid_, activity(1, 0)));
  dt_ = next_dt();
}

template <int D>
double SimulationT<D>::next_dt() const {
  const double dt = settings_.cfl * std::min(limits_.dt_force, limits_.dt_cfl);
  return std::min(dt, settings_.dt_max);
}

template <int D>
void SimulationT<D>::count_work(int finest, const SweepLimits& lim) {
  // Particles per level (the levels do not change within a step), then how many times each was due: bin b is
  // due every 2^(finest - b) of the 2^finest substeps, i.e. 2^b times a step.
  std::array<std::uint64_t, Work::kLevels> per_level{};
  const auto s = store_.view();
  for (std::size_t i = 0; i < s.n; ++i)
    if (s.kind[i] == Kind::fluid)
      per_level[static_cast<std::size_t>(std::min(s.level[i], Work::kLevels - 1))] += 1u << integrator_.bin(s.bin[i]);
  for (int l = 0; l < Work::kLevels; ++l) work_.evaluations[static_cast<std::size_t>(l)] += per_level[static_cast<std::size_t>(l)];
  work_.pairs += lim.pairs;
  work_.candidates += lim.candidates;
  work_.substeps += 1u << finest;
}

template <int D>
bool SimulationT<D>::choose_bins(bool neighbourhoods) {
  const auto s = store_.view();
  const Integrator& integ = integrator_;
  const double cfl = settings_.cfl;
  if (integ.bin_cap() == 0) {
    par::parallel_for(s.n, [&](std::size_t i) { s.next_bin[i] = 0; });
    return false;
  }
  // The levels' target step, then for each candidate share of it what a coarse step would cost: the evaluations
  // (sum of 2^bin over the fluid) and the substeps' own work (Integrator::kSubstepCost per fluid particle and
  // substep, 2^(finest bin) substeps). The cheapest per unit of time wins. Integer sums and an exact min: the
  // same at any thread and rank count. The costs take each particle's bin from its own limit: the neighbourhoods'
  // (below) move only a few particles a bin, and walking them for each of the nine candidates cost a fifth of a
  // run (docs/PERFORMANCE.md, "The neighbourhood limit made cheap").
  double target = par::reduce(
      s.n, std::numeric_limits<double>::infinity(), [&](std::size_t i) { return integ.level_target(s, i, cfl); },
      [](double a, double b) { return std::min(a, b); });
  if (domain_) target = -domain_->comm().max(-target);
  target = std::min(target, settings_.dt_max);
  constexpr std::size_t K = Integrator::kShrinks;
  std::array<double, K> candidate{};
  for (std::size_t k = 0; k < K; ++k) candidate[k] = target * Integrator::shrink(static_cast<int>(k));
  // Per candidate k: [k] the evaluations, [K + k] the finest bin; [2K] the fluid count.
  using Costs = std::array<std::uint64_t, 2 * K + 1>;
  // Folded in place (par::accumulate): a whole Costs built and combined per particle made this pass a few
  // per cent of a run.
  Costs cost = par::accumulate(
      s.n, Costs{},
      [&](Costs& c, std::size_t i) {
        if (s.kind[i] != Kind::fluid) return;
        std::array<int, K> bins;
        integ.bins_for_shares(s, i, candidate, cfl, bins);
        for (std::size_t k = 0; k < K; ++k) {
          const int b = bins[k];
          c[k] += std::uint64_t{1} << b;
          c[K + k] = std::max(c[K + k], static_cast<std::uint64_t>(b));
        }
        c[2 * K] += 1;
      },
      [](Costs a, const Costs& b) {
        for (std::size_t k = 0; k < K; ++k) {
          a[k] += b[k];
          a[K + k] = std::max(a[K + k], b[K + k]);
        }
        a[2 * K] += b[2 * K];
        return a;
      });
  if (domain_) {
    for (std::size_t k = 0; k < K; ++k) {
      cost[k] = domain_->comm().sum(cost[k]);
      cost[K + k] = static_cast<std::uint64_t>(domain_->comm().max(static_cast<double>(cost[K + k])));
    }
    cost[2 * K] = domain_->comm().sum(cost[2 * K]);
  }
  const auto per_time = [&](std::size_t k) {
    const double evaluations = static_cast<double>(cost[k]);
    const double substeps = static_cast<double>(std::uint64_t{1} << cost[K + k]);
    return (evaluations + Integrator::kSubstepCost * static_cast<double>(cost[2 * K]) * substeps) /
           Integrator::shrink(static_cast<int>(k));
  };
  std::size_t best = 0;
  for (std::size_t k = 1; k < K; ++k) {
    if (per_time(k) < per_time(best)) best = k;
  }
  const double dt0 = candidate[best];
  if (neighbourhoods) {
    integ.neighbourhood_bins(s, grid_, dt0, cfl, neighbourhood_work_, buffered());
  } else {
    par::parallel_for(s.n, [&](std::size_t i) {
      if (s.kind[i] == Kind::fluid) s.next_bin[i] = integ.bin_for(s, i, dt0, cfl);
    });
  }
  return next_bins_differ();
}

template <int D>
bool SimulationT<D>::choose_bins_on_grid() {
  // The bins from the limits over each neighbourhood (on the grid just built: the ghosts' and halos' limits are
  // their sources' latest), the copies' next bins, then the limiter.
  bool rebin = choose_bins(true);
  if (domain_) {
    prepare_neighbours();  // the halos' and ghosts' copies of the next bins
  } else {
    copy_next_bins_to_ghosts();
  }
  if (limit_bins()) rebin = next_bins_differ();
  return rebin;
}

template <int D>
bool SimulationT<D>::next_bins_differ() {
  const auto s = store_.view();
  bool differ = par::reduce(
      s.n, false, [&](std::size_t i) { return s.kind[i] == Kind::fluid && s.next_bin[i] != s.bin[i]; },
      [](bool a, bool b) { return a || b; });
  if (domain_) differ = domain_->comm().any(differ);
  return differ;
}

template <int D>
bool SimulationT<D>::limit_bins() {
  const Integrator& integ = integrator_;
  if (integ.bin_cap() == 0) return false;
  // No pair can be more than bin_jump apart unless the fluid's next bins span more (every rank's together).
  using Span = std::array<std::int32_t, 2>;  // the smallest and the largest next bin
  const auto s = store_.view();
  Span span = par::reduce(
      s.n, Span{kBinCount, -1},
      [&](std::size_t i) {
        return s.kind[i] == Kind::fluid ? Span{s.next_bin[i], s.next_bin[i]} : Span{kBinCount, -1};
      },
      [](const Span& a, const Span& b) { return Span{std::min(a[0], b[0]), std::max(a[1], b[1])}; });
  if (domain_) {
    span[0] = static_cast<std::int32_t>(-domain_->comm().max(-static_cast<double>(span[0])));
    span[1] = static_cast<std::int32_t>(domain_->comm().max(static_cast<double>(span[1])));
  }
  if (span[1] - span[0] <= integ.bin_jump()) return false;
  bool raised = false;
  for (;;) {
    bool changed = integ.limit_bins(store_.view(), grid_, bin_limiter_, buffered());
    if (domain_) changed = domain_->comm().any(changed);
    if (!changed) break;
    raised = true;
    // Across ranks, the halos' copies of the raised bins for the next pass (and the ghosts' for the sweep).
    if (domain_) prepare_neighbours();
  }
  if (raised && !domain_) copy_next_bins_to_ghosts();  // the sweep weighs ghost pairs by their next bins
  return raised;
}

template <int D>
void SimulationT<D>::copy_next_bins_to_ghosts() {
  if (!ghosts_) return;
  const auto s = store_.view();
  const std::uint32_t* order = grid_.order().data();
  const std::uint32_t* from = gather_from_.data();  // each slot's store index before the build
  const std::int8_t* image = expand_image_.data();
  ghost_source_.resize(expand_offsets_.size() - 1);  // one entry per particle of the store before the build
  par::parallel_for(s.n, [&](std::size_t k) {
    if (image[order[k]] < 0) ghost_source_[from[k]] = static_cast<std::uint32_t>(k);
  });
  par::parallel_for(s.n, [&](std::size_t k) {
    if (image[order[k]] >= 0) s.next_bin[k] = s.next_bin[ghost_source_[from[k]]];
  });
}

template <int D>
void SimulationT<D>::store_restored() {
  const auto s = store_.view();
  int finest = 0;
  for (std::size_t i = 0; i < s.n; ++i)
    if (s.kind[i] == Kind::fluid) finest = std::max(finest, integrator_.bin(s.bin[i]));
  limits_.finest_bin = domain_ ? static_cast<int>(domain_->comm().max(static_cast<double>(finest))) : finest;
}

template <int D>
Activity SimulationT<D>::activity(int k, int finest) {
  Activity act = integrator_.activity(k, finest);
  act.own_level_only = buffered();
  const auto s = store_.view();
  if (act.bin_cap > 0) {  // the finest bin in the store: fluid (active or passive), ghosts and halos, as they pair
    act.top_bin = par::reduce(
        s.n, 0, [&](std::size_t i) { return s.kind[i] == Kind::wall ? 0 : act.bin(s.bin[i]); },
        [](int a, int b) { return a > b ? a : b; });
  }
  if (act.active_bin == 0) return act;  // every particle is due
  due_prefix_.resize(s.n + 1);
  par::parallel_for(s.n, [&](std::size_t i) {
    due_prefix_[i] = s.kind[i] != Kind::wall && act.bin(s.bin[i]) >= act.active_bin ? 1u : 0u;
  });
  due_prefix_[s.n] = par::exclusive_scan(due_prefix_.data(), due_prefix_.data(), s.n);
  due_index_.resize(due_prefix_[s.n]);
  par::parallel_for(s.n, [&](std::size_t i) {
    if (due_prefix_[i + 1] != due_prefix_[i]) due_index_[due_prefix_[i]] = static_cast<std::uint32_t>(i);
  });
  act.due_prefix = due_prefix_.data();
  act.due_index = due_index_.data();
  return act;
}

template <int D>
StepInfo SimulationT<D>::step(double dt_cap) {
  const double dt = std::min(dt_, dt_cap);
  const bool watch = settings_.watchdog.enabled;
  const Integrator& integ = integrator_;
  // The finest bin of the step: the levels cannot change within it, and limits_ comes from an evaluation of
  // every particle (the end of the last step, or refresh()).
  const int finest = limits_.finest_bin;
  const int substeps = 1 << finest;
  const double tau = std::ldexp(dt, -finest);
  std::string step_error;
  if (watch) {
    last_good_.assign_from(store_);  // reuses capacity: no allocation once the sizes are stable
    last_good_limits_ = limits_;
    last_good_removed_ = removed_;
  }
  SweepLimits step_limits;
  for (int k = 1; k <= substeps && step_error.empty(); ++k) {
    // One parallel region for the opening kick (first substep) or the previous substep's kick, the drift and
    // prediction, and the first pass of the neighbour preparation (each particle's output count and the
    // smoothing-length range): all per particle.
    SmoothingRange hr;
    {
      auto s = store_.view();
      expand_offsets_.resize(s.n + 1);
      hr = par::accumulate(
          s.n, SmoothingRange{},
          [&](SmoothingRange& r, std::size_t i) {
            if (s.kind[i] == Kind::fluid && is_passive(s.role[i])) {
              integ.carry(s, i, tau);
            } else if (s.kind[i] == Kind::fluid) {
              if (k == 1) {
                integ.open(s, i, dt, finest);
              } else {
                integ.kick(s, i, dt, k - 1, finest);
              }
              integ.drift(s, i, tau, k, finest);
            }
            expand_offsets_[i] = output_count(s, i);
            r.add(s.kind[i], s.h[i], s.level[i]);
          },
          [](const SmoothingRange& a, const SmoothingRange& b) { return a.merged(b); });
    }
    if (buffered()) {
      refine::tie_buffers(store_);
      refine::keep_passive_inside_walls(store_, walls_);
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
    // Distributed, the ranks agree on whether the substep failed before the next collective call, so that no rank
    // waits for one that has left the step.
    // Before the last evaluation, on its grid: each particle's bin for the next step (choose_bins_on_grid, which
    // refreshes the ghosts' and halos' copies of it).
    const bool choose = k == substeps && integ.bin_cap() > 0;
    bool rebin = false;
    SweepLimits lim;
    try {
      if (renumbered || domain_) {
        prepare_neighbours();
      } else {
        build_neighbours(hr);
      }
      if (choose) rebin = choose_bins_on_grid();
      // Buffered levels: the passive particles take the active ones' state as predicted for this evaluation, which is
      // also the state they end the step with (output, the next drift).
      if (buffered()) refine::interpolate_passive(store_.view(), grid_, settings_.eos);
      Activity act = activity(k, finest);
      act.rebin = rebin;
      act.dt0 = dt;
      lim = sweep_->run(store_.view(), grid_, act);
    } catch (const std::exception& e) {
      if (!watch && !domain_) throw;
      step_error = e.what();
    }
    if (domain_ && domain_->comm().any(!step_error.empty()) && step_error.empty()) {
      step_error = "the step failed on another rank";
    }
    if (!step_error.empty()) {
      if (!watch) throw std::runtime_error(step_error);
      break;
    }
    lim = global(lim);
    step_limits = SweepLimits{std::min(step_limits.dt_force, lim.dt_force), std::min(step_limits.dt_cfl, lim.dt_cfl),
                              step_limits.pairs + lim.pairs,
                              lim.finest_bin,  // the last evaluation covers every bin
                              step_limits.candidates + lim.candidates};
  }
  if (step_error.empty()) {
    auto s = store_.view();
    par::parallel_for(s.n, [&](std::size_t i) {
      if (s.kind[i] != Kind::fluid) return;
      if (!is_passive(s.role[i])) integ.kick(s, i, dt, substeps, finest);
      s.bin[i] = s.next_bin[i];
    });
    limits_ = step_limits;
    count_work(finest, step_limits);
  }
  if (watch) {
    FailureReport report;
    const bool found = find_failure(store_, settings_.geometry, settings_.eos.rho0, settings_.watchdog, report);
    bool failed = found || !step_error.empty() || !(std::isfinite(dt) && dt > 0.0);
    if (domain_) {  // every rank rolls back when one fails, and reports the failure of the first rank that found one
      failed = domain_->comm().any(failed);
      if (failed) report = first_report(domain_->comm(), found ? &report : nullptr);
    }
    if (failed) {
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
  fine_steps_ += static_cast<std::uint64_t>(substeps);
  last_substeps_ = substeps;
  dt_ = next_dt();
  return {dt, limits_, substeps};
}

template <int D>
void SimulationT<D>::run_stages() {
  bool changed = false;
  for (auto& stage : stages_) changed = stage->after_step(*this) || changed;
  if (domain_) changed = domain_->comm().any(changed);  // a split on one rank changes the others' halos
  if (changed) refresh();
}

template <int D>
void SimulationT<D>::run_until(double t_end) {
  while (time_ < t_end * (1.0 - 1e-14)) {
    step(t_end - time_);
    run_stages();
  }
}

template <int D>
DiagnosticsT<D> SimulationT<D>::diagnostics() const {
  DiagnosticsT<D> d = compute_diagnostics<D>(store_, settings_.eos, settings_.gravity.value_or(Vec<D>::Zero()),
                                             domain_ ? &domain_->comm() : nullptr, own_ghosts_);
  d.time = time_;
  d.step = step_;
  d.dt = dt_;
  if (domain_) {  // each rank removed its own
    d.removed = domain_->comm().sum(removed_.particles);
    d.removed_mass = domain_->comm().sum(removed_.mass).value();
  } else {
    d.removed = removed_.particles;
    d.removed_mass = removed_.mass.value();
  }
  return d;
}

}  // namespace sph
