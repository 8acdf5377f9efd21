#!/usr/bin/python3
"""ctest check of tools/acoustic_amplification.py, the linear analysis behind time.predictor (docs/METHOD.md, "The
predictor", and AcousticLimit in core/sweep.hpp).

- The last-rate step grows a mode by z^4/4 to leading order (the derivation in docs/METHOD.md, "Time step and three
  refinement levels"): at z = 0.02 the next term is of relative order z^2 ~ 4e-4, so 1 % is ample.
- The extrapolated step damps every mode from z -> 0 up to its damping limit, and grows them beyond.
- The limit lies above kMaxZ / 0.75 = 0.667 (the bound core/sweep.hpp's AcousticLimit::kMaxZ = 0.5 is three
  quarters of) to the resolution of damping_limit's search (1e-3 of z over 2/4000 steps, i.e. 5e-4).

    /usr/bin/python3 tools/test_acoustic_amplification.py
Exit status 0 on success, 1 on failure.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import acoustic_amplification as aa  # noqa: E402
from checks import Checks  # noqa: E402

check = Checks("test_acoustic_amplification")

z = 0.02
g = aa.growth(z, extrapolated=False)
check(abs(g / (z ** 4 / 4) - 1.0) < 0.01, f"last_rate: growth {g:.4e} at z = {z}, z^4/4 = {z ** 4 / 4:.4e}")

limit = aa.damping_limit()
for zz in np.linspace(0.01, limit - 0.01, 40):
    gz = aa.growth(zz, extrapolated=True)
    check(gz < 0.0, f"extrapolated: growth {gz:+.3e} at z = {zz:.3f}, below the damping limit {limit:.3f}")
for zz in (limit + 0.01, 0.8, 1.0):
    check(aa.growth(zz, extrapolated=True) > 0.0, f"extrapolated: no growth at z = {zz:.3f} beyond the limit")
check(limit >= 0.5 / 0.75 - 5e-4, f"the damping limit {limit:.4f} is below kMaxZ / 0.75")


sys.exit(check.status())
