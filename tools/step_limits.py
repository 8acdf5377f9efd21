#!/usr/bin/python3
"""What sets the coarse step of a per-level run, read off its frames (docs/PERFORMANCE.md, "What sets the coarse
step"): for each frame, the coarse step dt0 (series.csv's dt at the frame's time) and, per level, the smallest
C 2^l dt_i (the step the level's own limits allow), the same with the acoustic stiffness undone (C 2^l dt_i s_i),
and how many of the level's particles are stiffer than their own lattice by more than 5 %. With --coarse, the
coarse-only run's smallest C dt_i at the same frame, the step it took.

    /usr/bin/python3 tools/step_limits.py RUN_FOLDER [--coarse COARSE_RUN_FOLDER] [--every 4]

C is read from the run's scene.json (time.cfl). Frames are written at synchronised instants, where every particle
of a level is in its level's bin or a finer one.
"""
import argparse
import csv
import glob
import json
import os
import sys

import h5py
import numpy as np

FLUID = 0  # Kind::fluid


def frames(folder):
    return sorted(glob.glob(os.path.join(folder, "frames", "frame_*.h5")))


def read(path):
    with h5py.File(path, "r") as f:
        g = f[next(iter(f.keys()))]
        fluid = g["kind"][:] == FLUID
        return {k: g[k][:][fluid] for k in ("level", "time_bin", "time_step_limit", "acoustic_stiffness")}


def series_dt(folder):
    with open(os.path.join(folder, "series.csv")) as f:
        return [(float(r["time"]), float(r["dt"])) for r in csv.DictReader(f)]


def dt_at(rows, t):
    return min(rows, key=lambda r: abs(r[0] - t))[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run")
    ap.add_argument("--coarse")
    ap.add_argument("--every", type=int, default=4, help="every n-th frame")
    args = ap.parse_args()
    for folder in [args.run] + ([args.coarse] if args.coarse else []):
        for name in ("scene.json", "series.csv"):
            if not os.path.isfile(os.path.join(folder, name)):
                sys.exit(f"{folder}: no {name} (a run folder written by sphrefine run is needed)")
    with open(os.path.join(args.run, "scene.json")) as f:
        scene = json.load(f)
    try:
        cfl = scene["time"]["cfl"]
        frame_dt = scene["output"]["frame_interval"]  # frame k is at t = k frame_dt (a run from t = 0, not resumed)
    except KeyError as e:
        sys.exit(f"{args.run}/scene.json: no {e} (time.cfl and output.frame_interval are needed)")
    rows = series_dt(args.run)
    coarse_rows = series_dt(args.coarse) if args.coarse else None
    paths = frames(args.run)
    if not paths:
        sys.exit(f"{args.run}: no frames")
    header = "| t (s) | dt0 | " + " | ".join(
        f"L{l}: min C 2^l dt_i, with s_i undone, stiff > 1.05" for l in (0, 1)) + " |"
    if args.coarse:
        header += " coarse-only run: dt |"
    print(header)
    print("|" + "---|" * (header.count("|") - 1))
    for k in range(0, len(paths), args.every):
        t = k * frame_dt
        fr = read(paths[k])
        cells = [f"{t:.1f}", f"{dt_at(rows, t):.3e}"]
        for level in (0, 1):
            m = fr["level"] == level
            if not m.any():
                cells.append("-")
                continue
            own = cfl * (2.0 ** level) * fr["time_step_limit"][m]
            undone = own * fr["acoustic_stiffness"][m]
            stiff = int((fr["acoustic_stiffness"][m] > 1.05).sum())
            cells.append(f"{own.min():.3e}, {undone.min():.3e}, {stiff} of {int(m.sum())}")
        if coarse_rows:
            cells.append(f"{dt_at(coarse_rows, t):.3e}")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
