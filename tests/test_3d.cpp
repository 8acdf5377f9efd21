// Three dimensions (issue #18), the driver and its output: a still tank stays still and hydrostatic, a run is
// bitwise the same at 1 and 2 threads, frames are N x 3 with an XYZ XDMF, a checkpoint resumes bitwise and refuses
// the other dimension, and the probes measure in 3D.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/case_builder.hpp"
#include "core/kernel.hpp"
#include "core/io/hdf5_frames.hpp"
#include "core/io/xdmf.hpp"
#include "core/scene/probes.hpp"
#include "tests/support/io_helpers.hpp"
#include "tests/support/physics_helpers.hpp"
#include "tests/support/test_scale.hpp"
#include "tests/support/thread_count.hpp"

namespace {

using sph::Kind;
using sph::test::ThreadCount;
using Vec3 = sph::Vec<3>;

constexpr double kG = 9.81;  // the cases' gravity (m/s^2)

/// The 3D still tank of these tests at h = h_factor d: 1 x 0.4 m, 0.5 m deep, d = 0.05 m (1600 particles); under the
/// sanitizer preset (SPH_TEST_SCALE=short), which looks for memory and undefined-behaviour errors, a 0.4 x 0.2 m tank
/// 0.3 m deep (192 particles).
sph::Tank3Spec test_tank(double h_factor) {
  sph::Tank3Spec spec;
  spec.h_factor = h_factor;
  if (sph::test::short_runs()) {
    spec.length = 0.4;
    spec.width = 0.2;
    spec.depth = 0.3;
    spec.reference_height = 0.15;
  }
  return spec;
}

// ---------------------------------------------------------------------------------------------------
// A lattice mode of 3D still water (docs/METHOD.md, "Three dimensions: a lattice mode")

/// The alternating-layer shear mode's shape at x: (-1)^layer sin(2 pi x / L) along x (layer = the lattice row in z;
/// the sine vanishes at the end walls).
double layer_shear_shape(const Vec3& x, const sph::Tank3Spec& spec) {
  const long layer = std::lround(x[2] / spec.spacing - 0.5);
  return (layer % 2 == 0 ? 1.0 : -1.0) * std::sin(2.0 * std::numbers::pi * x[0] / spec.length);
}

/// Adds `seed` times the mode to every fluid velocity the integrator holds (v, the half-step and the step-start copy).
void seed_layer_shear(sph::SimulationT<3>& sim, const sph::Tank3Spec& spec, double seed) {
  auto& s = sim.store();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    const double u = seed * layer_shear_shape(s.x[i], spec);
    s.v[i][0] += u;
    s.vh[i][0] += u;
    s.v_open[i][0] += u;
  }
}

/// The mode's amplitude: the fluid's x-velocity projected on its shape.
double layer_shear_amplitude(const sph::SimulationT<3>& sim, const sph::Tank3Spec& spec) {
  const auto& s = sim.store();
  double vu = 0.0, uu = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.kind[i] != Kind::fluid) continue;
    const double u = layer_shear_shape(s.x[i], spec);
    vu += s.v[i][0] * u;
    uu += u * u;
  }
  return vu / uu;
}

// The still tank at h = 1.2 d and 1.3 d, seeded with the alternating-layer shear mode at 1 mm/s. Where the mode's
// stiffness (CubicSpline::layer_shear_stiffness) is negative it grows, at most at sqrt(-2 S g H) / d, the rate at the
// floor's pressure rho g H (19 /s at h = 1.2 d; 14 /s at mid-depth). The test asks what tells an unstable mode from a
// stable one: at 1.2 d the amplitude must grow by an order of magnitude (ten times the seed) within 0.6 s, and once past
// the seed never faster between two samples than the floor's rate; at 1.3 d, where the mode is stable, it must never
// exceed the seed. (Measured: at 1.2 d the amplitude first falls to 0.14 of the seed, the seed's share in the tank's
// other motions, then grows at 9.7 /s from 0.2 to 0.5 s, slower than the analysis, which leaves out the viscosity, and
// peaks at 16x at 0.55 s, when the water is stirred; at 1.3 d it stays within 0.73 of the seed. The run is bitwise the
// same at any thread count.) The tank without a seed stays still at both: StillTank3D.
TEST(LayerShearMode3D, GrowsWhereItsStiffnessIsNegativeAndNotWhereItIsPositive) {
  ASSERT_LT(sph::CubicSpline<3>::layer_shear_stiffness(1.2), 0.0);
  ASSERT_GT(sph::CubicSpline<3>::layer_shear_stiffness(1.3), 0.0);
  const double seed = 1e-3;
  const double sample = 0.05;  // s
  for (double h : {1.2, 1.3}) {
    SCOPED_TRACE(testing::Message() << "h = " << h << " d");
    const sph::Tank3Spec spec = test_tank(h);
    sph::SimulationT<3> sim = sph::make_still_tank(spec);
    const double stiffness = sph::CubicSpline<3>::layer_shear_stiffness(h);
    const double floor_rate = std::sqrt(std::max(0.0, -2.0 * stiffness * kG * spec.depth)) / spec.spacing;
    seed_layer_shear(sim, spec, seed);
    const double a0 = layer_shear_amplitude(sim, spec);
    ASSERT_NEAR(a0, seed, 1e-12);
    std::vector<double> amplitude{a0};
    const double end = sph::test::short_runs() ? 0.1 : 0.6;
    for (double t = sample; t < end + 0.5 * sample; t += sample) {
      while (sim.time() < t * (1.0 - 1e-14)) sim.step(t - sim.time());
      amplitude.push_back(layer_shear_amplitude(sim, spec));
    }
    double largest = 0.0, fastest = 0.0;
    for (std::size_t k = 0; k < amplitude.size(); ++k) {
      largest = std::max(largest, std::abs(amplitude[k]));
      if (k > 0 && std::abs(amplitude[k - 1]) > seed)  // once grown past the seed, where the mode dominates
        fastest = std::max(fastest, std::log(std::abs(amplitude[k]) / std::abs(amplitude[k - 1])) / sample);
    }
    std::string series;
    for (double a : amplitude) series += " " + std::to_string(a);
    SCOPED_TRACE("amplitude every 0.05 s:" + series);
    RecordProperty(h < 1.25 ? "largest_over_seed_h1_2" : "largest_over_seed_h1_3", std::to_string(largest / seed));
    RecordProperty(h < 1.25 ? "fastest_growth_h1_2" : "fastest_growth_h1_3", std::to_string(fastest));
    RecordProperty(h < 1.25 ? "amplitudes_h1_2" : "amplitudes_h1_3", series);
    if (sph::test::short_runs()) continue;  // 0.1 s: a smoke run under the sanitizer
    if (stiffness < 0.0) {
      EXPECT_GE(largest, 10.0 * seed);
      EXPECT_LE(fastest, floor_rate) << "the floor's rate " << floor_rate << " /s";
    } else {
      EXPECT_LE(largest, seed);
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// The driver in 3D

/// The time average of the fluid's p / hydrostatic in a layer |z - z0| < d, away from the side walls.
struct LayerAverage {
  double z0 = 0.0;
  double sum = 0.0, time = 0.0;
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(const sph::SimulationT<3>& sim, const sph::Tank3Spec& spec, double dt) {
    const auto& s = sim.store();
    double p = 0.0, expected = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.kind[i] != Kind::fluid) continue;
      const Vec3& x = s.x[i];
      if (std::abs(x[2] - z0) >= spec.spacing || x[0] < 0.2 * spec.length || x[0] > 0.8 * spec.length ||
          x[1] < 0.2 * spec.width || x[1] > 0.8 * spec.width)
        continue;
      p += s.p[i];
      expected += sim.settings().eos.rho0 * kG * (spec.depth - x[2]);
    }
    if (!(expected > 0.0)) return;
    const double r = p / expected;
    sum += r * dt;
    time += dt;
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  double ratio() const { return sum / time; }
};

/// The cubic spline's gradient normalisation on the cubic lattice of spacing 1 at h = h_factor:
/// N = -sum_j V_j z_ij dW/dz (V_j = 1). A hydrostatic column needs its pressure gradient 1/N times rho g to stand
/// still (docs/METHOD.md, "The unrefined tank's own pressure offset").
double lattice_normalisation(double h_factor) {
  double n = 0.0;
  for (int a = -3; a <= 3; ++a)
    for (int b = -3; b <= 3; ++b)
      for (int c = -3; c <= 3; ++c) {
        const Vec3 xij(a, b, c);  // x_i - x_j, j a lattice neighbour of i
        const double r = xij.norm();
        if (r == 0.0) continue;
        n -= xij[2] * xij[2] * sph::CubicSpline<3>::gradient_factor(r, h_factor);
      }
  return n;
}

/// The 3D still tank at two sets of settings: the paper's (h = 1.2 d, c0 = 10 sqrt(2 g H_ref)) and the peer's 3D
/// ones (DualSPHysics' CaseDambreak: h = sqrt(3) d, coefsound 20).
struct TankSettings {
  const char* name;
  double h_factor;
  double mach_factor;
};

class StillTank3D : public testing::TestWithParam<TankSettings> {};

TEST_P(StillTank3D, StaysStillAndHydrostatic) {
  const TankSettings& settings = GetParam();
  sph::Tank3Spec spec = test_tank(settings.h_factor);
  spec.mach_factor = settings.mach_factor;
  sph::SimulationT<3> sim = sph::make_still_tank(spec);
  const auto d0 = sim.diagnostics();
  ASSERT_EQ(d0.fluid, sph::test::short_runs() ? 192u : 1600u);
  EXPECT_GT(d0.ghosts, 0u);
  const double mass0 = sph::test::mass_by_id(sim.store());
  // 1 s: 5 periods of the tank's compression mode (4 H / c0 = 0.2 s at c0 = 22 m/s; 10 at 44 m/s), the window
  // its second half. (0.1 s under the sanitizer preset.)
  const double t_end = sph::test::short_runs() ? 0.1 : 1.0;
  LayerAverage bottom{0.5 * spec.spacing}, mid{0.5 * spec.depth};
  double max_speed = 0.0;
  while (sim.time() < t_end * (1.0 - 1e-14)) {
    const sph::StepInfo info = sim.step(t_end - sim.time());
    max_speed = std::max(max_speed, sim.diagnostics().max_speed);
    if (sim.time() > 0.5 * t_end) {
      bottom.add(sim, spec, info.dt);
      mid.add(sim, spec, info.dt);
    }
  }
  sim.remove_ghosts();
  const auto d = sim.diagnostics();
  const double wave_speed = std::sqrt(kG * spec.depth);
  const double c0 = sim.settings().eos.c0;
  SCOPED_TRACE(testing::Message() << sim.step_count() << " steps, max |v| " << max_speed << ", bottom p/p_h "
                                  << bottom.ratio() << " [" << bottom.lo << ", " << bottom.hi << "], mid "
                                  << mid.ratio() << " [" << mid.lo << ", " << mid.hi << "], density error "
                                  << d.max_density_error);
  EXPECT_EQ(d.fluid, d0.fluid);
  EXPECT_EQ(sph::test::mass_by_id(sim.store()), mass0);
  EXPECT_TRUE(sph::test::all_finite(sim.store()));
  for (std::size_t i = 0; i < sim.store().size(); ++i)
    EXPECT_TRUE(sim.settings().geometry.in_fluid_domain(sim.store().x[i])) << "particle " << i;
  // Issue #18's bound: the water moves at less than 1 % of its long-wave speed.
  EXPECT_LT(max_speed, 0.01 * wave_speed);
  // The largest density error of still water is the floor's hydrostatic compression g H / c0^2; noise may add
  // at most as much again.
  EXPECT_LT(d.max_density_error, 2.0 * kG * spec.depth / (c0 * c0));
  // Time-averaged layer pressure. The scheme's own equilibrium sits above hydrostatic by two terms that
  // docs/METHOD.md derives: 1/N (the lattice's gradient normalisation) and 2 g depth / c0^2 (the equal-mass
  // hydrostatic start). Issue #18's bound, 1 %, is held against that equilibrium at any settings, and against
  // hydrostatic itself at the peer's, where both terms are small (0.2 % and 0.25-0.45 %). Not under the
  // sanitizer preset: its 0.1 s is half a compression period, not an average.
  if (sph::test::short_runs()) return;
  const double n = lattice_normalisation(spec.h_factor);
  for (const LayerAverage* avg : {&bottom, &mid}) {
    ASSERT_GT(avg->time, 0.0);
    const double equilibrium = 1.0 / n + 2.0 * kG * (spec.depth - avg->z0) / (c0 * c0);
    EXPECT_NEAR(avg->ratio(), equilibrium, 0.01) << "layer at z = " << avg->z0;
    if (std::string(settings.name) == "peer") {
      EXPECT_NEAR(avg->ratio(), 1.0, 0.01) << "layer at z = " << avg->z0;
    }
  }
  const auto& w = sim.work();
  testing::Test::RecordProperty("pairs_per_evaluation", std::to_string(static_cast<double>(w.pairs) / static_cast<double>(w.evaluations[0])));
  testing::Test::RecordProperty("candidates_per_evaluation", std::to_string(static_cast<double>(w.candidates) / static_cast<double>(w.evaluations[0])));
  testing::Test::RecordProperty("bottom_p_over_hydrostatic", std::to_string(bottom.ratio()));
  testing::Test::RecordProperty("mid_p_over_hydrostatic", std::to_string(mid.ratio()));
}

INSTANTIATE_TEST_SUITE_P(Settings, StillTank3D,
                         testing::Values(TankSettings{"paper", 1.2, 10.0},
                                         TankSettings{"peer", 1.7320508075688772, 20.0}),
                         [](const testing::TestParamInfo<TankSettings>& p) { return std::string(p.param.name); });

TEST(Determinism3D, SameBitsAtOneAndTwoThreads) {
  sph::Tank3Spec spec;
  spec.length = 0.5;
  spec.width = 0.3;
  spec.depth = 0.3;
  std::vector<sph::ParticleStore<3>> ends;
  for (const int threads : {1, 2}) {
    ThreadCount tc(threads);
    sph::SimulationT<3> sim = sph::make_still_tank(spec);
    // A disturbance, so the run is not trivially at rest: the fluid starts with a swirl.
    auto& s = sim.store();
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s.kind[i] == Kind::fluid) s.v[i] = Vec3(-(s.x[i][1] - 0.15), s.x[i][0] - 0.25, 0.0);
    sim.refresh();
    for (int k = 0; k < 40; ++k) sim.step();
    sim.remove_ghosts();
    ends.push_back(sim.store());
  }
  const auto& a = ends[0];
  const auto& b = ends[1];
  ASSERT_EQ(a.size(), b.size());
  const auto ia = sph::test::index_by_id(a), ib = sph::test::index_by_id(b);
  std::size_t moved = 0;
  for (std::size_t id = 0; id < ia.size(); ++id) {
    if (ia[id] == static_cast<std::size_t>(-1)) continue;
    ASSERT_NE(ib[id], static_cast<std::size_t>(-1));
    EXPECT_EQ(a.x[ia[id]], b.x[ib[id]]) << "id " << id;
    EXPECT_EQ(a.v[ia[id]], b.v[ib[id]]) << "id " << id;
    EXPECT_EQ(a.rho[ia[id]], b.rho[ib[id]]) << "id " << id;
    moved += a.v[ia[id]].norm() > 0.01;
  }
  EXPECT_GT(moved, 100u);
}

// ---------------------------------------------------------------------------------------------------
// Output in 3D

/// A 0.3 x 0.2 m tank, 0.2 m deep (96 particles).
sph::Tank3Spec small_tank() {
  sph::Tank3Spec spec;
  spec.length = 0.3;
  spec.width = 0.2;
  spec.depth = 0.2;
  return spec;
}

TEST(Io3D, FramesAreNByThreeAndXdmfSaysXYZ) {
  sph::test::TempFolder tmp;
  const sph::Tank3Spec spec = small_tank();
  sph::SimulationT<3> sim = sph::make_still_tank(spec);
  for (int k = 0; k < 3; ++k) sim.step();
  const auto& s = sim.store();
  const auto file = tmp.path() / "frame.h5";
  const sph::io::FrameHeader h = sph::io::write_frame(file, "frame_000001", s, sim.time(), sim.step_count(), 1, {});
  const std::size_t fluid = sim.diagnostics().fluid;
  EXPECT_EQ(h.particles, fluid) << "ghosts are left out";
  const sph::io::FrameHeader r = sph::io::read_frame_header(file, "frame_000001");
  EXPECT_EQ(r.fields, sph::io::field_layouts(3));
  const auto pos = std::find_if(r.fields.begin(), r.fields.end(), [](const auto& f) { return f.name == "position"; });
  ASSERT_NE(pos, r.fields.end());
  EXPECT_EQ(pos->components, 3);
  const std::vector<double> x = sph::io::read_frame_field(file, "frame_000001", "position");
  ASSERT_EQ(x.size(), 3 * fluid);
  std::vector<std::size_t> kept;  // a frame holds fluid and walls, in id order
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.kind[i] != Kind::ghost) kept.push_back(i);
  std::sort(kept.begin(), kept.end(), [&](std::size_t a, std::size_t b) { return s.id[a] < s.id[b]; });
  for (std::size_t k = 0; k < kept.size(); ++k) EXPECT_EQ(Vec3(x[3 * k], x[3 * k + 1], x[3 * k + 2]), s.x[kept[k]]);
  const std::string xdmf = sph::io::xdmf_document({{"frame.h5", r}});
  EXPECT_NE(xdmf.find("GeometryType=\"XYZ\""), std::string::npos);
  EXPECT_NE(xdmf.find("Dimensions=\"" + std::to_string(fluid) + " 3\""), std::string::npos);
}

TEST(Io3D, CheckpointResumesBitwiseAndRefusesTheOtherDimension) {
  sph::test::TempFolder tmp;
  const sph::Tank3Spec spec = small_tank();
  sph::SimulationT<3> a = sph::make_still_tank(spec);
  for (int k = 0; k < 5; ++k) a.step();
  a.remove_ghosts();
  sph::io::CheckpointState st;
  st.time = a.time();
  st.step = a.step_count();
  st.dt = a.dt();
  st.next_id = a.store().next_id();
  const auto file = tmp.path() / "checkpoint.h5";
  sph::io::write_checkpoint(file, a.store(), st);
  EXPECT_EQ(sph::io::checkpoint_dimension(file), 3);
  sph::SimulationT<3> b = sph::make_still_tank(spec);
  const auto got = sph::io::read_checkpoint(file, b.store());
  {  // the file holds the particles in id order
    std::vector<std::uint32_t> by_id(a.store().size());
    for (std::uint32_t i = 0; i < by_id.size(); ++i) by_id[i] = i;
    std::sort(by_id.begin(), by_id.end(), [&](std::uint32_t p, std::uint32_t q) { return a.store().id[p] < a.store().id[q]; });
    a.store().gather(by_id);
  }
  sph::test::expect_bitwise_equal(a.store(), b.store());
  b.set_clock(got.time, got.step, got.dt);
  b.store_restored();
  // Both continue from the same stored state: the rates are in the store, so the next steps agree bitwise.
  a.prepare_neighbours();
  b.prepare_neighbours();
  for (int k = 0; k < 5; ++k) {
    a.step();
    b.step();
  }
  a.remove_ghosts();
  b.remove_ghosts();
  sph::test::expect_bitwise_equal(a.store(), b.store());
  sph::ParticleStore<2> flat;
  EXPECT_THROW(sph::io::read_checkpoint(file, flat), std::runtime_error);
}

TEST(Probes3D, GaugeIsAVerticalLineAndSensorAPointOnAWall) {
  const sph::Tank3Spec spec;  // 0.5 m of water at rest, d = 0.05 m
  const sph::SimulationT<3> sim = sph::make_still_tank(spec);
  const auto& s = sim.store();
  // A lattice column's top edge is the water's depth exactly, anywhere in the tank; outside it the column is dry.
  using H = sph::scene::Horizontal<3>;
  EXPECT_NEAR(sph::scene::water_height<3>(s, H(0.5, 0.2), spec.spacing, 0.0, spec.spacing), spec.depth, 1e-12);
  EXPECT_NEAR(sph::scene::water_height<3>(s, H(0.02, 0.38), spec.spacing, 0.0, spec.spacing), spec.depth, 1e-12);
  EXPECT_EQ(sph::scene::water_height<3>(s, H(1.5, 0.2), spec.spacing, 0.0, spec.spacing), 0.0);
  // A sensor on the side wall x = 0 at mid-depth reads the hydrostatic pressure there: the lattice (and its ghosts
  // beyond the wall, which carry the same pressure) sits symmetrically about the point, so the Shepard
  // interpolation of the linear field p = rho0 g (H - z) is exact but for the weights' volumes m / rho, which vary
  // with depth by g (2 h) / c0^2 = 2.4e-3 across the kernel; the error is at most that share of p's variation
  // across the kernel, rho0 g 2 h = 0.48 of p here: 1.2e-3 of p. The bound is 2e-3.
  const double p = sph::scene::point_pressure<3>(s, Vec3(0.0, 0.2, 0.25));
  EXPECT_NEAR(p, 1000.0 * kG * 0.25, 2e-3 * 1000.0 * kG * 0.25);
}

}  // namespace

