#!/usr/bin/python3
"""What sets the coarse step of a per-level run, read off its frames (docs/PERFORMANCE.md, "The substeps' cost
measured again, and what sets the coarse step"): for each frame, the coarse step dt0 (series.csv's dt in the row
nearest the frame's time) and, per level l present, the smallest C 2^l dt_i over its fluid (the step the level's own
limits allow), the same with the acoustic stiffness undone (C 2^l dt_i s_i), and how many of its particles are
stiffer than their own lattice by more than 5 %. With --coarse, the coarse-only run's dt at the same time.

    /usr/bin/python3 tools/step_limits.py RUN_FOLDER [--coarse COARSE_RUN_FOLDER] [--every 4]

C is the run's time.cfl (scene.json). Frames are written at synchronised instants, where every particle of a level
is in its level's bin or a finer one.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from read_output import KIND_NAMES, frame_files, load_frame, load_series  # noqa: E402

FLUID = next(k for k, name in KIND_NAMES.items() if name == "fluid")


def dt_at(series, t):
    """series.csv's dt in the row nearest time t."""
    return float(series["dt"][int(np.argmin(np.abs(series["time"] - t)))])


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
        cfl = json.load(f).get("time", {}).get("cfl")
    if cfl is None:
        sys.exit(f"{args.run}/scene.json: no time.cfl")
    series = load_series(args.run)
    coarse = load_series(args.coarse) if args.coarse else None
    paths = frame_files(args.run)
    if not paths:
        sys.exit(f"{args.run}: no frames")
    frames = [load_frame(p) for p in paths[::args.every]]
    fluid = [fr["fields"]["kind"] == FLUID for fr in frames]
    levels = sorted({int(l) for fr, f in zip(frames, fluid) for l in np.unique(fr["fields"]["level"][f])})
    header = "| t (s) | dt0 | " + " | ".join(
        f"L{l}: min C 2^l dt_i, with s_i undone, stiff > 1.05" for l in levels) + " |"
    if coarse is not None:
        header += " coarse-only run: dt |"
    print(header)
    print("|" + "---|" * (header.count("|") - 1))
    for fr, f in zip(frames, fluid):
        t = float(fr["time"])
        level = fr["fields"]["level"][f]
        limit = fr["fields"]["time_step_limit"][f]
        stiffness = fr["fields"]["acoustic_stiffness"][f]
        cells = [f"{t:.1f}", f"{dt_at(series, t):.3e}"]
        for l in levels:
            m = level == l
            if not m.any():
                cells.append("-")
                continue
            own = cfl * (2.0 ** l) * limit[m]
            undone = own * stiffness[m]
            cells.append(f"{own.min():.3e}, {undone.min():.3e}, {int((stiffness[m] > 1.05).sum())} of {int(m.sum())}")
        if coarse is not None:
            cells.append(f"{dt_at(coarse, t):.3e}")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
