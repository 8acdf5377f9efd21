#!/usr/bin/python3
"""The still tank's pressure offset against its two predicted terms (docs/METHOD.md, "The unrefined tank's own
pressure offset").

    /usr/bin/python3 tools/still_tank_offset.py [SPHREFINE]

Runs cases/still_tank.json (2D) at mach factors 10, 20 and 40 for its 10 s, frames every 0.05 s, and
cases/still_tank_3d.json for its 2 s, frames every 0.02 s, as it is (h = 1.2 d, mach factor 10) and at the peer's
3D settings (DualSPHysics' CaseDambreak: h = sqrt(3) d, coefsound 20), one thread each, and prints, per run, the mean pressure
of a band one spacing either side of mid-depth and of the floor row, away from the side walls, over ratio to
rho0 g (depth - z), time-averaged over the run's second half (many periods of the tank's compression mode),
beside the prediction 1 / N + 2 g depth / c0^2: N the cubic spline's gradient normalisation on the lattice at
the run's h / d (-sum_j V_j z_ij dW/dz, summed here), depth the band's mean depth.
"""
import glob
import itertools
import json
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
G = 9.81


def normalisation(dim, h_factor=1.2):
    """-sum_j V_j z_ij dW/dz over the unit lattice for the cubic spline (PHYSICS.md)."""
    h = h_factor
    sigma = 10 / (7 * math.pi * h * h) if dim == 2 else 1 / (math.pi * h ** 3)
    total = 0.0
    for idx in itertools.product(range(-3, 4), repeat=dim):
        if not any(idx):
            continue
        r = math.sqrt(sum(i * i for i in idx))
        q = r / h
        dw = sigma / h * ((-3 * q + 2.25 * q * q) if q < 1 else (-0.75 * (2 - q) ** 2) if q < 2 else 0.0)
        z = -idx[-1]  # z_ij = z_i - z_j with i at the origin
        total += -z * (z / r * dw)
    return total


def bands(folder, dim, depth, d, t0, lo, hi):
    """Time-averaged p / rho0 g (depth - z) of the mid-depth band and the floor row, and their mean depths."""
    out = {"mid": ([], []), "floor": ([], [])}
    for fn in sorted(glob.glob(os.path.join(folder, "frames", "*.h5"))):
        with h5py.File(fn, "r") as f:
            g = f[list(f.keys())[0]]
            if g.attrs["time"] < t0:
                continue
            x, p, kind = g["position"][...], g["pressure"][...], g["kind"][...]
        keep = (kind == 0) & np.all((x[:, :dim - 1] > lo) & (x[:, :dim - 1] < hi), axis=1)
        z, pk = x[keep, dim - 1], p[keep]
        for name, z0 in (("mid", depth / 2), ("floor", d / 2)):
            b = np.abs(z - z0) < d
            out[name][0].append(pk[b].sum() / (1000 * G * (depth - z[b])).sum())
            out[name][1].append(float(np.mean(depth - z[b])))
    return {k: (float(np.mean(v[0])), float(np.mean(v[1]))) for k, v in out.items()}


def run(app, scene, overrides, folder):
    cmd = [app, "run", scene, "-o", folder, "--force", "-q", "--threads", "1"]
    for o in overrides:
        cmd += ["--set", o]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(folder, "scene.json")) as f:
        return json.load(f)


def main():
    app = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "release", "app", "sphrefine")
    tmp = tempfile.mkdtemp(prefix="still_tank_offset_")
    print("| run | mid-depth: measured / predicted | floor: measured / predicted |")
    print("|---|---|---|")
    runs = [(2, "cases/still_tank.json", m, 0.05, 1.2) for m in (10, 20, 40)] + [
        (3, "cases/still_tank_3d.json", 10, 0.02, 1.2), (3, "cases/still_tank_3d.json", 20, 0.02, math.sqrt(3))]
    for dim, case, mach, frames, h_factor in runs:
        folder = os.path.join(tmp, f"{dim}d_{mach}_{h_factor:.3f}")
        s = run(app, os.path.join(ROOT, case), [f"material.mach_factor={mach}", f"output.frame_interval={frames}",
                                                f"h_factor={h_factor!r}"], folder)
        f = s["fluid"][0]
        depth, d = f["hi"][-1], f["spacing"]
        size = np.array(f["hi"][:dim - 1], dtype=float)
        m = s["material"]
        v_ref = m.get("reference_speed") or math.sqrt(2 * G * m["reference_height"])
        c0 = m["mach_factor"] * v_ref
        r = bands(folder, dim, depth, d, s["time"]["end"] / 2, 0.2 * size, 0.8 * size)
        n = normalisation(dim, h_factor)
        pred = {k: 1 / n + 2 * G * r[k][1] / c0 ** 2 for k in r}
        print(f"| {dim}D, h = {h_factor:.3g} d, mach factor {mach} | {r['mid'][0]:.4f} / {pred['mid']:.4f} | "
              f"{r['floor'][0]:.4f} / {pred['floor']:.4f} |")
    print(f"\nnormalisation at h = 1.2 d: 2D {normalisation(2):.4f}, 3D {normalisation(3):.4f}; "
          f"at h = sqrt(3) d: 3D {normalisation(3, math.sqrt(3)):.4f}")


if __name__ == "__main__":
    main()
