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
best wall time of the process. Also the run's steps, its sweeps (substeps, run.json's sweeps), its force evaluations (run.json's
force_evaluations_per_level summed) and the level-0 evaluations per level-0 particle-second (the level_0 column
of series.csv integrated over time by the trapezoid rule over its rows): in a coarse-only run that is its steps
per second, and issue #16 asks a dynamic run's coarse particles for no more.
"""
import argparse
import csv
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
    with open(os.path.join(out, "series.csv")) as f:
        rows = list(csv.DictReader(f))
    level0_seconds = sum(0.5 * (float(a["level_0"]) + float(b["level_0"])) * (float(b["time"]) - float(a["time"]))
                         for a, b in zip(rows, rows[1:]))
    evals = j["force_evaluations_per_level"]
    return wall, (j["neighbour_candidates"], j["pair_interactions"], j["steps_this_run"], j["sweeps"], sum(evals),
                  evals[0] / level0_seconds if level0_seconds > 0 else float("nan"))


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
    print("| run | binary | candidates / pair | pairs | steps | sweeps | evaluations | level-0 evaluations / level-0 particle-s | best wall s |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec in args.runs:
            scene, *overrides = spec.split(",")
            if not os.path.exists(os.path.join(ROOT, scene)):
                sys.exit(f"{scene}: no such scene file")
            best = {a: None for a in apps}
            for _ in range(args.reps):
                for a in apps:
                    wall, counts = run_once(a, scene, overrides, os.path.join(tmp, "run"))
                    b = best[a]
                    best[a] = (min(wall, b[0]) if b else wall, counts)
            for a in apps:
                wall, (cand, pairs, steps, sweeps, evals, level0_rate) = best[a]
                print(f"| {spec} | {a} | {cand / pairs:.2f} | {pairs:.4g} | {steps} | {sweeps} | {evals:.4g} | {level0_rate:.1f} | {wall:.2f} |",
                      flush=True)


if __name__ == "__main__":
    main()
