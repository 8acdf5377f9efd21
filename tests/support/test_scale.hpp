#pragma once
// Long physical runs are shortened under the sanitizer preset (SPH_TEST_SCALE=short, set by the asan
// test preset): the same checks run over a shorter window there; the release suite runs them in full.
#include <cstdlib>
#include <cstring>

namespace sph::test {

inline bool short_runs() {
  const char* s = std::getenv("SPH_TEST_SCALE");
  return s != nullptr && std::strcmp(s, "short") == 0;
}

}  // namespace sph::test
