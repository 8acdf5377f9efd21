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

// The one list of the store's fields, in registry order: X(type, member, name, unit). The members, the registry
// (field_members(), behind for_each_field), the hot loops' view (ParticleView, view()) and bytes_per_particle() are
// all made from it, so a field added here is carried by every operation: resize, gather (permutation, compaction,
// expansion), append, copies, exchange across ranks, output and checkpoints. `VecD` is Vec<D>.
//
// What the fields hold:
// - x, v, rho, p, m, h, d, level, kind, id: the particle itself. m is per metre of depth in 2D (rho0 d^2), as
//   energies are J/m.
// - drho, a: the rates of its last evaluation.
// - vh, rhoh: the integrator's stage state (kick-drift-kick), the velocity and density at the half step.
// - level_time: when the particle took its level (its split, or the merge that made it); 0 for the set-up's
//   particles. Coarsening holds a family at its level for a minimum time (core/refinement/merge_pass.hpp).
// - origin (core/types.hpp): a fresh merge is not split at the next check.
// - kick, kick_rho: the pair sweep's weighted sums (core/sweep.hpp); the integrator kicks v and rho by dt0 times
//   them. Equal to a and drho with one global step; with time bins they hold only the pairs due at the current
//   substep.
// - bin, next_bin, stiffness, dt_limit: time bins (core/integrator.hpp). The particle steps dt0 / 2^bin this step;
//   next_bin is the bin of the next step, chosen before the step's last evaluation (Simulation::choose_bins) from
//   the particle's own time-step limit dt_limit (min of its force and acoustic limits, unscaled) and its acoustic
//   stiffness h_i / L_i >= 1 (core/kernel.hpp, LatticeGradientSum::acoustic_length), both from its last evaluation.
//   Bins are 0 with one global step.
// - jerk, density_jerk: the change of a and drho between the particle's last two evaluations over the time between
//   them (core/sweep.hpp); the extrapolated predictor (Integrator::drift) integrates a + t jerk. Zero before a
//   particle's second evaluation in a run and after a merge; a daughter keeps its parent's.
// - role (core/types.hpp).
// - tie: a daughter's place relative to its parent when its split put it there (zero for the set-up's particles
//   and a merge's). A buffer particle (buffered coupling) keeps that place: it moves with its host
//   (core/refinement/buffer.hpp).
// - full_a, full_drho, v_open, rho_open: time bins. The rates of every pair at full weight, whatever its bin (a and
//   drho weigh a pair of a finer bin than the particle's by 2^(b_i - b_ij), as its opening kick needs; equal to
//   them where every pair is in the particle's own bin), and the velocity and density at the start of the
//   particle's current step. Between its own evaluations the integrator predicts v and rho from them
//   (Integrator::drift).
#define SPH_PARTICLE_FIELDS(X)                                        \
  X(VecD, x, "position", "m")                                         \
  X(VecD, v, "velocity", "m/s")                                       \
  X(double, rho, "density", "kg/m^3")                                 \
  X(double, p, "pressure", "Pa")                                      \
  X(double, m, "mass", D == 2 ? "kg/m" : "kg")                        \
  X(double, h, "smoothing_length", "m")                               \
  X(double, d, "spacing", "m")                                        \
  X(std::int32_t, level, "level", "1")                                \
  X(Kind, kind, "kind", "1")                                          \
  X(ParticleId, id, "id", "1")                                        \
  X(double, drho, "density_rate", "kg/m^3/s")                         \
  X(VecD, a, "acceleration", "m/s^2")                                 \
  X(VecD, vh, "velocity_half", "m/s")                                 \
  X(double, rhoh, "density_half", "kg/m^3")                           \
  X(double, level_time, "level_time", "s")                            \
  X(Origin, origin, "origin", "1")                                    \
  X(VecD, kick, "kick_rate", "m/s^2")                                 \
  X(double, kick_rho, "kick_density_rate", "kg/m^3/s")                \
  X(std::int32_t, bin, "time_bin", "1")                               \
  X(std::int32_t, next_bin, "next_time_bin", "1")                     \
  X(double, stiffness, "acoustic_stiffness", "1")                     \
  X(double, dt_limit, "time_step_limit", "s")                         \
  X(VecD, jerk, "jerk", "m/s^3")                                      \
  X(double, density_jerk, "density_jerk", "kg/m^3/s^2")              \
  X(Role, role, "role", "1")                                          \
  X(VecD, tie, "tie_offset", "m")                                     \
  X(VecD, full_a, "acceleration_all_pairs", "m/s^2")                  \
  X(double, full_drho, "density_rate_all_pairs", "kg/m^3/s")          \
  X(VecD, v_open, "velocity_at_step_start", "m/s")                    \
  X(double, rho_open, "density_at_step_start", "kg/m^3")

/// Raw pointers into the store for hot loops, one per field. Valid until the store is resized or gathered.
template <int D>
struct ParticleView {
  using VecD = Vec<D>;
  std::size_t n = 0;
#define SPH_VIEW_POINTER(T, member, name, unit) T* member = nullptr;
  SPH_PARTICLE_FIELDS(SPH_VIEW_POINTER)
#undef SPH_VIEW_POINTER
};

template <int D>
class ParticleStore {
 public:
  static constexpr int dim = D;
  using VecD = Vec<D>;

  // The fields (SPH_PARTICLE_FIELDS above), each with its name and unit.
#define SPH_FIELD_MEMBER(T, member, name, unit) Field<T> member{name, unit};
  SPH_PARTICLE_FIELDS(SPH_FIELD_MEMBER)
#undef SPH_FIELD_MEMBER

  /// The registry: every field as a pointer to member, in SPH_PARTICLE_FIELDS' order.
  static constexpr auto field_members() {
#define SPH_FIELD_POINTER(T, member, name, unit) , std::make_tuple(&ParticleStore::member)
    return std::tuple_cat(std::tuple<>() SPH_PARTICLE_FIELDS(SPH_FIELD_POINTER));
#undef SPH_FIELD_POINTER
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
    ParticleView<D> out;
    out.n = size();
#define SPH_VIEW_DATA(T, member, name, unit) out.member = member.data();
    SPH_PARTICLE_FIELDS(SPH_VIEW_DATA)
#undef SPH_VIEW_DATA
    return out;
  }

  /// Bytes held by every field (data and scratch), for memory reports.
  std::size_t bytes() const {
    std::size_t b = 0;
    for_each_field([&](const auto& f) { b += f.bytes(); });
    return b;
  }

  /// Bytes one particle occupies across all fields.
  static constexpr std::size_t bytes_per_particle() {
#define SPH_FIELD_BYTES(T, member, name, unit) +sizeof(T)
    return 0 SPH_PARTICLE_FIELDS(SPH_FIELD_BYTES);
#undef SPH_FIELD_BYTES
  }

 private:
  ParticleId next_id_ = 0;
};

#undef SPH_PARTICLE_FIELDS

}  // namespace sph
