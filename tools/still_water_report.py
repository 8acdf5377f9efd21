#!/usr/bin/python3
"""Still water under refinement (issue: a split the flow does not notice): the still tank
(cases/still_tank.json, 25 m x 10 m, hydrostatic start, free-slip ghost walls) run for 30 s unrefined and
with a zone refined, for AAP and RSP, one and two levels, and zones in the bulk, at a wall and in a corner.
With --dim 3, the 3D tank (cases/still_tank_3d.json, 1 m x 0.4 m, 0.5 m deep) and 3D zones; give --end (2 s is
23 periods of its compression mode) and, for buffered levels, --set h_factor=1.3 (docs/METHOD.md, "Three
dimensions: a lattice mode"). Layers are a tenth of the depth (1 m in 2D, 0.05 m in 3D).

    /usr/bin/python3 tools/still_water_report.py [--jobs 2] [--end 30] [--set KEY=VALUE ...] [--skip-runs]
                                                 [--only NAME[,NAME]] [--coupling mixed|buffered] [--dim 2|3]
                                                 [--out results/still_water]

--set applies to every run (e.g. a candidate remedy's scene key), so one command compares a remedy with the
paper's scheme. Prints one markdown table: per run its status, max |v| over the run and over the window,
the time-averaged pressure per 1 m layer against the unrefined run's, and the fluid count after the first
pass and at the end. Figures:
  - max |v|: the largest speed over (0, end], and the mean of the per-row largest speed over the window
    [end/3, end] (an oscillating quantity: a time average over a stated window);
  - pressure per layer: the active fluid particles binned in 1 m layers from the floor, each one's pressure
    carried to the layer's middle along the hydrostatic gradient, averaged over the layer and the window's frames; the table gives the largest |p - p_unrefined| / p_unrefined over the
    layers below nine tenths of the depth (the top layer's pressure is near zero, so a relative error means nothing
    there), and the same normalised by rho g H at the floor;
  - creep: the fluid count at the first output after the first pass (t >= 1 s; 3D: t >= 0.2 s) and at the end;
  - energy: the kinetic energy averaged over the window, and the total energy's change from then to the end.
The environment variable SPH_APP names another sphrefine binary (to compare a build with a candidate change).
Exit status 0 when every run completed; 1 when one failed.
"""
import argparse
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
APP = os.environ.get("SPH_APP", os.path.join(ROOT, "build", "release", "app", "sphrefine"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from read_output import frame_files, load_frame, load_series  # noqa: E402

RHO0, G = 1000.0, 9.81
TANKS = {  # per dimension: the scene, the water's depth (m), when the first pass is behind (s), the frames' interval
    2: {"scene": os.path.join(ROOT, "cases", "still_tank.json"), "depth": 10.0, "settled": 1.0, "frames": 0.5,
        "zones": {  # m; the tank is [0, 25] x [0, 10]
            "bulk": {"lo": [10, 3], "hi": [15, 7]},
            "wall": {"lo": [0, 3], "hi": [4, 7]},
            "corner": {"lo": [0, 0], "hi": [5, 4]}}},
    3: {"scene": os.path.join(ROOT, "cases", "still_tank_3d.json"), "depth": 0.5, "settled": 0.2, "frames": 0.05,
        "zones": {  # m; the tank is [0, 1] x [0, 0.4] x [0, 0.5]
            "bulk": {"lo": [0.3, 0.1, 0.1], "hi": [0.7, 0.3, 0.3]},
            "wall": {"lo": [0, 0.1, 0.15], "hi": [0.3, 0.3, 0.35]},
            "corner": {"lo": [0, 0, 0], "hi": [0.3, 0.2, 0.2]}}},
}
TANK = TANKS[2]


def variants(coupling):
    v = [("unrefined", None)]
    for zone in TANK["zones"]:
        for pattern in ("aap", "rsp"):
            for levels in (1, 2):
                r = {"criterion": "zone", "zone": TANK["zones"][zone], "pattern": pattern, "check_interval": 100,
                     "max_level": levels, "coupling": coupling}
                v.append((f"{zone}_{pattern}_L{levels}", r))
    return v


def run(job, out_root, end, extra):
    name, refinement = job
    out = os.path.join(out_root, name)
    cmd = [APP, "run", TANK["scene"], "-o", out, "--force", "-q", "--threads", "1", "--set", f"time.end={end}",
           "--set", f"output.frame_interval={TANK['frames']}"]
    if refinement is not None:
        cmd += ["--set", "effects.refinement=" + json.dumps(refinement)]
    for e in extra:
        cmd += ["--set", e]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in (0, 1):  # 1: the watchdog stopped the run (run.json says why)
        print(f"FAILED {name}: {r.stderr.strip()}", file=sys.stderr)
    return name, out


def layer_pressure(out, t0):
    """Pressure per layer (ten layers, each a tenth of the depth) at the layer's mid-height, averaged over the active
    fluid particles of the layer and the frames with t >= t0. Each particle's pressure is carried to the layer's
    middle along the hydrostatic gradient, p + rho0 g (y - y_mid): a plain mean would compare runs whose particles
    sit at other heights within the layer (a refined zone's do), and the pressure changes by rho0 g over a layer.
    (The scheme's own gradient is up to 2 % steeper, docs/METHOD.md; over the 0.2 m by which the mean heights differ
    in 2D that is 40 Pa, under 0.3 % of any layer's pressure below 9 m.) Passive particles (role 1 and 3, buffered
    coupling) are interpolated copies, not fluid of their own, and are left out."""
    layer = TANK["depth"] / 10.0
    sums, frames = np.zeros(10), 0
    for path in frame_files(out):
        f = load_frame(path)
        if f["time"] < t0 - 1e-9:
            continue
        d = f["fields"]
        keep = d["kind"] == 0
        if "role" in d:
            keep &= (d["role"] != 1) & (d["role"] != 3)
        up = d["position"].shape[1] - 1
        y, p = d["position"][keep, up], d["pressure"][keep]
        k = np.clip(np.floor(y / layer).astype(int), 0, 9)
        p_mid = p + RHO0 * G * (y - (k + 0.5) * layer)
        sums += np.bincount(k, weights=p_mid, minlength=10)[:10] / np.maximum(np.bincount(k, minlength=10)[:10], 1)
        frames += 1
    return sums / max(frames, 1)


def summarize(out, end):
    with open(os.path.join(out, "run.json")) as f:
        summary = json.load(f)
    s = load_series(out)
    t = s["time"]
    window = t >= end / 3.0
    after = np.nonzero(t >= TANK["settled"])[0]
    return {
        "status": summary.get("status", "?"),
        "ended": float(t[-1]) if len(t) else 0.0,
        "vmax": float(np.max(s["max_speed"])),
        "vmean": float(np.mean(s["max_speed"][window])) if window.any() else float("nan"),
        "fluid_first": int(s["fluid"][after[0]]) if len(after) else int(s["fluid"][-1]),
        "fluid_end": int(s["fluid"][-1]),
        "removed": int(s["removed"][-1]) if "removed" in s else 0,
        "layers": layer_pressure(out, end / 3.0),
        # The active fluid's kinetic energy, averaged over the window, and the total energy's change from TANK's
        # "settled" (after the first pass) to the end: whether the motion carries energy, and whether anything feeds it.
        "kmean": float(np.mean(s["kinetic"][window])) if window.any() else float("nan"),
        "de": float(s["total_energy"][-1] - s["total_energy"][after[0]]) if len(after) else float("nan"),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--end", type=float, default=30.0)
    ap.add_argument("--set", action="append", default=[], dest="extra")
    ap.add_argument("--skip-runs", action="store_true")
    ap.add_argument("--only", default="")
    ap.add_argument("--coupling", default="mixed", choices=["mixed", "buffered"],
                    help="effects.refinement.coupling of the refined runs (mixed: the paper's pairs across levels)")
    ap.add_argument("--dim", type=int, default=2, choices=[2, 3])
    ap.add_argument("--out", default=None, help="default results/still_water (results/still_water_3d with --dim 3)")
    args = ap.parse_args()
    global TANK
    TANK = TANKS[args.dim]
    if args.out is None:
        args.out = os.path.join(ROOT, "results", "still_water" if args.dim == 2 else "still_water_3d")
    jobs = variants(args.coupling)
    if args.only:
        keep = set(args.only.split(",")) | {"unrefined"}
        jobs = [j for j in jobs if j[0] in keep]
    if not args.skip_runs:
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            list(pool.map(lambda j: run(j, args.out, args.end, args.extra), jobs))
    res = {name: summarize(os.path.join(args.out, name), args.end) for name, _ in jobs}
    base = res["unrefined"]
    print(f"Still tank ({args.dim}D), {args.end:g} s, one thread; window t >= {args.end / 3:g} s"
          + f"; coupling {args.coupling}"
          + (f"; every run with {' '.join(args.extra)}" if args.extra else "") + "\n")
    unit = "J/m" if args.dim == 2 else "J"
    print(f"| run | status | max |v| (m/s) | mean max |v| in window | / unrefined | layer p err (max, < {0.9 * TANK['depth']:g} m) "
          f"| / rho g H | fluid after 1st pass -> end | kinetic, window mean ({unit}) "
          f"| total energy, {TANK['settled']:g} s -> end ({unit}) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    ok = True
    for name, _ in jobs:
        r = res[name]
        ok &= r["status"] == "completed"
        rel = np.abs(r["layers"][:9] - base["layers"][:9]) / np.abs(base["layers"][:9])
        absn = np.abs(r["layers"][:9] - base["layers"][:9]) / (RHO0 * G * TANK["depth"])
        status = r["status"] if r["status"] == "completed" else f"{r['status']} at {r['ended']:.2f} s"
        print(f"| {name} | {status} | {r['vmax']:.3g} | {r['vmean']:.3g} | {r['vmean'] / base['vmean']:.3g} "
              f"| {100 * rel.max():.2f} % | {100 * absn.max():.2f} % | {r['fluid_first']} -> {r['fluid_end']} "
              f"| {r['kmean']:.3g} | {r['de']:+.3g} |")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
