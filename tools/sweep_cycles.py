#!/usr/bin/python3
"""The pair sweep's cycles by kind of evaluation, for whole runs: the tables of docs/PERFORMANCE.md, "The binned
loop's own cost".

    /usr/bin/python3 tools/sweep_cycles.py [--app PROBE_BUILD --app ... [--reps N]] RUN [RUN ...]

A RUN is a scene file followed by its --set overrides, separated by commas, as for tools/work_counters.py:
    cases/dam_break_aap.json,time.stepping=per_level

Builds the `probe` preset (build/probe: the program with core/sweep_probe.hpp compiled in), runs each RUN there at
one thread, and prints one markdown row per loop and class of particle the sweep met: rows (particle evaluations,
or visits of particles that get no sums), pairs per row, candidates checked per pair, time-stamp cycles per row and
per pair. The cycles include the probe's own two reads of the counter, about the cycles per row of the
`not_fluid` class (a wall, ghost or passive particle returns at once). One run at a time, nothing beside it: the
cycles are time.

With --app (probe builds of two versions, e.g. copies of build/probe/app/sphrefine made at each), nothing is built:
each RUN is run N times (--reps, default 3) with each binary in turn (A, B, A, B, ...), so that the machine's drift
falls on both alike, and the table gains a binary column and each row the repetition.
"""
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
APP = os.path.join(ROOT, "build", "probe", "app", "sphrefine")


def build():
    for cmd in (["cmake", "--preset", "probe"], ["cmake", "--build", "--preset", "probe", "--target", "sphrefine"]):
        r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{r.stdout[-2000:]}{r.stderr[-2000:]}")


def run(scene, overrides, out, app=APP):
    cmd = [app, "run", os.path.join(ROOT, scene), "-o", out, "--force", "-q", "--threads", "1"]
    for o in overrides:
        cmd += ["--set", o]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr.strip()}")
    rows = []
    for line in r.stderr.splitlines():
        f = line.split()
        if not f or f[0] != "sweep_probe":
            continue
        # sweep_probe LOOP CLASS rows N cycles N pairs N candidates N
        v = dict(zip(f[3::2], (int(x) for x in f[4::2])))
        rows.append((f[1], f[2], v))
    if not rows:
        sys.exit(f"{' '.join(cmd)}: no sweep_probe lines (is {app} the probe build?)")
    return rows


def main():
    args = sys.argv[1:]
    apps, reps, runs = [], 3, []
    while args:
        a = args.pop(0)
        if a in ("--app", "--reps") and not args:
            sys.exit(f"{a}: needs a value")
        if a == "--app":
            apps.append(args.pop(0))
        elif a == "--reps":
            try:
                reps = int(args.pop(0))
            except ValueError:
                sys.exit("--reps: needs a whole number")
            if reps < 1:
                sys.exit("--reps: at least 1")
        elif a.startswith("-"):
            sys.exit(__doc__)
        else:
            runs.append(a)
    if not runs:
        sys.exit(__doc__)
    for spec in runs:
        if not os.path.exists(os.path.join(ROOT, spec.split(",")[0])):
            sys.exit(f"{spec.split(',')[0]}: no such scene file")
    for a in apps:
        if not os.access(a, os.X_OK):
            sys.exit(f"--app {a}: not an executable")
    if not apps:
        build()
    rounds = [(app, rep) for rep in range(reps) for app in apps] if apps else [(APP, None)]
    head = "| run | binary | repetition " if apps else "| run "
    print(head + "| loop | class | rows | pairs / row | candidates / pair | cycles / row | cycles / pair |")
    print("|---|" + ("---|---|" if apps else "") + "---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec in runs:
            scene, *overrides = spec.split(",")
            for app, rep in rounds:
                lead = f"| {spec} | {app} | {rep + 1} " if apps else f"| {spec} "
                for loop, cls, v in run(scene, overrides, os.path.join(tmp, "run"), app):
                    n, p = v["rows"], v["pairs"]
                    per_pair = f"{v['cycles'] / p:.1f}" if p else ""
                    cand = f"{v['candidates'] / p:.2f}" if p else ""
                    print(f"{lead}| {loop} | {cls} | {n} | {p / n:.1f} | {cand} | {v['cycles'] / n:.0f} | {per_pair} |",
                          flush=True)


if __name__ == "__main__":
    main()
