#pragma once
// Keeps large freed blocks in the heap instead of returning them to the kernel. The solver's per-pass
// workspaces (refinement, output) are tens of megabytes at 1e6 particles; with glibc's defaults each one is
// a fresh mmap whose pages fault in on first touch, which made a split pass cost 2-10x more and vary from
// run to run. Called once at program start: first thing in the program's main (app/main.cpp), and at static
// initialisation in every benchmark executable (bench/), so that the benchmarks measure the set-up the program
// runs with. The tests do not call it: it changes where memory comes from, never a computed value.
#include <malloc.h>

namespace sph {

inline void tune_allocator() {
  mallopt(M_MMAP_THRESHOLD, 1 << 30);  // serve large blocks from the heap
  mallopt(M_TRIM_THRESHOLD, -1);       // and do not give the top of the heap back
}

}  // namespace sph
