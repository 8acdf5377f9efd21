#pragma once
// A cycle count of the pair sweep by kind of evaluation: an instrument for docs/PERFORMANCE.md ("The binned loop's
// own cost"), compiled in only with -DSPH_SWEEP_PROBE=ON (the `probe` preset, which tools/sweep_cycles.py builds and
// runs). Each particle's share of a sweep is timed with the processor's time-stamp counter and added to its class:
// the sweep's loop (single-rate, binned, rebin), and for a fluid particle whether it was due and its level. At exit
// the classes are written to stderr, one line each. The sums are plain, so the counts hold at one thread only
// (tools/sweep_cycles.py runs --threads 1). Without the option every call is empty and the sweep is unchanged.
#include <cstddef>
#include <cstdint>

namespace sph::probe {

enum class Loop { single = 0, binned = 1, rebin = 2 };

#ifdef SPH_SWEEP_PROBE
inline constexpr bool kEnabled = true;
std::uint64_t now();
/// One particle's share of a sweep: `fluid` false for a wall, ghost or passive particle (no sums of its own).
void record(Loop loop, bool fluid, bool due, int level, std::uint64_t cycles, std::size_t pairs,
            std::size_t candidates);
#else
inline constexpr bool kEnabled = false;
inline std::uint64_t now() { return 0; }
inline void record(Loop, bool, bool, int, std::uint64_t, std::size_t, std::size_t) {}
#endif

}  // namespace sph::probe
