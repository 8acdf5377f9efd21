// Case regressions: every case of cases/ and cases/validation/ runs to a fraction of its end time (a quarter;
// a fiftieth under the sanitizer preset, or less where that would exceed the work budget below) through the same
// Runner as the program, conserves mass exactly, and
// its probes stay within a tolerance of the reference series of a full-length run stored in
// tests/data/case_references/ (tools/case_references.py writes them). Each row is compared with the reference
// interpolated at the row's time.
//
// Tolerances. The length probes (water height, surge front, surface elevation) are maxima of particle
// positions over the body of water, so they move in steps of particles: a run that differs from the reference
// only by rounding (summation order, compiler) stays within a fraction of a spacing over these short windows,
// whereas a change to the physics (a force, the integrator, the refinement) moves the front or the column by
// whole spacings within tenths of a second. Half the coarsest spacing separates the two. The pressure probe is
// a kernel interpolation at a point carrying the weakly-compressible acoustic noise (a few per cent of the
// hydrostatic scale rho0 g H from step to step): 5 % of rho0 g H, H the tallest fluid region's top above the
// floor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/scene/runner.hpp"
#include "core/scene/scene_builder.hpp"
#include "core/scene/scene_parser.hpp"
#include "tests/support/io_helpers.hpp"
#include "tests/support/test_scale.hpp"

namespace {

namespace fs = std::filesystem;
using namespace sph;

const fs::path kRoot = fs::path(__FILE__).parent_path().parent_path();
const fs::path kReferences = kRoot / "tests" / "data" / "case_references";

struct Series {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  std::size_t column(const std::string& name) const {
    const auto it = std::find(columns.begin(), columns.end(), name);
    return it == columns.end() ? columns.size() : static_cast<std::size_t>(it - columns.begin());
  }
};

Series read_series(const fs::path& path) {
  Series s;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (s.columns.empty()) {
      s.columns = cells;
      continue;
    }
    std::vector<double> row;
    for (const auto& c : cells) row.push_back(c == "nan" || c == "NaN" ? std::nan("") : std::stod(c));
    s.rows.push_back(row);
  }
  return s;
}

fs::path scene_of(const std::string& name) {
  for (const fs::path& p : {kRoot / "cases" / (name + ".json"), kRoot / "cases" / "validation" / (name + ".json")}) {
    if (fs::exists(p)) return p;
  }
  return {};
}

std::vector<std::string> reference_names() {
  std::vector<std::string> names;
  if (!fs::exists(kReferences)) return names;
  for (const auto& e : fs::directory_iterator(kReferences)) {
    if (e.path().extension() == ".csv") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

double fluid_height(const scene::Scene& s) {
  const int up = scene::dimension(s) - 1;
  double top = s.container.box.lo[up];
  for (const auto& f : s.fluid) {
    top = std::max(top, f.shape == scene::Shape::rectangle ? f.rect.hi[up] : f.centre[up] + f.radius);
  }
  return top - s.container.box.lo[up];
}

// The work one case may take (fluid particle-steps, estimated from the start: its fluid count times the steps at the
// first step's dt, a 3D particle-step counted as four). A quarter of every 2D case is within it (the largest, the
// fully refined dam break, about 8e6); a 3D case runs to where its budget ends instead (the 3D dam break to about
// 2 % of its end time, Lobovsky's tank to 0.6 %), so that the suite stays within CI's time: it still checks the
// start of the flow. Under the sanitizer preset the budget shrinks with the fraction (0.02 / 0.25).
constexpr double kWorkBudget = 1.0e7;

/// The end time of a case's short run: the fraction of its end, cut to the work budget.
double short_end(const scene::Scene& s) {
  const double fraction = test::short_runs() ? 0.02 : 0.25;
  const auto [fluid, dt] = scene::with_dimension(s, [&](auto dim) {
    const auto sim = scene::build_simulation<decltype(dim)::value>(s);
    return std::pair<double, double>(static_cast<double>(sim.diagnostics().fluid), sim.dt());
  });
  // A 3D particle-step costs about four 2D ones (53-55 neighbours against 20, docs/PERFORMANCE.md "Three
  // dimensions"): the budget counts 2D-equivalent work.
  const double cost = scene::dimension(s) == 3 ? 4.0 : 1.0;
  const double budget = fraction / 0.25 * kWorkBudget / cost;
  return std::min(fraction * s.time.end, budget / fluid * dt);
}

template <int D>
void run_case(const scene::Scene& s, const scene::RunOptions& options) {
  scene::RunnerT<D> runner(s, options);
  runner.run();
}

class CaseRegression : public testing::TestWithParam<std::string> {};

TEST_P(CaseRegression, ShortRunConservesMassAndFollowsTheFullRun) {
  const std::string name = GetParam();
  const fs::path scene_path = scene_of(name);
  ASSERT_FALSE(scene_path.empty()) << "no case file for the reference " << name;
  const Series ref = read_series(kReferences / (name + ".csv"));
  ASSERT_GT(ref.rows.size(), 4u) << name;

  scene::Scene s = scene::load_scene(scene_path);
  const double full_end = s.time.end;
  s.time.output_interval = s.time.interval();  // the full run's (its default follows the end time)
  s.time.end = short_end(s);
  s.output.frames = false;
  const test::TempFolder tmp;
  scene::RunOptions options;
  options.folder = tmp.path() / "run";
  scene::with_dimension(s, [&](auto dim) { run_case<decltype(dim)::value>(s, options); });
  const Series got = read_series(options.folder / "series.csv");
  ASSERT_GT(got.rows.size(), 1u);

  // Mass: exactly the initial mass in every row, and the reference's.
  const std::size_t mass = got.column("mass");
  ASSERT_LT(mass, got.columns.size());
  const double m0 = got.rows.front()[mass];
  EXPECT_EQ(m0, ref.rows.front()[ref.column("mass")]);
  for (const auto& row : got.rows) {
    EXPECT_EQ(row[mass], m0) << "t = " << row[0];
  }

  // Probes, row by row, against the reference interpolated at the row's time (a rounding-level change can move
  // an output row by a step; the last row of the short run ends on a capped step and is skipped).
  const scene::Probes probes(s);
  const double length_tol = 0.5 * scene::coarsest_spacing(s);
  const double pressure_tol = 0.05 * s.material.rho0 * scene::gravity_magnitude(s) * fluid_height(s);
  const std::size_t ref_time = ref.column("time");
  auto reference_at = [&](std::size_t column, double t) {
    std::size_t r = 1;
    while (r + 1 < ref.rows.size() && ref.rows[r][ref_time] < t) ++r;
    const auto& a = ref.rows[r - 1];
    const auto& b = ref.rows[r];
    const double span = b[ref_time] - a[ref_time];
    const double w = span > 0.0 ? std::clamp((t - a[ref_time]) / span, 0.0, 1.0) : 0.0;
    if (std::isnan(a[column]) || std::isnan(b[column])) return w < 0.5 ? a[column] : b[column];
    return a[column] + w * (b[column] - a[column]);
  };
  std::size_t compared = 0;
  for (std::size_t r = 0; r + 1 < got.rows.size(); ++r) {
    const double t = got.rows[r][got.column("time")];
    for (std::size_t k = 0; k < s.probes.size(); ++k) {
      const std::string& column = probes.names()[k];
      const std::size_t cg = got.column(column), cr = ref.column(column);
      ASSERT_LT(cg, got.columns.size()) << column;
      ASSERT_LT(cr, ref.columns.size()) << column;
      const double a = got.rows[r][cg], b = reference_at(cr, t);
      if (std::isnan(a) || std::isnan(b)) {
        EXPECT_EQ(std::isnan(a), std::isnan(b)) << name << " " << column << " at t = " << t;
        continue;
      }
      const double tol = s.probes[k].kind == scene::ProbeKind::pressure ? pressure_tol : length_tol;
      EXPECT_NEAR(a, b, tol) << name << ": probe " << column << " at t = " << t;
      ++compared;
    }
  }
  if (!s.probes.empty()) {
    EXPECT_GT(compared, 0u) << name;
  }
  std::printf("[case] %s: t_end %.3g of %.3g s, %zu rows, %zu probe values compared (length tol %.3g m, pressure "
              "tol %.3g Pa)\n",
              name.c_str(), s.time.end, full_end, got.rows.size(), compared, length_tol, pressure_tol);
}

INSTANTIATE_TEST_SUITE_P(Cases, CaseRegression, testing::ValuesIn(reference_names()),
                         [](const testing::TestParamInfo<std::string>& param_info) {
                           std::string n = param_info.param;
                           std::replace_if(n.begin(), n.end(), [](char c) { return !std::isalnum(c); }, '_');
                           return n;
                         });

TEST(CaseReferences, EveryCaseHasAReference) {
  // A new case file without a reference would silently escape the regression.
  std::vector<std::string> missing;
  for (const fs::path& dir : {kRoot / "cases", kRoot / "cases" / "validation"}) {
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().extension() != ".json") continue;
      if (!fs::exists(kReferences / (e.path().stem().string() + ".csv"))) missing.push_back(e.path().filename());
    }
  }
  EXPECT_TRUE(missing.empty()) << "run tools/case_references.py for: " << testing::PrintToString(missing);
}

}  // namespace
