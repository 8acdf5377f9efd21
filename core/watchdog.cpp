#include "core/watchdog.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "parallel/parallel_for.hpp"

namespace sph {

const char* to_string(FailureKind kind) {
  switch (kind) {
    case FailureKind::not_finite: return "not_finite";
    case FailureKind::density: return "density";
    case FailureKind::left_domain: return "left_domain";
    case FailureKind::left_open_top: return "left_open_top";
  }
  return "?";
}

std::string FailureReport::message() const {
  std::string at = "(";
  char num[32];
  for (Eigen::Index k = 0; k < position.size(); ++k) {
    std::snprintf(num, sizeof num, "%s%.6g", k > 0 ? ", " : "", position[k]);
    at += num;
  }
  at += ")";
  char buf[512];
  std::snprintf(buf, sizeof buf, "run stopped at step %llu, t = %.6g s: particle %llu at %s: %s. Likely cause: %s",
                static_cast<unsigned long long>(step), time, static_cast<unsigned long long>(id), at.c_str(),
                quantity.c_str(), cause.c_str());
  return buf;
}

template <int D>
bool find_failure(const ParticleStore<D>& store, const Geometry<D>& geometry, double rho0,
                  const WatchdogSettings& settings, FailureReport& out) {
  constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
  struct Hit {
    std::size_t index;
    int kind;
  };
  auto classify = [&](std::size_t i) -> int {
    if (store.kind[i] != Kind::fluid) return -1;
    const Vec<D>& x = store.x[i];
    const Vec<D>& v = store.v[i];
    if (!x.allFinite() || !v.allFinite() || !std::isfinite(store.rho[i]) || !std::isfinite(store.p[i]))
      return 0;
    if (std::abs(store.rho[i] / rho0 - 1.0) > settings.max_density_error) return 1;
    if (!geometry.in_fluid_domain(x)) return geometry.left_through_open_top(x, store.vh[i]) ? 3 : 2;
    return -1;
  };
  const Hit hit = par::reduce(
      store.size(), Hit{none, -1},
      [&](std::size_t i) {
        const int k = classify(i);
        return k < 0 ? Hit{none, -1} : Hit{i, k};
      },
      [](const Hit& a, const Hit& b) { return a.index <= b.index ? a : b; });
  if (hit.index == none) return false;
  const std::size_t i = hit.index;
  out.id = store.id[i];
  out.position = store.x[i];
  char buf[160];
  switch (hit.kind) {
    case 0:
      out.kind = FailureKind::not_finite;
      out.quantity = "position, velocity, density or pressure is NaN or Inf";
      out.cause = "a time step too large for the sound speed (lower time.cfl or check material.c0), or two particles "
                  "at zero distance";
      break;
    case 1:
      out.kind = FailureKind::density;
      std::snprintf(buf, sizeof buf, "density error |rho/rho0 - 1| = %.3g exceeds the limit %.3g",
                    std::abs(store.rho[i] / rho0 - 1.0), settings.max_density_error);
      out.quantity = buf;
      // The sign says which way the fluid left the weakly-compressible range: a compression and an expansion
      // point at different causes.
      out.cause = store.rho[i] >= rho0
                      ? "compression beyond the weakly-compressible range: the sound speed is too low for the flow "
                        "(raise c0 or the Mach factor) or the time step too large"
                      : "expansion beyond the weakly-compressible range: the fluid is pulled apart (a diverging "
                        "initial velocity, or tension at a free surface or a jump in particle size) faster than "
                        "its pressure resists (raise c0 or the Mach factor, check the initial velocities)";
      break;
    case 2:
      out.kind = FailureKind::left_domain;
      out.quantity = "the particle left the domain through a wall (the container's floor, a side below the rim or a "
                     "closed top, or into an obstacle)";
      out.cause = "wall penetration: walls too weak for the impact speed (enable the Lennard-Jones wall or ghost "
                  "walls, raise its strength) or a time step too large";
      break;
    default:
      out.kind = FailureKind::left_open_top;
      std::snprintf(buf, sizeof buf, "the particle left the domain through the open top (over the rim at %s = %.6g m, "
                    "beside the container)", D == 2 ? "y" : "z", geometry.container.hi[D - 1]);
      out.quantity = buf;
      out.cause = "a splash over the rim: raise the walls (container.hi) or let the scene remove such fluid "
                  "(container.outflow: \"remove\")";
      break;
  }
  return true;
}

template bool find_failure<2>(const ParticleStore<2>&, const Geometry<2>&, double, const WatchdogSettings&,
                              FailureReport&);
template bool find_failure<3>(const ParticleStore<3>&, const Geometry<3>&, double, const WatchdogSettings&,
                              FailureReport&);

FailureReport first_report(const par::Comm& comm, const FailureReport* mine) {
  std::vector<std::byte> b;
  par::put<std::uint8_t>(b, mine != nullptr ? 1 : 0);
  if (mine != nullptr) {
    par::put(b, static_cast<int>(mine->kind));
    par::put(b, mine->step);
    par::put(b, mine->time);
    par::put(b, mine->id);
    par::put<std::uint64_t>(b, static_cast<std::uint64_t>(mine->position.size()));
    for (Eigen::Index a = 0; a < mine->position.size(); ++a) par::put(b, mine->position[a]);
    par::put_string(b, mine->quantity);
    par::put_string(b, mine->cause);
  }
  std::vector<std::size_t> from;
  const std::vector<std::byte> all = comm.all_gather(b, &from);
  std::size_t at = 0;
  for (const std::size_t bytes : from) {
    const std::size_t next = at + bytes;
    if (par::take<std::uint8_t>(all, at) != 0) {
      FailureReport r;
      r.kind = static_cast<FailureKind>(par::take<int>(all, at));
      r.step = par::take<std::uint64_t>(all, at);
      r.time = par::take<double>(all, at);
      r.id = par::take<ParticleId>(all, at);
      r.position.resize(static_cast<Eigen::Index>(par::take<std::uint64_t>(all, at)));
      for (Eigen::Index a = 0; a < r.position.size(); ++a) r.position[a] = par::take<double>(all, at);
      r.quantity = par::take_string(all, at);
      r.cause = par::take_string(all, at);
      return r;
    }
    at = next;
  }
  return {};
}

}  // namespace sph
