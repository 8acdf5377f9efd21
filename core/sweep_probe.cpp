#include "core/sweep_probe.hpp"

#ifdef SPH_SWEEP_PROBE
#include <array>
#include <cstdio>
#include <x86intrin.h>

namespace sph::probe {
namespace {

// Per loop: due fluid particles of level 0, 1 and 2 or finer; fluid particles not due with a due partner, and
// without one; the other rows (walls, ghosts, passive particles).
constexpr int kClasses = 6;
constexpr const char* kLoopNames[3] = {"single", "binned", "rebin"};
constexpr const char* kClassNames[kClasses] = {"due_L0", "due_L1", "due_L2+", "not_due_paired", "not_due_alone",
                                               "not_fluid"};

struct Totals {
  std::uint64_t rows = 0, cycles = 0, pairs = 0, candidates = 0;
};

struct Table {
  std::array<std::array<Totals, kClasses>, 3> t{};
  ~Table() {
    for (int l = 0; l < 3; ++l)
      for (int c = 0; c < kClasses; ++c) {
        const Totals& x = t[static_cast<std::size_t>(l)][static_cast<std::size_t>(c)];
        if (x.rows == 0) continue;
        std::fprintf(stderr, "sweep_probe %s %s rows %llu cycles %llu pairs %llu candidates %llu\n", kLoopNames[l],
                     kClassNames[c], static_cast<unsigned long long>(x.rows),
                     static_cast<unsigned long long>(x.cycles), static_cast<unsigned long long>(x.pairs),
                     static_cast<unsigned long long>(x.candidates));
      }
  }
};

Table table;

}  // namespace

std::uint64_t now() { return __rdtsc(); }

void record(Loop loop, bool fluid, bool due, int level, std::uint64_t cycles, std::size_t pairs,
            std::size_t candidates) {
  int c = 5;
  if (fluid) c = due ? (level < 2 ? level : 2) : (pairs > 0 ? 3 : 4);
  Totals& x = table.t[static_cast<std::size_t>(loop)][static_cast<std::size_t>(c)];
  ++x.rows;
  x.cycles += cycles;
  x.pairs += pairs;
  x.candidates += candidates;
}

}  // namespace sph::probe
#endif
