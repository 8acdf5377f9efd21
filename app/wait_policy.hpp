#pragma once
// How OpenMP's idle threads wait, chosen by the program unless the user's environment chooses.
//
// A thread that reaches a barrier before the others waits for them. By default it spins (libgomp polls
// ~300,000 times before it sleeps; clang's libomp spins for 200 ms). On quiet cores that is fastest. On cores
// that other work also uses, the thread being waited for may not be running at all, and the waiters burn the
// time it needs: a step with a few parallel regions then costs scheduler time slices instead of microseconds
// (the paper's dam break, two threads, two busy cores: 36 s instead of 2 s). A passive policy (sleep at once)
// holds up under that load at the price of a futex wake per barrier, measured in docs/PERFORMANCE.md ("Busy
// cores").
//
// The runtime reads its policy once, when it is loaded, before main() runs: setting the variable in main()
// is too late. So the program sets it and starts itself again (exec of /proc/self/exe with the same
// arguments) before it does anything else. Nothing is repeated: the second start finds the variable set.
namespace sph::app {

/// The variables that express a user's choice of wait policy; if any is set, the program leaves it alone.
inline constexpr const char* kWaitPolicyVariables[] = {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT", "KMP_BLOCKTIME"};

/// Sets OMP_WAIT_POLICY=passive and re-executes the program, unless the environment already chooses a
/// policy. Returns only if it did not re-execute (a choice was set, or exec failed: the run then goes on
/// with the runtime's default).
void ensure_wait_policy(char** argv);

}  // namespace sph::app
