#pragma once
// The watchdog checks the state after every step: a NaN or Inf, a density error past a limit, a particle
// leaving the domain (through a wall, or over the rim of an open top). On failure the simulation is put back to the last good state (the step before) and a
// SimulationFailure names the step, time, particle, quantity and the likely cause.
#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "core/boundary/wall.hpp"
#include "core/particle_store.hpp"
#include "parallel/comm.hpp"

namespace sph {

struct WatchdogSettings {
  bool enabled = true;
  double max_density_error = 0.5;  // |rho/rho0 - 1| past this stops the run
};

/// left_domain: through a wall (or into an obstacle); left_open_top: over the rim of an open container (a splash,
/// not a wall failure; a scene can remove such fluid with container.outflow = "remove").
enum class FailureKind { not_finite, density, left_domain, left_open_top };

/// The kind's name in run.json ("not_finite", "density", "left_domain", "left_open_top").
const char* to_string(FailureKind kind);

struct FailureReport {
  FailureKind kind = FailureKind::not_finite;
  std::uint64_t step = 0;
  double time = 0.0;
  ParticleId id = 0;
  Eigen::VectorXd position;  // D entries
  std::string quantity;
  std::string cause;
  std::string message() const;
};

class SimulationFailure : public std::runtime_error {
 public:
  explicit SimulationFailure(FailureReport report) : std::runtime_error(report.message()), report_(std::move(report)) {}
  const FailureReport& report() const { return report_; }

 private:
  FailureReport report_;
};

/// Scans the fluid particles; returns the failure of the lowest-index offender (deterministic), if any.
template <int D>
bool find_failure(const ParticleStore<D>& store, const Geometry<D>& geometry, double rho0,
                  const WatchdogSettings& settings, FailureReport& out);

/// The report of the lowest rank that found a failure (`mine` when this rank found one, else nullptr), on every rank;
/// an empty report when none did. Collective.
FailureReport first_report(const par::Comm& comm, const FailureReport* mine);

}  // namespace sph
