#!/usr/bin/python3
"""Field errors of a run against a reference run, from their HDF5 frames (issue #17).

Each frame's particles are sampled on one fixed lattice of points (the same for every run of a case) with the
run's own kernel (the cubic spline, support 2h, PHYSICS.md):

    phi(x) = sum_j V_j W(x - x_j, h_j)           the volume fraction (1 inside the fluid, 0 outside)
    q_v(x) = sum_j V_j v_j W(x - x_j, h_j)       phi times the velocity there
    q_p(x) = sum_j V_j p_j W(x - x_j, h_j)       phi times the pressure there

with V_j = m_j / rho_j. Weighted by phi, the fields are continuous across the free surface, so a surface in the
wrong place shows as an error of the size of the field there, and no point needs a wet/dry decision.

The errors over a window of frames, each normalised by the range of the reference's own signal:

    E_v   = sqrt( sum_t sum_x |q_v - q_v,ref|^2 / sum_t sum_x phi_ref ) / max_{t,x} |q_v,ref|
    E_p   = sqrt( sum_t sum_x (q_p - q_p,ref)^2 / sum_t sum_x phi_ref ) / (max - min)_{t,x} q_p,ref
    E_phi = sqrt( sum_t sum_x (phi - phi_ref)^2 / sum_t sum_x phi_ref )        (phi ranges over [0, 1])

The denominators sum_x phi_ref count the lattice points the reference's fluid covers, so each is an RMS over the
fluid, not over the empty air of the box. Frames are paired by index: every run writes its frames at the same
output interval (each at the first step past the output time, within one time step of the others).

    /usr/bin/python3 tools/field_error.py RUN_FOLDER REFERENCE_FOLDER --spacing S [--window T0 T1]
"""
import argparse
import math
import os
import sys

import h5py
import numpy as np


def frame_paths(folder):
    d = os.path.join(folder, "frames")
    return sorted(os.path.join(d, n) for n in os.listdir(d) if n.startswith("frame_") and n.endswith(".h5"))


def read_fluid(path):
    """time and the fluid particles' position, h, volume, velocity and pressure of one frame."""
    with h5py.File(path, "r") as f:
        g = f[list(f.keys())[0]]
        fluid = g["kind"][...] == 0
        x = g["position"][...][fluid]
        h = g["smoothing_length"][...][fluid]
        vol = g["mass"][...][fluid] / g["density"][...][fluid]
        v = g["velocity"][...][fluid]
        p = g["pressure"][...][fluid]
        return float(g.attrs["time"]), x, h, vol, v, p


class Lattice:
    """The sample points: spacing s over the box [lo, hi] (corners included)."""

    def __init__(self, lo, hi, s):
        self.lo = np.asarray(lo, dtype=float)
        self.s = float(s)
        self.n = (np.floor((np.asarray(hi, dtype=float) - self.lo) / s).astype(int) + 1)  # points along x, y

    def sample(self, x, h, vol, v, p):
        """phi, q_v (two components) and q_p on the lattice, as arrays of shape (ny, nx)."""
        nx, ny = int(self.n[0]), int(self.n[1])
        phi = np.zeros(ny * nx)
        qv = np.zeros((ny * nx, 2))
        qp = np.zeros(ny * nx)
        if len(x) == 0:
            return phi.reshape(ny, nx), qv.reshape(ny, nx, 2), qp.reshape(ny, nx)
        # Each particle reaches the points within 2 h_j: loop over the offsets of the widest stencil, vectorised
        # over the particles (kernel values beyond the support are zero).
        reach = int(math.ceil(2.0 * float(h.max()) / self.s)) + 1
        base = np.rint((x - self.lo) / self.s).astype(int)
        sigma = 10.0 / (7.0 * math.pi * h * h)
        for dy in range(-reach, reach + 1):
            for dx in range(-reach, reach + 1):
                ix, iy = base[:, 0] + dx, base[:, 1] + dy
                inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
                px = self.lo[0] + ix * self.s
                py = self.lo[1] + iy * self.s
                q = np.hypot(x[:, 0] - px, x[:, 1] - py) / h
                w = np.where(q < 1.0, 1.0 - 1.5 * q * q + 0.75 * q ** 3,
                             np.where(q < 2.0, 0.25 * (2.0 - q) ** 3, 0.0)) * sigma
                m = inside & (w > 0.0)
                if not m.any():
                    continue
                k = iy[m] * nx + ix[m]
                vw = vol[m] * w[m]
                np.add.at(phi, k, vw)
                np.add.at(qv[:, 0], k, vw * v[m, 0])
                np.add.at(qv[:, 1], k, vw * v[m, 1])
                np.add.at(qp, k, vw * p[m])
        return phi.reshape(ny, nx), qv.reshape(ny, nx, 2), qp.reshape(ny, nx)


def sampled_frames(folder, lattice, window):
    """[(time, phi, q_v, q_p)] of the frames whose time lies in the window [t0, t1]."""
    out = []
    for path in frame_paths(folder):
        t, x, h, vol, v, p = read_fluid(path)
        if window[0] <= t <= window[1]:
            out.append((t,) + lattice.sample(x, h, vol, v, p))
    return out


def errors(run, ref):
    """E_v, E_p, E_phi (see the module's docstring) of sampled frames against the reference's, paired in order;
    the pairs are as many as the shorter list (a run the watchdog stopped covers only its part)."""
    n = min(len(run), len(ref))
    if n == 0:
        return {"E_v": float("nan"), "E_p": float("nan"), "E_phi": float("nan"), "frames": 0}
    dv = dp = dphi = cover = 0.0
    vmax, pmin, pmax = 0.0, math.inf, -math.inf
    for k in range(n):
        _, phi, qv, qp = run[k]
        _, phi_r, qv_r, qp_r = ref[k]
        dv += float(np.sum((qv - qv_r) ** 2))
        dp += float(np.sum((qp - qp_r) ** 2))
        dphi += float(np.sum((phi - phi_r) ** 2))
        cover += float(np.sum(phi_r))
        vmax = max(vmax, float(np.max(np.hypot(qv_r[..., 0], qv_r[..., 1]))))
        pmin, pmax = min(pmin, float(qp_r.min())), max(pmax, float(qp_r.max()))
    return {"E_v": math.sqrt(dv / cover) / vmax if vmax > 0 else float("nan"),
            "E_p": math.sqrt(dp / cover) / (pmax - pmin) if pmax > pmin else float("nan"),
            "E_phi": math.sqrt(dphi / cover), "frames": n}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run")
    ap.add_argument("reference")
    ap.add_argument("--spacing", type=float, required=True, help="the lattice's spacing (m)")
    ap.add_argument("--box", type=float, nargs=4, metavar=("X0", "Y0", "X1", "Y1"),
                    help="the sampled box (default: the reference's fluid over every frame)")
    ap.add_argument("--window", type=float, nargs=2, default=(0.0, math.inf), metavar=("T0", "T1"))
    args = ap.parse_args()
    for folder in (args.run, args.reference):
        if not os.path.isdir(os.path.join(folder, "frames")):
            sys.exit(f"{folder}: no frames/ folder (a run folder written with output.frame_interval)")
    if args.box:
        lo, hi = args.box[:2], args.box[2:]
    else:
        pts = np.concatenate([read_fluid(p)[1] for p in frame_paths(args.reference)])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
    lat = Lattice(lo, hi, args.spacing)
    window = tuple(args.window)
    e = errors(sampled_frames(args.run, lat, window), sampled_frames(args.reference, lat, window))
    print(" ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in e.items()))


if __name__ == "__main__":
    main()
