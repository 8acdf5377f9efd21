#!/usr/bin/python3
"""Whether the dam break with a refined zone completes when nothing that matters changes: the check interval one
step either side of 100, and the Courant number 0.19; and what its energy does: the largest rise of the total energy
between output rows (a fraction of E(0); the fully refined run only ever loses energy between rows), the largest
speed and the largest density error. Buffered levels, and the paper's mixed pairs on the same runs for comparison.
docs/METHOD.md, "Buffered flows under small changes", holds the summary table this prints last.

    /usr/bin/python3 tools/buffered_robustness.py [--app build/release/app/sphrefine] [--jobs 2]
                                                  [--couplings buffered,mixed] [--patterns aap,rsp]

A coupling may carry "+coarsening" (e.g. --couplings buffered,buffered+coarsening): the zone's refinement then has
"coarsening": {} (the defaults: fluid that has left the zone merges back after the hold).
Each run: cases/dam_break_aap.json, one thread, a zone criterion with one level. Prints one markdown row per
coupling, zone, pattern and perturbation, then one row per zone and pattern with the couplings side by side. "fine
at the end" is the active level-1 fluid in the last output row (the range over the runs that complete).
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The zones of docs/METHOD.md's tables: the right-hand corner, the column's foot, the floor ahead of it, a block
# through which the whole surge passes.
ZONES = [((44, 0), (50, 6)), ((0, 0), (8, 8)), ((20, 0), (30, 5)), ((10, 0), (20, 10))]
# (check_interval, cfl): the settings of the tables, then one step either side, then a Courant number 5 % lower.
PERTURBATIONS = [(100, 0.2), (99, 0.2), (101, 0.2), (100, 0.19)]


def run(app, coupling, zone, pattern, interval, cfl, out):
    refinement = {"criterion": "zone", "zone": {"lo": list(zone[0]), "hi": list(zone[1])}, "pattern": pattern,
                  "check_interval": interval, "max_level": 1, "coupling": coupling.split("+")[0]}
    if coupling.endswith("+coarsening"):
        refinement["coarsening"] = {}
    cmd = [app, "run", os.path.join(ROOT, "cases", "dam_break_aap.json"), "-o", out, "--force", "-q", "--threads",
           "1", "--set", f"time.cfl={cfl}", "--set", "effects.refinement=" + json.dumps(refinement)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    stop = re.search(r"stopped at step \d+, t = ([0-9.]+) s", r.stderr + r.stdout)
    if r.returncode != 0 and not stop:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr.strip()}")
    with open(os.path.join(out, "series.csv")) as f:
        rows = list(csv.DictReader(f))
    energy = [float(row["total_energy"]) for row in rows]
    rise = max(b - a for a, b in zip(energy, energy[1:])) / abs(energy[0])
    return {"status": f"stopped at {float(stop.group(1)):.2f} s" if stop else "completes",
            "rise": rise,
            "speed": max(float(row["max_speed"]) for row in rows),
            "density": max(float(row["max_density_error"]) for row in rows),
            "fine": int(float(rows[-1].get("level_1", 0)))}


def summary(rows):
    """(runs that complete, with the stop times; largest rise; largest speed; largest density error) of a zone's runs."""
    stops = [r["status"].replace("stopped at ", "") for r in rows if r["status"] != "completes"]
    done = f"{len(rows) - len(stops)} of {len(rows)}" + (f" (stops at {', '.join(stops)})" if stops else "")
    fine = [r["fine"] for r in rows if r["status"] == "completes"]
    return (done, f"{max(r['rise'] for r in rows):.1e}", f"{max(r['speed'] for r in rows):.0f}",
            f"{max(r['density'] for r in rows):.2f}",
            (f"{min(fine)}-{max(fine)}" if min(fine) != max(fine) else str(fine[0])) if fine else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--app", default=os.path.join(ROOT, "build", "release", "app", "sphrefine"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--patterns", default="aap,rsp")
    ap.add_argument("--couplings", default="buffered,mixed")
    args = ap.parse_args()
    if not os.access(args.app, os.X_OK):
        sys.exit(f"--app {args.app}: not an executable")
    couplings = args.couplings.split(",")
    for c in couplings:
        if c.replace("+coarsening", "") not in ("buffered", "mixed"):
            sys.exit(f"--couplings: unknown coupling {c!r} (buffered, mixed, either with +coarsening)")
    patterns = args.patterns.split(",")
    jobs = [(k, z, p, i, c) for k in couplings for z in ZONES for p in patterns for i, c in PERTURBATIONS]
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda n_job: run(args.app, *n_job[1], os.path.join(tmp, str(n_job[0]))),
                                enumerate(jobs)))
    zone_text = lambda z: f"`[{z[0][0]},{z[1][0]}] x [{z[0][1]},{z[1][1]}]`"  # noqa: E731
    print("| coupling | zone | pattern | check interval | C | run | largest energy rise between rows / E(0) "
          "| max speed (m/s) | max density error | fine at the end |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for (k, z, p, i, c), r in zip(jobs, results):
        print(f"| {k} | {zone_text(z)} | {p.upper()} | {i} | {c} | {r['status']} | {r['rise']:.1e} | {r['speed']:.0f} "
              f"| {r['density']:.2f} | {r['fine']} |")
    print()
    head = "| zone | pattern |" + "".join(f" {k}: runs that complete | largest rise / E(0) | max speed (m/s) | max "
                                         "density error | fine at the end |" for k in couplings)
    print(head)
    print("|---|---|" + "---|---|---|---|---|" * len(couplings))
    for z in ZONES:
        for p in patterns:
            cells = []
            for k in couplings:
                rows = [r for (kk, zz, pp, _, _), r in zip(jobs, results) if (kk, zz, pp) == (k, z, p)]
                cells += summary(rows)
            print(f"| {zone_text(z)} | {p.upper()} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
