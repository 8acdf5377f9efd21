#include "app/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <string>

namespace sph::app {

namespace {

std::string clock_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  const auto s = static_cast<long long>(seconds + 0.5);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

}  // namespace

ProgressPrinter::ProgressPrinter(std::FILE* out, bool quiet)
    : out_(out), quiet_(quiet), terminal_(isatty(fileno(out)) != 0) {}

void ProgressPrinter::operator()(const scene::Progress& p) {
  if (quiet_) return;
  const double steps_per_s = p.wall_seconds > 0.0 ? static_cast<double>(p.steps_run) / p.wall_seconds : 0.0;
  if (terminal_) {
    if (p.wall_seconds - last_wall_ < 0.25 && p.time < p.end) return;
    last_wall_ = p.wall_seconds;
  } else {
    const int tenth = static_cast<int>(std::floor(10.0 * p.time / p.end + 1e-9));
    if (tenth <= last_tenth_) return;
    last_tenth_ = tenth;
  }
  // ETA from the simulated-time rate so far (finer particles later in a run make it optimistic).
  const double rate = p.wall_seconds > 0.0 ? p.time / p.wall_seconds : 0.0;
  const double eta = rate > 0.0 ? (p.end - p.time) / rate : -1.0;
  char line[256];
  std::snprintf(line, sizeof line, "t = %.4g / %.4g s (%3.0f%%)  step %llu  particles %zu  %.0f steps/s  ETA %s",
                p.time, p.end, 100.0 * p.time / p.end, static_cast<unsigned long long>(p.step), p.fluid, steps_per_s,
                clock_text(eta).c_str());
  if (terminal_) {
    std::fprintf(out_, "\r\033[K%s", line);
    dirty_ = true;
  } else {
    std::fprintf(out_, "%s\n", line);
  }
  std::fflush(out_);
}

void ProgressPrinter::done() {
  if (dirty_) std::fputs("\n", out_);
  dirty_ = false;
  std::fflush(out_);
}

}  // namespace sph::app
