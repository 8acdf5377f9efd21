#!/usr/bin/python3
"""The stress report: reads the full-length stress runs in results/stress/<name>/ (written by scripts/stress:
series.csv, run.json, stress_status.json, stderr.txt) and writes docs/figures/stress_<name>.png (total energy,
density error and maximum speed over time) and the stress section of docs/VALIDATION.md (one table per case).

    /usr/bin/python3 tools/stress_report.py [--results results/stress]

The energy in series.csv is kinetic + potential + elastic (Diagnostics::total_energy); the Lennard-Jones wall
energy (core/diagnostics.hpp lennard_jones_energy) is not a series column, so it is left out here (the test
suite, tests/test_stress.cpp, includes it).
"""
import argparse
import glob
import json
import math
import os

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIGURES = os.path.join(ROOT, "docs", "figures")
DOC = os.path.join(ROOT, "docs", "VALIDATION.md")
# The stress section's place in docs/VALIDATION.md: replaced between these markers (appended if absent);
# tools/validation_report.py keeps the block when it rewrites the rest of the file.
BEGIN, END = "<!-- stress:begin (tools/stress_report.py) -->", "<!-- stress:end -->"
SCENES = os.path.join(ROOT, "cases", "stress")

from validation_report import read_csv  # noqa: E402  (tools/ is the script's folder)


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def description(name):
    """The scene's description line (scene files allow // comments: strip them)."""
    try:
        with open(os.path.join(SCENES, name + ".json")) as f:
            text = "\n".join(l for l in f if not l.strip().startswith("//"))
        return json.loads(text).get("description", "")
    except (OSError, ValueError):
        return ""


def plot_case(name, s, failed):
    t = s["time"]
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.6))
    e = s["total_energy"]
    ax[0].plot(t, (e - e[0]) / 1e3, color="C0", label="E - E(0)")
    ax[0].plot(t, (s["kinetic"]) / 1e3, color="C1", lw=0.8, label="kinetic")
    ax[0].set_ylabel("energy (kJ/m)")
    ax[0].set_title("total energy change (KE + PE + elastic)")
    ax[0].legend(fontsize=8)
    ax[1].plot(t, s["max_density_error"], color="C2")
    ax[1].set_ylabel("max |rho/rho0 - 1|")
    ax[1].set_title("density error")
    ax[2].plot(t, s["max_speed"], color="C3")
    ax[2].set_ylabel("max |v| (m/s)")
    ax[2].set_title("maximum speed")
    for a in ax:
        a.set_xlabel("t (s)")
        a.grid(alpha=0.3)
    fig.suptitle(name + (" (stopped by the watchdog)" if failed else ""))
    fig.tight_layout()
    path = os.path.join(FIGURES, "stress_%s.png" % name)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def fmt(x, spec=".3g"):
    return format(x, spec) if x is not None and not (isinstance(x, float) and math.isnan(x)) else "-"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--results", default=os.path.join(ROOT, "results", "stress"))
    args = ap.parse_args()
    os.makedirs(FIGURES, exist_ok=True)
    runs = sorted(d for d in glob.glob(os.path.join(args.results, "*")) if os.path.isdir(d))
    out = ["## Stress runs", "",
           "Full-length runs of the stress scenes in `cases/stress/` (the \"hard cases stay numerically stable\" "
           "issue), written by `scripts/stress` (`tools/stress_report.py`). The short forms of the same scenes are "
           "checked in `tests/test_stress.cpp` (density-error bounds, exact mass, energy never above its start, "
           "1 vs 2 threads bitwise).", "",
           "Energy here is kinetic + potential + elastic from `series.csv` (sampled every output interval); the "
           "Lennard-Jones wall energy is not in the series. Drift is E(end) - E(0); max rise is the largest "
           "E(t) - E(0) over the samples, both relative to |E(0)|.", ""]
    for d in runs:
        name = os.path.basename(d)
        status = read_json(os.path.join(d, "stress_status.json")) or {}
        summary = read_json(os.path.join(d, "run.json")) or {}
        series_path = os.path.join(d, "series.csv")
        stderr = ""
        if os.path.exists(os.path.join(d, "stderr.txt")):
            with open(os.path.join(d, "stderr.txt")) as f:
                stderr = f.read().strip().replace(ROOT + "/", "")
        code = status.get("exit_code")
        failed = code not in (0, None)
        out += ["### %s" % name, "", description(name), ""]
        if not os.path.exists(series_path):
            out += ["No series.csv (exit code %s): %s" % (code, stderr or "-"), ""]
            continue
        s = read_csv(series_path)
        if len(s["time"]) == 0:
            out += ["Empty series (exit code %s): %s" % (code, stderr or "-"), ""]
            continue
        fig = plot_case(name, s, failed)
        e = s["total_energy"]
        e0 = e[0]
        finite = all(np.all(np.isfinite(v)) for v in s.values())
        levels = summary.get("fluid_per_level")
        if levels is None:  # failed runs write no run.json: the last row's level columns
            levels = [int(s[k][-1]) for k in sorted(c for c in s if c.startswith("level_"))]
        steps = summary.get("step", int(s["step"][-1]))
        wall = summary.get("wall_seconds", status.get("wall_seconds"))
        removed_mass = s["removed_mass"][-1] if "removed_mass" in s else 0.0  # fluid removed through an open top
        mass_drift = (s["mass"][-1] + removed_mass - s["mass"][0]) / s["mass"][0]
        out += ["| quantity | value |", "|---|---|",
                "| outcome | %s |" % ("completed" if not failed else "stopped (exit %s): %s" % (code, stderr.replace("|", "/"))),
                "| simulated time | %s s |" % fmt(float(s["time"][-1]), ".4g"),
                "| steps | %d |" % steps,
                "| wall time | %s s (%s thread%s) |" % (fmt(wall, ".1f"), summary.get("threads", "-"),
                                                     "" if summary.get("threads") == 1 else "s"),
                "| max density error | %s |" % fmt(float(np.max(s["max_density_error"])), ".4f"),
                "| energy drift E(end) - E(0) | %s J/m (%s of E(0)) |" % (fmt(float(e[-1] - e0), ".4g"), fmt(float((e[-1] - e0) / abs(e0)), ".2e")),
                "| max energy rise | %s J/m (%s of E(0)) |" % (fmt(float(np.max(e - e0)), ".4g"), fmt(float(np.max(e - e0) / abs(e0)), ".2e")),
                "| max speed | %s m/s |" % fmt(float(np.max(s["max_speed"])), ".3g"),
                "| mass drift | %s |" % fmt(float(mass_drift), ".1e"),
                "| NaN-free | %s |" % ("yes" if finite else "NO"),
                "| fluid particles per level (end) | %s |" % ", ".join("L%d %d" % (k, n) for k, n in enumerate(levels)),
                "", "![%s](figures/%s)" % (name, os.path.basename(fig)), ""]
    block = BEGIN + "\n" + "\n".join(out) + "\n" + END
    text = open(DOC).read() if os.path.exists(DOC) else "# Validation\n"
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + block + text[text.index(END) + len(END):]
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    tmp = DOC + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, DOC)
    print("wrote %s and %d figures" % (DOC, len(runs)))


if __name__ == "__main__":
    main()
