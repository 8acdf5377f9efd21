#!/usr/bin/python3
"""ctest check of tools/field_error.py, the sampling behind the validation report's accuracy-against-cost charts.

- The stencil sampler (vectorised over particles, one loop over lattice offsets) equals a direct sum over every
  particle and every lattice point, on random particles of mixed smoothing lengths (its brute-force twin).
- The volume fraction phi is 1 to within the kernel's discretisation inside a regular block of particles and 0
  far from it; phi-weighted velocity over phi gives back a uniform velocity.
- The errors of a set of frames against itself are exactly 0; against frames whose velocity is scaled by
  (1 + eps), E_v = eps * RMS|q_v| / max|q_v| exactly (the definition); shifting the fluid gives E_phi > 0.

    /usr/bin/python3 tools/test_field_error.py
Exit status 0 on success, 1 on failure.
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402
import field_error  # noqa: E402

check = Checks("test_field_error")


def direct(lat, x, h, vol, v, p):
    """The same sums, point by point and particle by particle."""
    nx, ny = int(lat.n[0]), int(lat.n[1])
    phi = np.zeros((ny, nx))
    qv = np.zeros((ny, nx, 2))
    qp = np.zeros((ny, nx))
    for iy in range(ny):
        for ix in range(nx):
            px, py = lat.lo[0] + ix * lat.s, lat.lo[1] + iy * lat.s
            for j in range(len(x)):
                q = math.hypot(x[j, 0] - px, x[j, 1] - py) / h[j]
                if q < 1.0:
                    w = 1.0 - 1.5 * q * q + 0.75 * q ** 3
                elif q < 2.0:
                    w = 0.25 * (2.0 - q) ** 3
                else:
                    continue
                w *= 10.0 / (7.0 * math.pi * h[j] * h[j])
                phi[iy, ix] += vol[j] * w
                qv[iy, ix] += vol[j] * w * v[j]
                qp[iy, ix] += vol[j] * w * p[j]
    return phi, qv, qp


rng = np.random.default_rng(7)
# Brute-force twin: 60 particles with h from 0.05 to 0.4 around and beyond a 1.5 x 1 box of spacing 0.1.
n = 60
x = rng.uniform(-0.3, 1.8, size=(n, 2))
h = rng.uniform(0.05, 0.4, size=n)
vol = rng.uniform(0.005, 0.02, size=n)
v = rng.normal(size=(n, 2))
p = rng.normal(size=n)
lat = field_error.Lattice((0.0, 0.0), (1.5, 1.0), 0.1)
fast = lat.sample(x, h, vol, v, p)
slow = direct(lat, x, h, vol, v, p)
for name, a, b in zip(("phi", "q_v", "q_p"), fast, slow):
    # Both sum the same terms in different orders: equal to rounding (1e-12 of the largest value).
    check(np.allclose(a, b, rtol=0.0, atol=1e-12 * max(1.0, float(np.abs(b).max()))),
          f"stencil {name} equals the direct sum (largest difference {float(np.abs(a - b).max()):.3g})")

# A regular block of spacing d with h = 1.2 d: phi ~ 1 inside (the cubic spline's lattice sum, within 1 %), 0 far
# away; q_v / phi returns the block's uniform velocity.
d = 0.1
g = np.arange(0.0, 2.0, d) + d / 2
bx, by = np.meshgrid(g, g)
xb = np.column_stack([bx.ravel(), by.ravel()])
hb = np.full(len(xb), 1.2 * d)
vb = np.full(len(xb), d * d)
velocity = np.tile([0.3, -0.2], (len(xb), 1))
lat2 = field_error.Lattice((0.0, 0.0), (3.0, 3.0), d / 2)
phi, qv, qp = lat2.sample(xb, hb, vb, velocity, np.ones(len(xb)))
inner = phi[10:30, 10:30]  # 0.5 .. 1.5 m: more than 2h from the block's edges
check(abs(float(inner.mean()) - 1.0) < 0.01 and float(np.ptp(inner)) < 0.01,
      f"phi inside a block is 1 (mean {float(inner.mean()):.4f}, spread {float(np.ptp(inner)):.2g})")
check(float(phi[-5:, -5:].max()) == 0.0, "phi is 0 far from the block")
wet = phi > 1e-6
check(np.allclose(qv[wet] / phi[wet][:, None], [0.3, -0.2], rtol=0, atol=1e-12), "q_v / phi is the block's velocity")

# Errors: of frames against themselves, with the velocity scaled, with the fluid shifted.
frames = [(0.0, phi, qv, qp), (0.1, phi, 0.5 * qv, qp)]
e0 = field_error.errors(frames, frames)
check(e0["E_v"] == 0.0 and e0["E_p"] == 0.0 and e0["E_phi"] == 0.0, f"errors against itself are 0 ({e0})")
eps = 0.01
scaled = [(t, ph, (1 + eps) * q, pp) for t, ph, q, pp in frames]
e1 = field_error.errors(scaled, frames)
num = sum(float(np.sum(np.hypot(q[..., 0], q[..., 1]) ** 2)) for _, _, q, _ in frames)
cover = sum(float(np.sum(ph)) for _, ph, _, _ in frames)
expect = eps * math.sqrt(num / cover) / float(np.max(np.hypot(qv[..., 0], qv[..., 1])))
check(abs(e1["E_v"] - expect) <= 1e-12 * expect, f"E_v of a 1 % scaled velocity is its definition ({e1['E_v']} vs {expect})")
shifted = lat2.sample(xb + [0.3, 0.0], hb, vb, velocity, np.ones(len(xb)))
e2 = field_error.errors([(0.0,) + shifted], [(0.0, phi, qv, qp)])
check(e2["E_phi"] > 0.1, f"a block shifted by 0.3 m gives a volume-fraction error ({e2['E_phi']:.3g})")

sys.exit(check.status())
