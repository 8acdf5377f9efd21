#pragma once
// Refinement criteria (section 3.1). A criterion only marks; the split pass never knows which one did.
// One virtual call per pass, never one per particle.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/particle_store.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

template <int D>
class CriterionIn {
 public:
  virtual ~CriterionIn() = default;
  virtual const char* name() const = 0;
  /// Sets marks[i] = 1 for the fluid particles this criterion wants refined (others untouched).
  virtual void mark(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks) const = 0;
  /// Sets marks[i] = 1 for the fluid particles that pass the merge test (coarsening; others untouched). The
  /// merge test is stricter than the negation of the split test (hysteresis), and it looks `horizon` seconds
  /// ahead (the time to the next check) at the particle's present rate of change: a family merged now would
  /// not be split again at the next check unless the flow changes course.
  virtual void mark_mergeable(const ParticleStore<D>& store, double horizon, std::vector<std::uint8_t>& marks) const = 0;
  /// For a merged particle at x with velocity v: true when mark() would mark it at once (a merge the
  /// criterion would undo at the next check is not made). Criteria that need neighbours answer false.
  virtual bool would_split(const Vec<D>& x, const Vec<D>& v) const = 0;
};

/// The paper's criterion: |v_i| > v_threshold.
template <int D>
class VelocityCriterionIn final : public CriterionIn<D> {
 public:
  /// Merges below merge_threshold (< threshold).
  explicit VelocityCriterionIn(double threshold, double merge_threshold = 0.0)
      : threshold_(threshold), merge_threshold_(merge_threshold) {}
  const char* name() const override { return "velocity"; }
  void mark(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks) const override;
  void mark_mergeable(const ParticleStore<D>& store, double horizon, std::vector<std::uint8_t>& marks) const override;
  bool would_split(const Vec<D>&, const Vec<D>& v) const override { return v.squaredNorm() > threshold_ * threshold_; }

 private:
  double threshold_;
  double merge_threshold_;
};

/// A fixed zone: every particle inside the box.
template <int D>
class ZoneCriterionIn final : public CriterionIn<D> {
 public:
  explicit ZoneCriterionIn(const Box<D>& zone) : zone_(zone) {}
  const char* name() const override { return "zone"; }
  void mark(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks) const override;
  void mark_mergeable(const ParticleStore<D>& store, double horizon, std::vector<std::uint8_t>& marks) const override;
  bool would_split(const Vec<D>& x, const Vec<D>&) const override { return zone_.contains(x); }

 private:
  Box<D> zone_;
};

/// Too few fluid neighbours within 2 h_ij (thin sheets, splashes).
template <int D>
class FewNeighboursCriterionIn final : public CriterionIn<D> {
 public:
  /// Merges with at least merge_min_neighbours (> min_neighbours).
  explicit FewNeighboursCriterionIn(int min_neighbours, int merge_min_neighbours = 0)
      : min_(min_neighbours), merge_min_(merge_min_neighbours) {}
  const char* name() const override { return "few_neighbours"; }
  void mark(const ParticleStore<D>& store, std::vector<std::uint8_t>& marks) const override;
  void mark_mergeable(const ParticleStore<D>& store, double horizon, std::vector<std::uint8_t>& marks) const override;
  bool would_split(const Vec<D>&, const Vec<D>&) const override { return false; }

 private:
  int min_;
  int merge_min_;
};

/// The criterion the settings name. A zone of another dimension than D throws std::invalid_argument.
template <int D = 2>
std::unique_ptr<CriterionIn<D>> make_criterion(const RefinementSettings& s);

using Criterion = CriterionIn<2>;
using VelocityCriterion = VelocityCriterionIn<2>;
using ZoneCriterion = ZoneCriterionIn<2>;
using FewNeighboursCriterion = FewNeighboursCriterionIn<2>;

}  // namespace sph::refine
