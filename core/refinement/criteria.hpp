#pragma once
// Refinement criteria (section 3.1). A criterion only marks; the split pass never knows which one did.
// One virtual call per pass, never one per particle.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/particle_store.hpp"
#include "core/refinement/refinement_settings.hpp"

namespace sph::refine {

class Criterion {
 public:
  virtual ~Criterion() = default;
  virtual const char* name() const = 0;
  /// Sets marks[i] = 1 for the fluid particles this criterion wants refined (others untouched).
  virtual void mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const = 0;
};

/// The paper's criterion: |v_i| > v_threshold.
class VelocityCriterion final : public Criterion {
 public:
  explicit VelocityCriterion(double threshold) : threshold_(threshold) {}
  const char* name() const override { return "velocity"; }
  void mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const override;

 private:
  double threshold_;
};

/// A fixed zone: every particle inside the box.
class ZoneCriterion final : public Criterion {
 public:
  explicit ZoneCriterion(const Box2& zone) : zone_(zone) {}
  const char* name() const override { return "zone"; }
  void mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const override;

 private:
  Box2 zone_;
};

/// Too few fluid neighbours within 2 h_ij (thin sheets, splashes).
class FewNeighboursCriterion final : public Criterion {
 public:
  explicit FewNeighboursCriterion(int min_neighbours) : min_(min_neighbours) {}
  const char* name() const override { return "few_neighbours"; }
  void mark(const ParticleStore<2>& store, std::vector<std::uint8_t>& marks) const override;

 private:
  int min_;
};

std::unique_ptr<Criterion> make_criterion(const RefinementSettings& s);

}  // namespace sph::refine
