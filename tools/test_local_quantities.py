#!/usr/bin/python3
"""ctest check of tools/local_quantities.py (the validation report's impact pressures and probe errors).

- The sliding mean on unevenly spaced samples equals a brute-force mean of the piecewise-linear signal sampled
  densely over each window (its twin); it returns a constant unchanged and a straight line unchanged away from
  the record's ends.
- A triangular pulse of height A and base b gives the raw peak A and the impulse A b / 2; its sliding mean over
  a window w <= b peaks at A (1 - w / (2 b)) (the mean of the tent over [-w/2, w/2]).
- A record that does not span the impulse window gives NaN, not a partial integral.
- A run equal to the reference plus a constant c after the reference departs has error c / range; the window
  starts where the reference first moves by 5 % of its range.

    /usr/bin/python3 tools/test_local_quantities.py
Exit status 0 on success, 1 on failure.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402
import local_quantities as lq  # noqa: E402

check = Checks("test_local_quantities")


rng = np.random.default_rng(7)

# Sliding mean against its brute-force twin, on uneven samples.
t = np.sort(np.concatenate([[0.0, 10.0], rng.uniform(0.0, 10.0, 300)]))
y = np.sin(1.3 * t) + 0.3 * rng.standard_normal(t.size)
w = 0.7
got = lq.sliding_mean(t, y, w)
worst = 0.0
for i in range(0, t.size, 7):
    lo, hi = max(t[0], t[i] - w / 2), min(t[-1], t[i] + w / 2)
    dense = np.linspace(lo, hi, 20001)
    ref = np.trapz(np.interp(dense, t, y), dense) / (hi - lo)
    worst = max(worst, abs(got[i] - ref))
# The dense sampling integrates the piecewise-linear signal exactly but for the few kinks inside each of its
# 20000 intervals: a bound of (max |y| * interval), about 1e-4, is far below any real discrepancy.
check(worst < 1e-3, f"sliding mean equals the dense twin (worst {worst:.2e})")
check(np.allclose(lq.sliding_mean(t, np.full_like(t, 2.5), w), 2.5), "sliding mean of a constant")
line = lq.sliding_mean(t, 3.0 * t - 1.0, w)
inner = (t > w) & (t < 10.0 - w)
check(np.allclose(line[inner], 3.0 * t[inner] - 1.0), "sliding mean of a straight line, away from the ends")

# A triangular pulse.
A, b, t0 = 4.0, 0.2, 2.0
tt = np.linspace(0.0, 5.0, 5001)  # the vertices t0 - b/2, t0, t0 + b/2 are samples
pulse = A * np.clip(1.0 - np.abs(tt - t0) / (b / 2), 0.0, None)
peak, raw, imp = lq.impact(tt, pulse, 0.05, 1.0, 3.0)
check(abs(raw - A) < 1e-12, f"raw peak {raw} = {A}")
check(abs(imp - A * b / 2) < 1e-12, f"impulse {imp} = {A * b / 2}")
expect = A * (1.0 - 0.05 / (2 * b))  # the tent (half-base c = b/2) averaged over [-w/2, w/2]: A (1 - w / (4 c))
check(abs(peak - expect) < 1e-9, f"sliding-mean peak {peak} = {expect}")
check(all(np.isnan(v) for v in lq.impact(tt, pulse, 0.05, 1.0, 6.0)), "a record short of the window gives NaN")

# Probe error and its window.
tr = np.linspace(0.0, 4.0, 401)
ref = np.where(tr < 1.0, 10.0, 10.0 + 2.0 * (tr - 1.0))  # at rest until t = 1, then a ramp to 16
run = ref + np.where(tr >= 1.0, 0.3, 0.0)
err, start, end = lq.probe_error(tr, run, tr, ref)
# 5 % of the range 6 is 0.3, reached at t = 1.15: the first sample past it (1.15 or 1.16, by rounding).
check(1.15 - 1e-9 <= start <= 1.16 + 1e-9, f"window starts at the 5 % departure, t = 1.15 ({start})")
check(abs(end - 4.0) < 1e-12, "window ends with the records")
ref_start = 10.0 + 2.0 * (start - 1.0)
check(abs(err - 0.3 / (16.0 - ref_start)) < 1e-12, f"error = offset / range over the window ({err})")
err2, _, end2 = lq.probe_error(tr, run, tr, ref, t_end=2.0)
check(abs(end2 - 2.0) < 1e-12 and abs(err2 - 0.3 / (12.0 - ref_start)) < 1e-9, f"t_end shortens the window ({err2})")
err3, start3, _ = lq.probe_error(tr, run, tr, ref, t_start=3.0)
check(start3 == 3.0 and abs(err3 - 0.3 / 2.0) < 1e-9, f"a later t_start moves the window's start ({err3})")
check(lq.probe_error(tr, ref, tr, ref)[0] == 0.0, "a run equal to its reference has error 0")

sys.exit(check.status())
