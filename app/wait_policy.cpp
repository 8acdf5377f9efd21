#include "app/wait_policy.hpp"

#include <unistd.h>

#include <cstdlib>

namespace sph::app {

void ensure_wait_policy(char** argv) {
  for (const char* name : kWaitPolicyVariables) {
    if (std::getenv(name) != nullptr) return;
  }
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);
  // exec failed (no /proc, say): carry on with the runtime's default policy. The variable stays set, so a
  // child process of this one would get the passive policy, which is harmless.
}

}  // namespace sph::app
