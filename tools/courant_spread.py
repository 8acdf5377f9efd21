#!/usr/bin/python3
"""How much a probe's error against a reference moves when only the Courant number changes: the spread that
tells a real difference between two variants from a single run's luck. For docs/PERFORMANCE.md, "At unchanged
accuracy: the probes' spread" (issue #16).

    /usr/bin/python3 tools/courant_spread.py --reference SCENE [--courant 0.1,0.15,0.18,0.2] [--probe H ...] RUN [RUN ...]

A RUN is a scene file followed by its --set overrides, separated by commas, as for tools/work_counters.py:
    cases/dam_break_aap.json,time.stepping=per_level
Each RUN is run once at each Courant number (time.cfl), the reference once at its scene's own; two at a time,
one thread each (nothing here is timed). For each probe (default H): its RMS difference from the reference over
the reference's window, divided by the reference's range there (tools/local_quantities.py, probe_error: the
validation report's definition; the window runs from the reference's departure from its initial value to the
end). Prints one markdown row per RUN: the error at each Courant number, then their mean, smallest and largest.

A probe that follows one particle (the water height at a wall is the top of the highest particle in a band one
coarse spacing wide) differs from run to run by that particle's path: a change of the time step that leaves the
flow's physics as it was moves it. Two variants differ in accuracy where their ranges over the Courant numbers
part, not where two single runs do.
"""
import argparse
import concurrent.futures
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import local_quantities as lq  # noqa: E402
from read_output import load_series  # noqa: E402


def run(app, scene, overrides, out):
    cmd = [app, "run", os.path.join(ROOT, scene), "-o", out, "--force", "-q", "--threads", "1"]
    for o in overrides:
        cmd += ["--set", o]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {r.stderr.strip()}")
    return load_series(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--reference", required=True, help="the reference scene (run at its own Courant number)")
    ap.add_argument("--courant", default="0.1,0.15,0.18,0.2", help="comma-separated Courant numbers")
    ap.add_argument("--probe", action="append", help="a series.csv column (default: H)")
    ap.add_argument("--app", default=os.path.join(ROOT, "build", "release", "app", "sphrefine"))
    args = ap.parse_args()
    probes = args.probe or ["H"]
    if not os.access(args.app, os.X_OK):
        sys.exit(f"--app {args.app}: not an executable (build the release preset first)")
    try:
        args.courant = [float(c) for c in args.courant.split(",")]
    except ValueError:
        sys.exit(f"--courant {args.courant}: not a comma-separated list of numbers")
    for c in args.courant:
        if not 0.0 < c <= 1.0:
            sys.exit(f"--courant {c:g}: must lie in (0, 1]")
    specs = [s.split(",") for s in args.runs]
    for spec in specs + [[args.reference]]:
        if not os.path.exists(os.path.join(ROOT, spec[0])):
            sys.exit(f"{spec[0]}: no such scene file")
    with tempfile.TemporaryDirectory() as tmp, concurrent.futures.ThreadPoolExecutor(2) as pool:
        ref_job = pool.submit(run, args.app, args.reference, [], os.path.join(tmp, "reference"))
        jobs = {}
        for r, spec in enumerate(specs):
            for k, c in enumerate(args.courant):
                out = os.path.join(tmp, f"run{r}_{k}")
                jobs[(r, k)] = pool.submit(run, args.app, spec[0], spec[1:] + [f"time.cfl={c}"], out)
        try:
            ref = ref_job.result()
            res = {key: job.result() for key, job in jobs.items()}
        except RuntimeError as e:
            sys.exit(str(e))
    for probe in probes:
        if probe not in ref:
            sys.exit(f"--probe {probe}: not a column of the reference's series.csv")
        print(f"\n{probe}: RMS / range against {args.reference}\n")
        head = " | ".join(f"C = {c:g}" for c in args.courant)
        print(f"| run | {head} | mean | smallest | largest |")
        print("|---|" + "---|" * (len(args.courant) + 3))
        for r, spec in enumerate(specs):
            errs = []
            for k in range(len(args.courant)):
                s = res[(r, k)]
                errs.append(lq.probe_error(s["time"], s[probe], ref["time"], ref[probe])[0])
            cells = " | ".join(f"{100 * e:.2f} %" for e in errs)
            name = " ".join([spec[0]] + spec[1:])
            print(f"| {name} | {cells} | {100 * np.mean(errs):.2f} % | {100 * min(errs):.2f} % | "
                  f"{100 * max(errs):.2f} % |")


if __name__ == "__main__":
    main()
