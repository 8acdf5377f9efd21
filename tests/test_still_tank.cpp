// Still water in a tank (make_still_tank: 25 m wide, 10 m deep, ghost walls, gravity) stays still and
// hydrostatic over 10 s of physical time, at the paper's spacing d = 25/30 m and at d/2, and with the
// optional density diffusion. The band pressures are judged by their time average over the last 5 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "core/case_builder.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

using sph::Kind;
using sph::Vec;

constexpr double kG = 9.81;

struct TankState {
  double max_speed = 0.0;
  double max_density_error = 0.0;
  double p_mid = 0.0, p_mid_expected = 0.0;        // band at mid-depth
  double p_bottom = 0.0, p_bottom_expected = 0.0;  // band along the bottom
  std::size_t n_mid = 0, n_bottom = 0;
  std::size_t outside = 0;  // particles inside a wall or outside the container
  std::size_t fluid = 0;
  double min_y = 0.0, max_y = 0.0;
  std::string describe() const {
    std::ostringstream o;
    o << "max|v| = " << max_speed << ", max density error = " << max_density_error << ", p_mid = " << p_mid
      << " (hydrostatic " << p_mid_expected << ", " << n_mid << " particles), p_bottom = " << p_bottom
      << " (hydrostatic " << p_bottom_expected << ", " << n_bottom << " particles), outside = " << outside
      << ", y in [" << min_y << ", " << max_y << "]";
    return o.str();
  }
};

/// Averages p and rho0 g (depth - y) over the fluid particles in the band |y - y0| < half_width, away
/// from the side walls (x in [width/5, 4 width/5]).
void band(const sph::ParticleStore<2>& s, double y0, double half_width, double width, double depth, double rho0,
          double& p, double& expected, std::size_t& count) {
  p = expected = 0.0;
  count = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    const Vec<2>& x = s.x[i];
    if (std::abs(x[1] - y0) >= half_width || x[0] < 0.2 * width || x[0] > 0.8 * width) continue;
    p += s.p[i];
    expected += rho0 * kG * (depth - x[1]);
    ++count;
  }
  if (count > 0) {
    p /= static_cast<double>(count);
    expected /= static_cast<double>(count);
  }
}

TankState measure(const sph::Simulation& sim, const sph::TankSpec& spec) {
  const auto& s = sim.store();
  const auto& st = sim.settings();
  TankState out;
  const auto d = sim.diagnostics();
  out.max_speed = d.max_speed;
  out.max_density_error = d.max_density_error;
  out.fluid = d.fluid;
  out.min_y = std::numeric_limits<double>::infinity();
  out.max_y = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    if (!st.geometry.in_fluid_domain(s.x[i]) || s.x[i][1] > st.geometry.container.hi[1]) ++out.outside;
    out.min_y = std::min(out.min_y, s.x[i][1]);
    out.max_y = std::max(out.max_y, s.x[i][1]);
  }
  band(s, 0.5 * spec.depth, spec.spacing, spec.width, spec.depth, st.eos.rho0, out.p_mid, out.p_mid_expected,
       out.n_mid);
  band(s, 0.5 * spec.spacing, spec.spacing, spec.width, spec.depth, st.eos.rho0, out.p_bottom,
       out.p_bottom_expected, out.n_bottom);
  return out;
}

/// The time average of a band's p / hydrostatic over the steps added (weighted by their dt), and its range.
struct Averages {
  double sum = 0.0, time = 0.0;
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(const sph::Simulation& sim, const sph::TankSpec& spec, double y0, double dt) {
    double p = 0.0, expected = 0.0;
    std::size_t count = 0;
    band(sim.store(), y0, spec.spacing, spec.width, spec.depth, sim.settings().eos.rho0, p, expected, count);
    if (count == 0 || !(expected > 0.0)) return;
    const double r = p / expected;
    sum += r * dt;
    time += dt;
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  double ratio() const { return sum / time; }
  double half_range() const { return 0.5 * (hi - lo); }
};

void run_still_tank(double spacing, bool density_diffusion = false) {
  sph::TankSpec spec;
  spec.spacing = spacing;
  spec.density_diffusion = density_diffusion;
  sph::Simulation sim = sph::make_still_tank(spec);
  const double mass0 = sph::test::mass_by_id(sim.store());
  const std::size_t fluid0 = sim.diagnostics().fluid;
  const TankState start = measure(sim, spec);
  ASSERT_EQ(start.outside, 0u) << start.describe();

  // 10 s (~25 sloshing periods of the tank's first mode). Under the sanitizer preset (SPH_TEST_SCALE=short)
  // 1 s: that run looks for memory and undefined-behaviour errors, which the first steps already exercise;
  // the physics is held to the full 10 s by the release run.
  const double t_end = sph::test::short_runs() ? 1.0 : 10.0;
  double max_speed_seen = 0.0;
  // The band pressures oscillate (the tank's compression mode: the bottom band swings by a few per cent at
  // ~2.6 Hz, undamped), so they are judged by their time average over the second half of the run (the last
  // 5 s, ~13 periods), each step weighted by its length; the swing's half range is reported beside it.
  Averages mid, bottom;
  while (sim.time() < t_end * (1.0 - 1e-14)) {
    const sph::StepInfo info = sim.step(t_end - sim.time());
    max_speed_seen = std::max(max_speed_seen, sim.diagnostics().max_speed);
    ASSERT_TRUE(std::isfinite(sim.dt()) && sim.dt() > 0.0) << "t = " << sim.time();
    if (sim.time() > 0.5 * t_end) {
      mid.add(sim, spec, 0.5 * spec.depth, info.dt);
      bottom.add(sim, spec, 0.5 * spec.spacing, info.dt);
    }
  }
  sim.remove_ghosts();
  const TankState end = measure(sim, spec);
  // Scales of the tank: its long-wave speed, and the compression of its floor at rest, g depth / c0^2 (the
  // hydrostatic pressure rho0 g depth over the Tait law's stiffness rho0 c0^2, to first order).
  const double wave_speed = std::sqrt(kG * spec.depth);
  const double c0 = sim.settings().eos.c0;
  const double floor_compression = kG * spec.depth / (c0 * c0);
  SCOPED_TRACE("d = " + std::to_string(spacing) + ", " + std::to_string(sim.step_count()) + " steps: " +
               end.describe() + ", max|v| over the run = " + std::to_string(max_speed_seen));

  EXPECT_EQ(end.fluid, fluid0);
  EXPECT_EQ(sph::test::mass_by_id(sim.store()), mass0);
  EXPECT_TRUE(sph::test::all_finite(sim.store()));
  EXPECT_LT(end.max_speed, 0.05 * wave_speed);
  ASSERT_GT(end.n_mid, 10u);
  ASSERT_GT(end.n_bottom, 10u);
  // Time-averaged band pressure against hydrostatic, rho0 g (depth - y). The bound is the 5 % this test held the
  // pressure to at one instant, kept, not derived: the time averages sit about 2 % (mid-depth) and 3 % (bottom)
  // above hydrostatic at both spacings, an offset that does not shrink with d and whose cause is open
  // (docs/METHOD.md, "Still water across a level jump": the kernel's lattice gradient factor at h = 1.2 d accounts
  // for 0.9 % of it). So no tighter bound can be reasoned yet; this one catches the offset growing.
  for (const auto& [name, avg] : {std::pair{"mid-depth", &mid}, std::pair{"bottom", &bottom}}) {
    const double tolerance = 0.05;
    ASSERT_GT(avg->time, 0.0);
    EXPECT_NEAR(avg->ratio(), 1.0, tolerance)
        << name << " band: time-averaged p / hydrostatic = " << avg->ratio() << ", swing (half range) "
        << avg->half_range() << " of hydrostatic";
    testing::Test::RecordProperty(std::string(name) + "_p_over_hydrostatic", std::to_string(avg->ratio()));
    testing::Test::RecordProperty(std::string(name) + "_swing", std::to_string(avg->half_range()));
  }
  // The largest density error of still water is the floor's hydrostatic compression; noise may add at most as
  // much again.
  EXPECT_LT(end.max_density_error, 2.0 * floor_compression);
  EXPECT_EQ(end.outside, 0u);
}

TEST(StillTank, StaysStillAndHydrostaticAtPaperSpacing) { run_still_tank(25.0 / 30.0); }

TEST(StillTank, StaysStillAndHydrostaticAtHalfSpacing) { run_still_tank(25.0 / 60.0); }

// The optional density diffusion keeps the tank still and hydrostatic over the same 10 s. (Its hydrostatic
// correction itself is checked by Sweep.DensityDiffusionLeavesAHydrostaticColumnAlone: without it, this
// coarse tank still stays inside these bounds over 10 s, so this run alone would not catch its loss.)
TEST(StillTank, StaysStillAndHydrostaticWithDensityDiffusion) { run_still_tank(25.0 / 30.0, true); }

}  // namespace
