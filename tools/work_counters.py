#!/usr/bin/python3
"""Neighbour work and wall time of whole runs, one at a time (nothing beside them), best of N: the table of
docs/PERFORMANCE.md, "One grid layer per level".

    /usr/bin/python3 tools/work_counters.py [--reps 3] [--app A.exe --app B.exe ...] RUN [RUN ...]

A RUN is a scene file followed by its --set overrides, separated by commas:
    cases/dam_break_aap.json,time.stepping=per_level
Each --app is a sphrefine binary (default: build/release/app/sphrefine); with several, the runs alternate
between them (A, B, A, B, ...) so that the machine's drift falls on both alike. One thread per run. Prints one
markdown row per run and binary: candidates checked per pair evaluated and pairs (run.json's
neighbour_candidates and pair_interactions, the same at every repetition: the runs are deterministic), and the
best wall time of the process. Exit status 1 when a run fails.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run_once(app, scene, overrides, out):
    cmd = [app, "run", os.path.join(ROOT, scene), "-o", out, "--force", "-q", "--threads", "1"]
    for o in overrides:
        cmd += ["--set", o]
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr.strip()}")
    with open(os.path.join(out, "run.json")) as f:
        j = json.load(f)
    return wall, j["neighbour_candidates"], j["pair_interactions"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--app", action="append")
    args = ap.parse_args()
    apps = args.app or [os.path.join(ROOT, "build", "release", "app", "sphrefine")]
    for a in apps:
        if not os.access(a, os.X_OK):
            sys.exit(f"--app {a}: not an executable")
    print("| run | binary | candidates / pair | pairs | best wall s |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec in args.runs:
            scene, *overrides = spec.split(",")
            if not os.path.exists(os.path.join(ROOT, scene)):
                sys.exit(f"{scene}: no such scene file")
            best = {a: None for a in apps}
            for _ in range(args.reps):
                for a in apps:
                    wall, cand, pairs = run_once(a, scene, overrides, os.path.join(tmp, "run"))
                    b = best[a]
                    best[a] = (min(wall, b[0]) if b else wall, cand, pairs)
            for a in apps:
                wall, cand, pairs = best[a]
                print(f"| {spec} | {a} | {cand / pairs:.2f} | {pairs:.4g} | {wall:.2f} |", flush=True)


if __name__ == "__main__":
    main()
