#!/usr/bin/python3
"""The alternating-layer shear mode of a still tank, seeded (docs/METHOD.md, "Three dimensions: a lattice mode").

    /usr/bin/python3 tools/layer_shear_mode.py [--scene cases/still_tank_3d.json] [--h 1.0,1.2,1.3,1.5]
                                               [--seed-at 0.2] [--end 1.2] [--seed 1e-3] [--jobs 2]
                                               [--out results/layer_shear_mode]

For each h_factor: runs the scene unrefined to --seed-at with a checkpoint, adds to every fluid particle's
velocity (and the integrator's half-step and step-start copies) seed (-1)^layer sin(2 pi x / L) along x (layer:
the particle's lattice row in the vertical, L: the fluid's length; the sine vanishes at the end walls), resumes to
--end, and prints per h the largest speed before the seed and after it, and the mode's amplitude (the fluid's
x-velocity projected on that shape) at eleven times from the seed to the end. The stiffness whose sign decides the mode's fate is
CubicSpline::layer_shear_stiffness (core/kernel.hpp); this measures what the solver does.
The environment variable SPH_APP names another sphrefine binary.
"""
import argparse
import json
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
APP = os.environ.get("SPH_APP", os.path.join(ROOT, "build", "release", "app", "sphrefine"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from read_output import frame_files, load_frame, load_series  # noqa: E402


def shape(x, spacing, length):
    """(-1)^layer sin(2 pi x / L) per particle; x is N x D, the last axis up."""
    layer = np.rint(x[:, -1] / spacing - 0.5).astype(int)
    return np.where(layer % 2 == 0, 1.0, -1.0) * np.sin(2.0 * np.pi * x[:, 0] / length)


def run_one(h, args, spacing, length):
    out = os.path.join(args.out, f"h{h:g}")
    common = ["--threads", "1", "-q", "--set", f"h_factor={h}", "--set", "output.frame_interval=0.05"]
    r = subprocess.run([APP, "run", args.scene, "-o", out, "--force", "--set", f"time.end={args.seed_at}",
                        "--checkpoint-every", f"{args.seed_at}"] + common, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"h = {h}: the run to the seed failed: {r.stderr.strip()}")
    checkpoint = os.path.join(out, "checkpoint.h5")
    with h5py.File(checkpoint, "r+") as f:
        g = f["checkpoint"]
        fluid = g["kind"][:] == 0
        u = args.seed * shape(g["position"][:], spacing, length) * fluid
        for name in ("velocity", "velocity_half", "velocity_at_step_start"):
            v = g[name][:]
            v[:, 0] += u
            g[name][...] = v
    r = subprocess.run([APP, "run", args.scene, "-o", out, "--resume", checkpoint, "--set", f"time.end={args.end}"]
                       + common, capture_output=True, text=True)
    if r.returncode not in (0, 1):  # 1: the watchdog stopped the run (run.json says why)
        sys.exit(f"h = {h}: the resumed run failed: {r.stderr.strip()}")
    return out


def amplitude(frame, spacing, length):
    d = frame["fields"]
    fluid = d["kind"] == 0
    s = shape(d["position"][fluid], spacing, length)
    return float((d["velocity"][fluid, 0] * s).sum() / (s * s).sum())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=os.path.join(ROOT, "cases", "still_tank_3d.json"))
    ap.add_argument("--h", default="1.0,1.2,1.3,1.5")
    ap.add_argument("--seed-at", type=float, default=0.2)
    ap.add_argument("--end", type=float, default=1.2)
    ap.add_argument("--seed", type=float, default=1e-3)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "layer_shear_mode"))
    args = ap.parse_args()
    # The scene's first fluid region gives the lattice spacing and the fluid's length along x (comments stripped).
    with open(args.scene) as f:
        scene = json.loads(re.sub(r"^\s*//.*$", "", f.read(), flags=re.M))
    region = scene["fluid"][0]
    spacing = float(region["spacing"])
    length = float(region["hi"][0]) - float(region["lo"][0])
    hs = [float(h) for h in args.h.split(",")]
    every = max(0.05, round((args.end - args.seed_at) / 10.0 / 0.05) * 0.05)  # a multiple of the frames' 0.05 s
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        outs = list(pool.map(lambda h: run_one(h, args, spacing, length), hs))
    print(f"{os.path.relpath(args.scene, ROOT)}: {args.seed:g} m/s of the alternating-layer shear mode at "
          f"t = {args.seed_at:g} s, then to {args.end:g} s; one thread\n")
    print("| h / d | status | max \\|v\\| before the seed | max \\|v\\| after (time) "
          f"| mode amplitude every {every:g} s from the seed |")
    print("|---|---|---|---|---|")
    for h, out in zip(hs, outs):
        with open(os.path.join(out, "run.json")) as f:
            status = json.load(f).get("status", "?")
        s = load_series(out)
        t, v = s["time"], s["max_speed"]
        before, after = t <= args.seed_at + 1e-9, t > args.seed_at + 1e-9
        k = int(np.argmax(np.where(after, v, -1.0)))
        amps = []
        for path in frame_files(out):
            fr = load_frame(path)
            step = (fr["time"] - args.seed_at) / every
            if fr["time"] >= args.seed_at - 1e-9 and abs(step - round(step)) < 0.02:
                amps.append(amplitude(fr, spacing, length))
        print(f"| {h:g} | {status} | {v[before].max():.2g} | {v[k]:.2g} ({t[k]:.2f} s) | "
              + ", ".join(f"{a:.2g}" for a in amps) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
