#pragma once
// The particle store: structure of arrays, the one owner of every per-particle array.
// `for_each_field` is the field registry: resize, gather (permutation, compaction, expansion), append,
// output and checkpoints all go through it, so no field can be forgotten when particles move in memory.
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

#include "core/field.hpp"
#include "core/types.hpp"
#include "parallel/compaction.hpp"
#include "parallel/parallel_for.hpp"

namespace sph {

/// Raw pointers into the store for hot loops. Valid until the store is resized or gathered.
template <int D>
struct ParticleView {
  std::size_t n = 0;
  Vec<D>* x = nullptr;
  Vec<D>* v = nullptr;
  double* rho = nullptr;
  double* p = nullptr;
  double* m = nullptr;
  double* h = nullptr;
  double* d = nullptr;
  std::int32_t* level = nullptr;
  Kind* kind = nullptr;
  ParticleId* id = nullptr;
  double* drho = nullptr;
  Vec<D>* a = nullptr;
  Vec<D>* vh = nullptr;
  double* rhoh = nullptr;
  double* level_time = nullptr;
  Origin* origin = nullptr;
  Vec<D>* kick = nullptr;
  double* kick_rho = nullptr;
  std::int32_t* bin = nullptr;
  std::int32_t* next_bin = nullptr;
  double* stiffness = nullptr;
  double* dt_limit = nullptr;
  Vec<D>* jerk = nullptr;
  double* density_jerk = nullptr;
  Role* role = nullptr;
  Vec<D>* tie = nullptr;
  Vec<D>* full_a = nullptr;
  double* full_drho = nullptr;
  Vec<D>* v_open = nullptr;
  double* rho_open = nullptr;
};

template <int D>
class ParticleStore {
 public:
  static constexpr int dim = D;
  using VecD = Vec<D>;

  // The fields, each with its name and unit. Adding one here (and to for_each_field) is all it takes for every
  // operation to carry it.
  Field<VecD> x{"position", "m"};
  Field<VecD> v{"velocity", "m/s"};
  Field<double> rho{"density", "kg/m^3"};
  Field<double> p{"pressure", "Pa"};
  Field<double> m{"mass", D == 2 ? "kg/m" : "kg"};  // 2D: per metre of depth (rho0 d^2), as energies are J/m
  Field<double> h{"smoothing_length", "m"};
  Field<double> d{"spacing", "m"};
  Field<std::int32_t> level{"level", "1"};
  Field<Kind> kind{"kind", "1"};
  Field<ParticleId> id{"id", "1"};
  Field<double> drho{"density_rate", "kg/m^3/s"};
  Field<VecD> a{"acceleration", "m/s^2"};
  // Integrator stage state (kick-drift-kick): velocity and density at the half step.
  Field<VecD> vh{"velocity_half", "m/s"};
  Field<double> rhoh{"density_half", "kg/m^3"};
  // When the particle took its level (its split, or the merge that made it); 0 for the set-up's particles.
  // Coarsening holds a family at its level for a minimum time (core/refinement/merge_pass.hpp).
  Field<double> level_time{"level_time", "s"};
  Field<Origin> origin{"origin", "1"};  // core/types.hpp: a fresh merge is not split at the next check
  // The pair sweep's weighted sums (core/sweep.hpp): the integrator kicks v and rho by dt0 times them. Equal to
  // a and drho with one global step; with time bins they hold only the pairs due at the current substep.
  Field<VecD> kick{"kick_rate", "m/s^2"};
  Field<double> kick_rho{"kick_density_rate", "kg/m^3/s"};
  // Time bins (core/integrator.hpp): the particle steps dt0 / 2^bin this step; next_bin is the bin of the next
  // step, chosen before the step's last evaluation (Simulation::choose_bins) from the particle's own time-step
  // limit dt_limit (min of its force and acoustic limits, unscaled) and its acoustic stiffness h_i / L_i >= 1
  // (core/kernel.hpp, LatticeGradientSum::acoustic_length), both from its last evaluation. Bins are 0 with one
  // global step.
  Field<std::int32_t> bin{"time_bin", "1"};
  Field<std::int32_t> next_bin{"next_time_bin", "1"};
  Field<double> stiffness{"acoustic_stiffness", "1"};
  Field<double> dt_limit{"time_step_limit", "s"};
  // The change of a and drho between the particle's last two evaluations over the time between them (core/sweep.hpp);
  // the extrapolated predictor (Integrator::drift) integrates a + t jerk. Zero before a particle's second evaluation
  // in a run and after a merge; a daughter keeps its parent's.
  Field<VecD> jerk{"jerk", "m/s^3"};
  Field<double> density_jerk{"density_jerk", "kg/m^3/s^2"};
  Field<Role> role{"role", "1"};  // core/types.hpp
  // A daughter's place relative to its parent when its split put it there (zero for the set-up's particles and a
  // merge's). A buffer particle (buffered coupling) keeps that place: it moves with its host (core/refinement/buffer.hpp).
  Field<VecD> tie{"tie_offset", "m"};
  // Time bins: the rates of every pair at full weight, whatever its bin (a and drho weigh a pair of a finer bin than
  // the particle's by 2^(b_i - b_ij), as its opening kick needs; equal to them where every pair is in the particle's
  // own bin), and the velocity and density at the start of the particle's current step. Between its own evaluations
  // the integrator predicts v and rho from them (Integrator::drift).
  Field<VecD> full_a{"acceleration_all_pairs", "m/s^2"};
  Field<double> full_drho{"density_rate_all_pairs", "kg/m^3/s"};
  Field<VecD> v_open{"velocity_at_step_start", "m/s"};
  Field<double> rho_open{"density_at_step_start", "kg/m^3"};

  /// The registry: every field as a pointer to member. Adding a field above and here is all it takes for
  /// every operation (gather, compaction, expansion, copies, output, checkpoints) to carry it.
  static constexpr auto field_members() {
    return std::make_tuple(&ParticleStore::x, &ParticleStore::v, &ParticleStore::rho, &ParticleStore::p,
                           &ParticleStore::m, &ParticleStore::h, &ParticleStore::d, &ParticleStore::level,
                           &ParticleStore::kind, &ParticleStore::id, &ParticleStore::drho, &ParticleStore::a,
                           &ParticleStore::vh, &ParticleStore::rhoh, &ParticleStore::level_time,
                           &ParticleStore::origin, &ParticleStore::kick, &ParticleStore::kick_rho,
                           &ParticleStore::bin, &ParticleStore::next_bin, &ParticleStore::stiffness,
                           &ParticleStore::dt_limit, &ParticleStore::jerk, &ParticleStore::density_jerk,
                           &ParticleStore::role, &ParticleStore::tie, &ParticleStore::full_a,
                           &ParticleStore::full_drho, &ParticleStore::v_open, &ParticleStore::rho_open);
  }

  /// Visits every field. f is called with each Field<T>&.
  template <class F>
  void for_each_field(F&& f) {
    std::apply([&](auto... member) { (f(this->*member), ...); }, field_members());
  }
  /// Visits every field of this store with the same field of `other`: f(Field<T>& mine, const Field<T>& theirs).
  template <class F>
  void for_each_field_with(const ParticleStore& other, F&& f) {
    std::apply([&](auto... member) { (f(this->*member, other.*member), ...); }, field_members());
  }
  template <class F>
  void for_each_field(F&& f) const {
    const_cast<ParticleStore*>(this)->for_each_field([&](const auto& field) { f(field); });
  }

  std::size_t size() const { return x.size(); }
  bool empty() const { return size() == 0; }

  /// The next id that append() hands out; part of the state (checkpoints keep it).
  ParticleId next_id() const { return next_id_; }
  void set_next_id(ParticleId next) { next_id_ = next; }
  /// Hands out `count` consecutive fresh ids and returns the first.
  ParticleId take_ids(std::size_t count) {
    const ParticleId first = next_id_;
    next_id_ += count;
    return first;
  }

  void resize(std::size_t n) {
    for_each_field([n](auto& f) { f.resize(n); });
  }
  void reserve(std::size_t n) {
    for_each_field([n](auto& f) { f.reserve(n); });
  }
  void clear() { resize(0); }

  /// Appends `count` particles with zeroed fields and fresh ids; returns the index of the first.
  std::size_t append(std::size_t count) {
    const std::size_t first = size();
    resize(first + count);
    const ParticleId id0 = take_ids(count);
    for (std::size_t k = 0; k < count; ++k) id[first + k] = id0 + k;
    return first;
  }

  /// Every field := old field gathered through src (new[k] = old[src(k)] for k < new_size). The one
  /// primitive behind permutation (src a permutation), compaction (src increasing) and expansion (src
  /// repeats indices); src may compose maps (it is evaluated once per field and item, and must be pure).
  /// All fields in one parallel region (a worksharing loop per field, no barrier between them), not one
  /// region per field: a step gathers every field once, and each region costs a fork and a join.
  template <class Src>
  void gather(std::size_t new_size, Src&& src) {
    for_each_field([&](auto& f) { f.prepare_gather(new_size); });
    const auto count = static_cast<std::ptrdiff_t>(new_size);
    const auto fields = [&] {
      for_each_field([&](auto& f) {
        auto* out = f.gather_scratch();
        const auto* in = f.data();
#pragma omp for schedule(static) nowait
        for (std::ptrdiff_t k = 0; k < count; ++k) out[k] = in[src(static_cast<std::size_t>(k))];
      });
    };
    if (par::serial(new_size)) {  // one thread: no region (the orphaned loops run on this thread)
      fields();
    } else {
#pragma omp parallel
      fields();
    }
    for_each_field([&](auto& f) { f.gather_commit(); });
  }
  void gather(const std::vector<std::uint32_t>& src) {
    const std::uint32_t* from = src.data();
    gather(src.size(), [from](std::size_t k) { return from[k]; });
  }

  /// Sizes this store as `other` (and takes its next id) for a copy; no allocation once sizes settle.
  void prepare_copy_of(const ParticleStore& other) {
    const std::size_t n = other.size();
    for_each_field([n](auto& f) { f.values().resize(n); });
    next_id_ = other.next_id_;
  }
  /// This store := a copy of `other`'s particles (values and next id; the scratch buffers are not copied).
  /// Reuses this store's capacity: no allocation once sizes settle. Field by field, each a contiguous copy (one
  /// stream read and one written at a time), all fields in one parallel region as gather() has them.
  void assign_from(const ParticleStore& other) {
    prepare_copy_of(other);
    const auto count = static_cast<std::ptrdiff_t>(other.size());
    const auto fields = [&] {
      for_each_field_with(other, [&](auto& mine, const auto& theirs) {
        auto* out = mine.data();
        const auto* in = theirs.data();
#pragma omp for schedule(static) nowait
        for (std::ptrdiff_t k = 0; k < count; ++k) out[k] = in[k];
      });
    };
    if (par::serial(other.size())) {
      fields();
    } else {
#pragma omp parallel
      fields();
    }
  }

  /// Keeps the particles with keep(i), in order.
  template <class Keep>
  void compact(Keep&& keep) {
    gather(par::compaction_map(size(), std::forward<Keep>(keep)));
  }

  ParticleView<D> view() {
    return {size(), x.data(), v.data(), rho.data(), p.data(), m.data(), h.data(), d.data(),
            level.data(), kind.data(), id.data(), drho.data(), a.data(), vh.data(), rhoh.data(), level_time.data(),
            origin.data(), kick.data(), kick_rho.data(), bin.data(), next_bin.data(), stiffness.data(), dt_limit.data(),
            jerk.data(), density_jerk.data(), role.data(), tie.data(), full_a.data(), full_drho.data(), v_open.data(),
            rho_open.data()};
  }

  /// Bytes held by every field (data and scratch), for memory reports.
  std::size_t bytes() const {
    std::size_t b = 0;
    for_each_field([&](const auto& f) { b += f.bytes(); });
    return b;
  }

  /// Bytes one particle occupies across all fields.
  static constexpr std::size_t bytes_per_particle() {
    return 9 * sizeof(VecD) + 14 * sizeof(double) + 3 * sizeof(std::int32_t) + sizeof(Kind) + sizeof(ParticleId) +
           sizeof(Origin) + sizeof(Role);
  }

 private:
  ParticleId next_id_ = 0;
};

}  // namespace sph
