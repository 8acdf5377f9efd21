#pragma once
// Basic types shared by the whole library.
#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>

// Forces a function (or a lambda: after its parameter list) to be inlined into its caller. The neighbour scans
// (CellGrid::scan and its callers) and the pair loops they call back must end up in one function: when GCC 12 kept
// the per-run callback out of line, every captured accumulator and the pair's scratch lived in memory behind the
// closure, and the 2D pair sweep took 2.6 times as long (docs/PERFORMANCE.md, "A scan that stopped inlining").
#if defined(__GNUC__)
#define SPH_ALWAYS_INLINE __attribute__((always_inline))
#else
#define SPH_ALWAYS_INLINE
#endif

namespace sph {

/// A point or vector in D dimensions (D = 2 or 3).
template <int D>
using Vec = Eigen::Matrix<double, D, 1>;

/// A point or vector whose dimension is known only when a scene is read: 2 or 3 coordinates, or none (a vector
/// left at its default, zero). What a scene holds before the solver is chosen for the scene's dimension;
/// `fixed<D>()` gives the solver's Vec<D>. Compared by size and value.
struct AnyVec : Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 3, 1> {
  using Base = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 3, 1>;
  AnyVec() = default;
  explicit AnyVec(Eigen::Index n) : Base(n) {}  // n coordinates, unset
  template <class Other>
  AnyVec(const Eigen::MatrixBase<Other>& other) : Base(other) {}  // NOLINT: a Vec<D> is an AnyVec
  template <class Other>
  AnyVec& operator=(const Eigen::MatrixBase<Other>& other) {
    Base::operator=(other);
    return *this;
  }
  bool operator==(const AnyVec& o) const {
    return size() == o.size() && (size() == 0 || static_cast<const Base&>(*this) == static_cast<const Base&>(o));
  }
  /// The vector in D dimensions; empty is zero. Throws std::invalid_argument for another dimension.
  template <int D>
  Vec<D> fixed() const {
    if (size() == 0) return Vec<D>::Zero();
    if (size() != D) {
      throw std::invalid_argument("a vector of " + std::to_string(size()) + " coordinates where " + std::to_string(D) +
                                  " are needed");
    }
    return Vec<D>(data());
  }
};

/// What a particle is: a real fluid particle, a fixed wall particle (Lennard-Jones repulsion, eq. 10),
/// or a ghost mirrored from a fluid particle across a wall (section 2.4).
/// fluid; wall (a wall particle); ghost (a mirror image of a fluid particle or halo across a wall); halo (a copy of
/// another rank's fluid particle, core/domain.hpp: a neighbour like fluid, but this rank neither moves it nor
/// computes its rates, and it is never output).
enum class Kind : std::uint8_t { fluid = 0, wall = 1, ghost = 2, halo = 3 };

/// How a particle took its level: at set-up, as a daughter of a split, or as the particle a merge made
/// (`fresh_merge` until the refinement check after that merge, which does not split it, then `merge`; `fresh_split`
/// until the check after the split that made it, or that made it active, at which its family does not merge, then
/// `split`). No family flips between split and merge from one check to the next, whatever the cause of the split.
enum class Origin : std::uint8_t { setup = 0, split = 1, fresh_merge = 2, merge = 3, fresh_split = 4 };

/// effects.refinement.coupling: how particles of different levels interact. `mixed` (the paper's): every pair within
/// reach, whatever the levels, with h_ij = (h_i + h_j) / 2. `buffered`: a particle's SPH sums take only particles of
/// its own level; each level's lattice is completed where another level is active by passive particles that take
/// their velocity and density from that level (core/refinement/buffer.hpp; docs/METHOD.md, "Buffered levels").
enum class LevelCoupling { mixed, buffered };

/// A particle's part in its level with buffered coupling (always `active` with mixed coupling). Active particles
/// carry the SPH equations; passive ones complete their level's lattice and copy another level's state.
///   active: a particle without daughters;
///   shadow: a passive parent whose daughters are active (it stays where they are, inside a refined zone);
///   host:   an active parent whose daughters are buffer particles (at the edge of a refined zone);
///   buffer: a passive daughter.
enum class Role : std::uint8_t { active = 0, shadow = 1, host = 2, buffer = 3 };
inline constexpr bool is_passive(Role r) { return r == Role::shadow || r == Role::buffer; }

/// time.stepping (core/integrator.hpp): one global step (the paper's), or power-of-two steps per refinement level.
enum class TimeStepping { global, per_level };
/// time.predictor (core/integrator.hpp, Integrator::drift): how v and rho are predicted for an evaluation inside or
/// at the end of a particle's step. `extrapolated` integrates the rates extrapolated linearly from the particle's
/// last two evaluations (a + t jerk); `last_rate` holds the last evaluation's rates (the scheme until 2026-12-02,
/// the same to first order as DualSPHysics' symplectic one). The last-rate prediction grows the fastest acoustic
/// modes by z^4/4 a step (z = omega dt), which the stiffness-aware acoustic limit contains; the extrapolated one
/// damps them up to z = 0.67 (docs/METHOD.md, "The predictor").
enum class TimePredictor { extrapolated, last_rate };
/// time.bin_jump's default: the most a particle's time bin may differ from a neighbour's (Integrator::limit_bins).
/// One, measured on the hardest per-level case (docs/METHOD.md, "Time steps per level"): the three-level dam break
/// per level stops on a density error of 0.5 at the right wall at t = 3.74 s without the limiter and at 4.04 s
/// with bin_jump 2, and completes its 4.5 s with bin_jump 1 (max density error 0.169), for 0.5 % more evaluations
/// in the paper's dam break per level.
inline constexpr int kDefaultBinJump = 1;
/// Time bins 0 .. kBinCount - 1 (Integrator::kMaxBin is the last).
inline constexpr int kBinCount = 16;

using Index = std::uint32_t;
using ParticleId = std::uint64_t;

}  // namespace sph
