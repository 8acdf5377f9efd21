#pragma once
// The pair sweep's brute-force twin for the tests (tests/test_sweep.cpp and test_sweep_bins.cpp in 2D, test_sweep_3d.cpp
// in 3D):
// eqs. (5), (6), (9) and (10) over all pairs, written from PHYSICS.md, with the optional effects and time bins,
// and the comparison of a sweep's rates and limits against it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/integrator.hpp"
#include "core/kernel.hpp"
#include "core/sweep_factory.hpp"
#include "tests/support/brute_force.hpp"
#include "tests/support/physics_helpers.hpp"

namespace sph::test {


template <int D>
struct ReferenceT {
  std::vector<double> drho, drho_scale, kick_rho;
  std::vector<Vec<D>> a, kick;
  std::vector<double> full_drho, full_a_scale, full_drho_scale;  // every pair at weight 1 (full_a and full_drho)
  std::vector<Vec<D>> full_a;
  std::vector<std::uint8_t> due;
  std::vector<double> a_scale;
  double dt_force = std::numeric_limits<double>::infinity();
  double dt_cfl = std::numeric_limits<double>::infinity();
  std::size_t pairs = 0;
};
using Reference = ReferenceT<2>;

// With time bins (sph::Activity, core/sweep.hpp): a particle's bin is min(bin, cap) (the store's time bin); a
// pair is evaluated when the larger of its two bins is at least the active bin, its terms weighted by
// 2^-(that bin); gravity and the wall terms belong to a due particle's own bin. `kick` holds the weighted
// sums; for a due particle, a = 2^b kick and its limits are scaled by 2^b. With act.rebin the same with the
// store's next_bin for a, drho and the limits (kick keeps bin). The default activity is the single-rate sweep.
template <int D>
ReferenceT<D> brute_force(const ParticleStore<D>& s, const sph::SolverSettingsT<D>& st, sph::Activity act = {}) {
  using K = sph::CubicSpline<D>;
  const std::size_t n = s.size();
  ReferenceT<D> ref;
  ref.drho.assign(n, 0.0);
  ref.drho_scale.assign(n, 0.0);
  ref.kick_rho.assign(n, 0.0);
  ref.a.assign(n, Vec<D>::Zero());
  ref.full_a.assign(n, Vec<D>::Zero());
  ref.full_drho.assign(n, 0.0);
  ref.full_a_scale.assign(n, 0.0);
  ref.full_drho_scale.assign(n, 0.0);
  ref.kick.assign(n, Vec<D>::Zero());
  ref.due.assign(n, 0);
  ref.a_scale.assign(n, 0.0);
  const Vec<D> g = st.gravity.value_or(Vec<D>::Zero());
  const double c = st.eos.c0;
  const sph::LatticeGradientSum<D> lattice;
  const auto bin = [&](std::size_t k) { return std::min(static_cast<int>(s.bin[k]), act.bin_cap); };
  const auto next_bin = [&](std::size_t k) {
    return act.rebin ? std::min(static_cast<int>(s.next_bin[k]), act.bin_cap) : bin(k);
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (s.kind[i] != Kind::fluid || is_passive(s.role[i])) continue;  // a passive particle has no sums of its own
    const int bi = bin(i), nbi = next_bin(i);
    const bool due = bi >= act.active_bin;
    const double wi = std::pow(2.0, -bi), nwi = std::pow(2.0, -nbi);
    Vec<D> ai = due ? Vec<D>(wi * g) : Vec<D>(Vec<D>::Zero());
    Vec<D> next_ai = due ? Vec<D>(nwi * g) : Vec<D>(Vec<D>::Zero());  // weighted by the next bins
    Vec<D> full_ai = g;  // every pair at weight 1
    double full_drho = 0.0, full_scale = g.norm(), full_drho_scale = 0.0;
    double scale = g.norm(), drho = 0.0, next_drho = 0.0, drho_scale = 0.0, mu_max = 0.0, grad_mass = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const Vec<D> xij = s.x[i] - s.x[j];
      const double r = xij.norm();
      if (!(r < s.h[i] + s.h[j])) continue;
      // Buffered levels: fluid and ghost partners of i's own level only.
      if (act.own_level_only && s.kind[j] != Kind::wall && s.level[j] != s.level[i]) continue;
      if (s.kind[j] == Kind::wall) {  // eq. (10), r0 = r0_factor d_i: a wall pair is one within r0
        if (!due || !st.lennard_jones) continue;
        const double r0 = st.lennard_jones->r0_factor * s.d[i];
        if (r >= r0) continue;
        ++ref.pairs;
        if (r == 0.0) continue;
        const Vec<D> f = st.lennard_jones->strength * (std::pow(r0 / r, 12) - std::pow(r0 / r, 6)) * xij / (r * r);
        ai += wi * f;
        next_ai += nwi * f;
        full_ai += f;
        full_scale += f.norm();
        scale += wi * f.norm();
        continue;
      }
      const int bij = std::max(bi, bin(j));
      if (bij < act.active_bin) continue;
      ++ref.pairs;
      const double w = std::pow(2.0, -bij), nw = std::pow(2.0, -std::max(nbi, next_bin(j)));
      const double hij = 0.5 * (s.h[i] + s.h[j]);
      // Every term is linear in grad W: summed at weight 1 here, then scaled by the pair's weights (powers of two).
      const Vec<D> gradW = r > 0.0 ? Vec<D>(K::derivative(r, hij) * xij / r) : Vec<D>(Vec<D>::Zero());
      grad_mass += s.m[j] * std::abs(K::derivative(r, hij));  // the acoustic limit's stiffness, unweighted
      // Near the edge of the support grad W goes as (2 - q)^2, so an ulp of q (the sweep forms q = r (1/h_ij),
      // this r / h_ij) moves the term by 2 q / (2 - q) ulps: the term's share of the scale carries that factor.
      // (With many neighbours other terms dominate the scale; a particle whose only due pair sits at the edge
      // of its support does not.)
      const double q = r / hij;
      const double cond = q >= 1.0 && q < 2.0 ? 1.0 + 2.0 * q / (2.0 - q) : 1.0;
      const Vec<D> vij = s.v[i] - s.v[j];
      double dr = s.m[j] * vij.dot(gradW);  // eq. (5)
      if (st.density_diffusion) {  // delta-SPH: psi = (rho_j - rho_i) - (rho0/c0^2) g.(x_j - x_i)
        const Vec<D> xji = s.x[j] - s.x[i];
        const double psi = (s.rho[j] - s.rho[i]) - st.eos.rho0 / (c * c) * g.dot(xji);
        dr += 2.0 * st.density_diffusion->delta * hij * c * psi * xji.dot(gradW) / (r * r + 0.01 * hij * hij) *
              s.m[j] / s.rho[j];
      }
      drho += w * dr;
      next_drho += nw * dr;
      full_drho += dr;
      full_drho_scale += cond * std::abs(dr);
      drho_scale += cond * std::abs(w * dr);
      double bracket = s.p[i] / (s.rho[i] * s.rho[i]) + s.p[j] / (s.rho[j] * s.rho[j]);  // eq. (6)
      const double mu = hij * vij.dot(xij) / (r * r + 0.01 * hij * hij);
      mu_max = std::max(mu_max, std::abs(mu));
      if (st.viscosity && vij.dot(xij) < 0.0) {  // eq. (9), opposes approach
        const double rho_bar = 0.5 * (s.rho[i] + s.rho[j]);
        bracket += (-st.viscosity->alpha * c * mu + st.viscosity->beta * mu * mu) / rho_bar;
      }
      if (st.artificial_stress) {  // Monaghan (2000): R_ij (W(r, h_ij) / W(d_ij, h_ij))^n
        const double eps = st.artificial_stress->epsilon;
        const double Ri = s.p[i] < 0.0 ? -eps * s.p[i] / (s.rho[i] * s.rho[i]) : 0.0;
        const double Rj = s.p[j] < 0.0 ? -eps * s.p[j] / (s.rho[j] * s.rho[j]) : 0.0;
        const double f = K::value(r, hij) / K::value(0.5 * (s.d[i] + s.d[j]), hij);
        bracket += (Ri + Rj) * std::pow(f, st.artificial_stress->exponent);
      }
      const Vec<D> f = -s.m[j] * bracket * gradW;
      ai += w * f;
      next_ai += nw * f;
      full_ai += f;
      full_scale += cond * f.norm();
      scale += cond * w * f.norm();
    }
    ref.kick[i] = ai;
    ref.kick_rho[i] = drho;
    ref.a_scale[i] = scale;
    ref.drho_scale[i] = drho_scale;
    if (!due) continue;
    ref.due[i] = 1;
    const double up = std::pow(2.0, nbi);
    ref.a[i] = up * next_ai;
    ref.drho[i] = up * next_drho;
    ref.full_a[i] = full_ai;
    ref.full_drho[i] = full_drho;
    ref.full_a_scale[i] = full_scale;
    ref.full_drho_scale[i] = full_drho_scale;
    if (ref.a[i].norm() > 0.0) ref.dt_force = std::min(ref.dt_force, up * std::sqrt(s.h[i] / ref.a[i].norm()));
    // The acoustic length (core/sweep.hpp, AcousticLimit): h_i, or where shorter, with the last-rate predictor
    // kappa(h_i / d_i) rho_i / sum_j m_j |grad W_ij| (kernel.hpp), with the extrapolated one the length at which
    // C L / c0 puts 0.61 (c0 / rho_i) sum_j m_j |grad W_ij| (the fastest mode's frequency) at omega dt = 0.5.
    const double stiff = st.predictor == sph::TimePredictor::last_rate ? lattice(s.h[i] / s.d[i]) * s.rho[i] / grad_mass
                                                                       : 0.5 * s.rho[i] / (0.61 * st.cfl * grad_mass);
    const double length = grad_mass > 0.0 ? std::min(s.h[i], stiff) : s.h[i];
    ref.dt_cfl = std::min(ref.dt_cfl, up * length / (c + mu_max));
  }
  return ref;
}

/// Compares the rates and limits a sweep left in `s` with the brute-force evaluation of the same state.
/// Tolerance: both add the same terms (the brute force in index order, with its own but equal expressions for
/// grad W and (r0/r)^12), so each term differs by a few ulps and each sum by rounding, of order
/// n_neighbours * 1e-16 of the sum of the terms' magnitudes (~1e-14 at ~50 neighbours). 1e-12 of that sum
/// leaves a factor ~100; a missing or extra pair changes a sum by a whole term, or, at the edge of the support
/// where grad W vanishes, changes the pair count, which must match exactly.
template <int D>
void expect_rates_match_brute_force(const ParticleStore<D>& s, const sph::SweepLimits& lim, const sph::SolverSettingsT<D>& st,
                                    const char* what, sph::Activity act = {}) {
  const ReferenceT<D> ref = brute_force(s, st, act);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || is_passive(s.role[i])) {
      EXPECT_EQ(s.a[i], Vec<D>::Zero()) << what << ": non-fluid " << i;
      EXPECT_EQ(s.drho[i], 0.0) << what << ": non-fluid " << i;
      continue;
    }
    // The weights are powers of two and the bins' scales undo them exactly, so the single-rate tolerance holds.
    EXPECT_LE((s.kick[i] - ref.kick[i]).norm(), 1e-12 * ref.a_scale[i] + 1e-300) << what << ": kick of " << i;
    EXPECT_LE(std::abs(s.kick_rho[i] - ref.kick_rho[i]), 1e-12 * ref.drho_scale[i] + 1e-300)
        << what << ": kick_rho of " << i;
    if (ref.due[i] == 0) continue;  // a and drho of a particle that is not due are not the sweep's to write
    ++checked;
    // a_scale sums the terms at this step's weights; the next bins' weights differ from them by at most
    // 2^|next_bin - bin|, and a is scaled back by 2^next_bin.
    const int b = act.rebin ? s.next_bin[i] : s.bin[i];
    const double up = std::pow(2.0, b + std::abs(static_cast<int>(s.next_bin[i]) - static_cast<int>(s.bin[i])));
    EXPECT_LE((s.a[i] - ref.a[i]).norm(), 1e-12 * up * ref.a_scale[i] + 1e-300) << what << ": a of " << i;
    EXPECT_LE(std::abs(s.drho[i] - ref.drho[i]), 1e-12 * up * ref.drho_scale[i] + 1e-300)
        << what << ": drho of " << i;
    // The rates at full weight, against the same sums of term magnitudes at weight 1 (the same reasoning).
    EXPECT_LE((s.full_a[i] - ref.full_a[i]).norm(), 1e-12 * ref.full_a_scale[i] + 1e-300) << what << ": full_a of " << i;
    EXPECT_LE(std::abs(s.full_drho[i] - ref.full_drho[i]), 1e-12 * ref.full_drho_scale[i] + 1e-300)
        << what << ": full_drho of " << i;
  }
  EXPECT_GT(checked, act.active_bin == 0 ? 100u : 20u);
  EXPECT_EQ(lim.pairs, ref.pairs) << what;
  EXPECT_NEAR(lim.dt_force, ref.dt_force, 1e-12 * ref.dt_force) << what;
  EXPECT_NEAR(lim.dt_cfl, ref.dt_cfl, 1e-12 * ref.dt_cfl) << what;
}

/// The sweep on a grid built here (cell size 2 h_max), against the brute force.
template <int D>
void expect_matches_brute_force(ParticleStore<D>& s, const sph::SolverSettingsT<D>& st, const char* what) {
  CellGrid<D> grid;
  build_grid(s, grid);
  const sph::SweepLimits lim = sph::make_sweep(st)->run(s.view(), grid);
  expect_rates_match_brute_force(s, lim, st, what);
}

/// How many particles a term moves beyond the comparison's tolerance: the acceleration or density rate of
/// the brute-force evaluation with the term against that without it. (A twin test is only as sharp as this.)
template <int D>
std::size_t changed_accelerations(const ReferenceT<D>& with, const ReferenceT<D>& without) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < with.a.size(); ++i) n += (with.a[i] - without.a[i]).norm() > 1e-6 * with.a_scale[i];
  return n;
}

template <int D>
std::size_t changed_density_rates(const ReferenceT<D>& with, const ReferenceT<D>& without) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < with.drho.size(); ++i)
    n += std::abs(with.drho[i] - without.drho[i]) > 1e-6 * with.drho_scale[i];
  return n;
}

/// The due particles of an activity as the sweep's optional lists (Activity::due_prefix, due_index): fluid and ghosts
/// whose bin is at least the active bin, in store order. Set act.due_prefix = prefix.data() (and due_index) to use them.
struct DueLists {
  std::vector<std::uint32_t> prefix, index;
};
template <int D>
DueLists due_lists(const ParticleStore<D>& s, const sph::Activity& act) {
  DueLists l;
  l.prefix.assign(s.size() + 1, 0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool is_due = s.kind[i] != Kind::wall && act.bin(s.bin[i]) >= act.active_bin;
    l.prefix[i + 1] = l.prefix[i] + (is_due ? 1u : 0u);
    if (is_due) l.index.push_back(static_cast<std::uint32_t>(i));
  }
  return l;
}

/// The 2D twins' settings (tests/test_sweep.cpp, tests/test_sweep_bins.cpp): no ghost walls, and the optional effects
/// on request.
inline SolverSettings twin_settings(bool viscosity, bool lennard_jones) {
  SolverSettings st;
  st.eos.rho0 = 1000.0;
  st.eos.c0 = 25.0;
  st.gravity = Vec<2>(0.0, -9.81);
  st.ghosts.reset();
  if (viscosity) {
    st.viscosity = ViscositySettings{0.2, 0.5};
  } else {
    st.viscosity.reset();
  }
  if (lennard_jones) st.lennard_jones = LennardJonesSettings{50.0, 0.5, 0.25};
  return st;
}

/// A mixed-level cloud plus ghost-kind particles (sources only) and a row of wall particles at y = 0.
inline ParticleStore<2> twin_cloud(const SolverSettings& st, std::uint32_t seed) {
  ParticleStore<2> s = random_cloud(700, 10.0, 0.5, st.eos, seed, 1.5);
  for (std::size_t i = 0; i < s.size(); i += 7) s.kind[i] = Kind::ghost;
  for (int k = 0; k <= 40; ++k) add_particle(s, wall_particle<2>(Vec<2>(0.25 * k, 0.0), 0.125, st.eos.rho0), st.eos);
  return s;
}

/// Every third fluid particle of the cloud passive (alternately a shadow and a buffer particle).
template <int D>
std::size_t make_some_passive(ParticleStore<D>& s) {
  std::size_t passive = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid || i % 3 != 1) continue;
    s.role[i] = (i / 3) % 2 == 0 ? Role::shadow : Role::buffer;
    ++passive;
  }
  return passive;
}

}  // namespace sph::test
