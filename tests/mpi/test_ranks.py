#!/usr/bin/python3
"""The same run at any rank count (issue #19): a scene run under `mpirun -np N` for N in 1..4, at 1 or 2 threads
(--configs), writes the same frames (every dataset, bit for bit, and the frame attributes) and the same time series
(every column, as text) as the run at one rank and one thread; and a checkpoint written at one rank count
resumes at another to the uninterrupted run's end, bit for bit.

usage: test_ranks.py SPHREFINE MPIEXEC SCENE OUT [--configs 1x2,2x1,...] [--set key=value ...]
                     [--resume-at T --resume-ranks A,B] [--expect-recut] [--expect-merge-across]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np


def run(args, ranks, threads, out, extra=()):
    cmd = [args.mpiexec, "--oversubscribe", "-np", str(ranks), args.sphrefine, "run", args.scene, "-o", str(out),
           "--threads", str(threads), "--quiet"] + list(extra)
    for s in args.set:
        cmd += ["--set", s]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    if p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {p.returncode}\n{p.stdout}\n{p.stderr}")


def frame_files(folder):
    return sorted((Path(folder) / "frames").glob("frame_*.h5"))


def same_frame(a, b):
    """'' when the two frame files hold the same group, attributes and datasets bit for bit, else what differs."""
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        if list(fa.keys()) != list(fb.keys()):
            return f"groups {list(fa.keys())} vs {list(fb.keys())}"
        for g in fa.keys():
            ga, gb = fa[g], fb[g]
            if dict(ga.attrs) != dict(gb.attrs):
                return f"{g} attributes {dict(ga.attrs)} vs {dict(gb.attrs)}"
            if sorted(ga.keys()) != sorted(gb.keys()):
                return f"{g} datasets differ"
            for name in ga.keys():
                x, y = ga[name][()], gb[name][()]
                if x.shape != y.shape or x.dtype != y.dtype or x.tobytes() != y.tobytes():
                    bad = ""
                    if x.shape == y.shape and x.dtype.kind == "f":
                        diff = np.argwhere(x != y)
                        bad = f"; {len(diff)} values differ, first at {diff[0].tolist() if len(diff) else None}"
                    return f"{g}/{name}: shape {x.shape} vs {y.shape}{bad}"
    return ""


def compare(reference, other, label, last_only=False):
    fa, fb = frame_files(reference), frame_files(other)
    if last_only:
        fa, fb = fa[-1:], fb[-1:]
    elif [f.name for f in fa] != [f.name for f in fb]:
        sys.exit(f"FAIL {label}: frames {[f.name for f in fa]} vs {[f.name for f in fb]}")
    if not fa:
        sys.exit(f"FAIL {label}: no frames written")
    for a, b in zip(fa, fb):
        why = same_frame(a, b)
        if why:
            sys.exit(f"FAIL {label}: {a.name} differs from the reference: {why}")
    if not last_only:
        sa = (Path(reference) / "series.csv").read_text()
        sb = (Path(other) / "series.csv").read_text()
        if sa != sb:
            la, lb = sa.splitlines(), sb.splitlines()
            first = next((k for k in range(min(len(la), len(lb))) if la[k] != lb[k]), min(len(la), len(lb)))
            sys.exit(f"FAIL {label}: series.csv differs from line {first + 1}:\n  {la[first] if first < len(la) else ''}"
                     f"\n  {lb[first] if first < len(lb) else ''}")
    print(f"ok  {label}: {len(fa)} frame(s){'' if last_only else ' and the time series'} bitwise equal")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sphrefine")
    ap.add_argument("mpiexec")
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--configs", default="1x2,2x1,2x2,3x1,4x1,4x2",
                    help="ranks x threads of the runs compared with the 1 x 1 run")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--resume-at", type=float)
    ap.add_argument("--resume-ranks", default="2,3")
    ap.add_argument("--expect-recut", action="store_true",
                    help="fail unless some run recut its cells (so that a rebalance is among what is compared)")
    ap.add_argument("--expect-merge-across", action="store_true",
                    help="fail unless the reference merged families and some run merged one whose members sat on "
                         "several ranks (so that coarsening across ranks is among what is compared)")
    args = ap.parse_args()
    out = Path(args.out)
    if out.exists():
        shutil.rmtree(out)
    configs = [tuple(int(v) for v in c.split("x")) for c in args.configs.split(",")]
    reference = out / "np1_t1"
    run(args, 1, 1, reference)
    recuts = across = 0
    for n, t in configs:
        folder = out / f"np{n}_t{t}"
        run(args, n, t, folder)
        compare(reference, folder, f"{n} rank(s) x {t} thread(s)")
        summary = json.loads((folder / "run.json").read_text())
        recuts += len(summary.get("exchange", {}).get("rebalances", []))
        across += summary.get("refinement", {}).get("merged_families_across_ranks", 0)
    merged = json.loads((reference / "run.json").read_text()).get("refinement", {}).get("merged_families", 0)
    print(f"recuts of the cells among these runs: {recuts}; families merged in the reference: {merged}, "
          f"merged with members lent across ranks among the runs: {across}")
    if args.expect_merge_across and (merged == 0 or across == 0):
        sys.exit("FAIL: no family merged across ranks, so coarsening across ranks was not compared")
    if args.expect_recut and recuts == 0:
        sys.exit("FAIL: no run recut its cells, so no rebalance was compared")
    if args.resume_at is not None:
        a, b = (int(r) for r in args.resume_ranks.split(","))
        folder = out / f"resume_np{a}_np{b}"
        run(args, a, 1, folder, ["--checkpoint-every", str(args.resume_at), "--set", f"time.end={args.resume_at}"])
        run(args, b, 2, folder, ["--resume", str(folder / "checkpoint.h5")])
        compare(reference, folder, f"checkpoint at {a} rank(s), resumed at {b}", last_only=True)


if __name__ == "__main__":
    main()
