// sphrefine: command-line front end (thin over core/).
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/case_builder.hpp"

int main(int argc, char** argv) {
  const std::string name = argc > 1 ? argv[1] : "dam_break";
  if (name != "dam_break") {
    std::fprintf(stderr, "sphrefine: unknown case '%s'\n", name.c_str());
    return 2;
  }
  sph::DamBreakSpec spec;
  sph::Simulation sim = sph::make_dam_break(spec);
  const double H0 = spec.column_height, g = 9.81;
  const double t_end = 2.0 * std::sqrt(H0 / g);
  const auto t0 = std::chrono::steady_clock::now();
  double next_print = 0.0;
  while (sim.time() < t_end) {
    sim.step(t_end - sim.time());
    sim.run_stages();
    if (sim.time() >= next_print) {
      const auto d = sim.diagnostics();
      std::printf("t*=%.3f step=%llu dt=%.3e fluid=%zu ghosts=%zu |v|max=%.3f drho=%.4f mass=%.6e\n",
                  sim.time() / std::sqrt(H0 / g), static_cast<unsigned long long>(d.step), d.dt, d.fluid,
                  d.ghosts, d.max_speed, d.max_density_error, d.mass);
      next_print += 0.1 * std::sqrt(H0 / g);
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("done: %llu steps in %.3f s\n", static_cast<unsigned long long>(sim.step_count()), wall);
  return 0;
}
