#!/usr/bin/python3
"""Read the output folder of a sphrefine run and print a summary (or JSON with --json).

    /usr/bin/python3 tools/read_output.py RUN_FOLDER [--json] [--frame N]

A run folder holds (docs/SCENES.md, "Output"):
  scene.json        the resolved scene (every default written out)
  series.csv        one row per output time: time, step, dt, counts, level_<l>, conserved quantities, probes
  frames/frame_NNNNNN.h5
                    one group "frame_NNNNNN" per file, one dataset per particle field (ghosts left out) with
                    its `units` attribute, attributes time, time_units, step, frame, particles
  frames.xdmf       ParaView's index of the frames (a temporal collection of point sets)
  run.json          the summary, written when the run ends: "status" completed, or failed (the watchdog
                    stopped it; "failure" says where and why); absent while it runs or if it was killed
  checkpoint.h5     with --checkpoint-every

The functions load_series, load_frame, xdmf_datasets and summarize are importable. Exit status: 0 when the
folder is consistent (every XDMF dataset exists with the announced shape), 1 otherwise, 2 on bad usage.
"""
import argparse
import json
import os
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

KIND_NAMES = {0: "fluid", 1: "wall", 2: "ghost"}
# The time series' columns that are not probes or level counts, in a 2D or a 3D run (docs/SCENES.md, "The output
# folder"); tools/plot_run.py uses the same list.
DIAGNOSTICS = ["time", "step", "dt", "fluid", "ghosts", "walls", "mass", "removed", "removed_mass", "momentum_x",
               "momentum_y", "momentum_z", "angular_momentum", "angular_momentum_x", "angular_momentum_y",
               "angular_momentum_z", "kinetic", "potential", "elastic", "total_energy", "max_speed", "max_density_error"]


def load_series(folder):
    """The time series as a dict column name -> numpy array (empty arrays when there is no row yet)."""
    path = os.path.join(folder, "series.csv")
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.size == 0:
        data = np.zeros((0, len(header)))
    return {name: data[:, k] for k, name in enumerate(header)}


def frame_files(folder):
    """The frame files in frame order."""
    d = os.path.join(folder, "frames")
    if not os.path.isdir(d):
        return []
    return sorted(os.path.join(d, n) for n in os.listdir(d) if n.startswith("frame_") and n.endswith(".h5"))


def text(value):
    """An HDF5 string attribute as str (h5py gives fixed-length strings as bytes)."""
    return value.decode() if isinstance(value, bytes) else str(value)


def load_frame(path):
    """One frame: its attributes, every dataset as numpy arrays and their units (None where a dataset has none)."""
    with h5py.File(path, "r") as f:
        (group_name,) = list(f.keys())
        g = f[group_name]
        frame = {k: (text(v) if isinstance(v, bytes) else v.item() if hasattr(v, "item") else v)
                 for k, v in g.attrs.items()}
        frame["group"] = group_name
        frame["fields"] = {name: g[name][()] for name in g.keys()}
        frame["units"] = {name: text(g[name].attrs["units"]) if "units" in g[name].attrs else None for name in g.keys()}
    return frame


def run_status(folder):
    """'completed' or 'failed' (run.json's status), or 'not finished' when there is no run.json yet (the run is
    still going, or it was killed)."""
    path = os.path.join(folder, "run.json")
    if not os.path.exists(path):
        return "not finished"
    with open(path) as f:
        return json.load(f).get("status", "completed")


def xdmf_datasets(folder):
    """Every (time, particles, file, dataset path, dimensions) the XDMF names, in document order."""
    tree = ET.parse(os.path.join(folder, "frames.xdmf"))
    out = []
    for grid in tree.getroot().iter("Grid"):
        if grid.get("GridType") != "Uniform":
            continue
        time = float(grid.find("Time").get("Value"))
        particles = int(grid.find("Topology").get("Dimensions"))
        for item in grid.iter("DataItem"):
            file, path = item.text.strip().split(":", 1)
            dims = tuple(int(x) for x in item.get("Dimensions").split())
            out.append((time, particles, file, path, dims))
    return out


def check_xdmf(folder):
    """Problems found between the XDMF and the HDF5 files (an empty list when consistent)."""
    problems = []
    for time, particles, file, path, dims in xdmf_datasets(folder):
        full = os.path.join(folder, file)
        if not os.path.exists(full):
            problems.append(f"{file}: missing")
            continue
        with h5py.File(full, "r") as f:
            if path not in f:
                problems.append(f"{file}:{path}: missing dataset")
                continue
            shape = f[path].shape
            group = f[path.rsplit("/", 1)[0]]
            if tuple(shape) != dims or dims[0] != particles:
                problems.append(f"{file}:{path}: shape {shape}, XDMF says {dims} ({particles} particles)")
            if abs(float(group.attrs["time"]) - time) > 1e-12 * max(1.0, abs(time)):
                problems.append(f"{file}: time {group.attrs['time']} but XDMF says {time}")
    return problems


def summarize(folder, frame_index=-1):
    """A dict describing the run: scene, series, frames, summary and consistency."""
    s = {"folder": folder}
    with open(os.path.join(folder, "scene.json")) as f:
        scene = json.load(f)
    s["scene"] = scene.get("name")
    s["end_time"] = scene["time"]["end"]
    series = load_series(folder)
    s["rows"] = int(len(series["time"]))
    if s["rows"]:
        s["time_range"] = [float(series["time"][0]), float(series["time"][-1])]
        s["steps"] = int(series["step"][-1])
        mass = series["mass"]
        # Fluid removed through an open top (container.outflow "remove") is accounted for, not lost.
        removed_mass = series.get("removed_mass", np.zeros_like(mass))
        s["removed"] = int(series["removed"][-1]) if "removed" in series else 0
        s["removed_mass"] = float(removed_mass[-1])
        s["mass_drift"] = float((mass[-1] + removed_mass[-1] - mass[0]) / mass[0]) if mass[0] else 0.0
        s["max_speed"] = float(np.max(series["max_speed"]))
        s["max_density_error"] = float(np.max(series["max_density_error"]))
        levels = sorted(k for k in series if k.startswith("level_"))
        s["final_per_level"] = {k: int(series[k][-1]) for k in levels}
        known = set(DIAGNOSTICS) | set(levels)
        s["probes"] = {k: {"first": float(v[0]), "last": float(v[-1]), "min": float(np.nanmin(v)),
                           "max": float(np.nanmax(v))} for k, v in series.items() if k not in known}
    files = frame_files(folder)
    s["frames"] = len(files)
    if files:
        fr = load_frame(files[frame_index])
        kinds = fr["fields"].get("kind")
        s["frame"] = {
            "file": os.path.relpath(files[frame_index], folder),
            "time": float(fr["time"]),
            "step": int(fr["step"]),
            "particles": int(fr["particles"]),
            "fields": sorted(fr["fields"].keys()),
            "units": fr["units"],
        }
        if kinds is not None:
            s["frame"]["kinds"] = {KIND_NAMES.get(int(k), str(k)): int(n) for k, n in zip(*np.unique(kinds, return_counts=True))}
        if kinds is not None and "level" in fr["fields"]:
            lv = fr["fields"]["level"][kinds == 0]
            s["frame"]["fluid_per_level"] = {int(l): int(n) for l, n in zip(*np.unique(lv, return_counts=True))}
    if os.path.exists(os.path.join(folder, "frames.xdmf")):
        s["xdmf_frames"] = len({(t, f) for t, _, f, _, _ in xdmf_datasets(folder)})
        s["problems"] = check_xdmf(folder)
    else:
        s["problems"] = [] if not files else ["frames.xdmf missing"]
    s["status"] = run_status(folder)
    summary_path = os.path.join(folder, "run.json")
    if os.path.exists(summary_path):
        with open(summary_path) as f:
            s["summary"] = json.load(f)
        if "failure" in s["summary"]:
            s["failure"] = s["summary"]["failure"]
    return s


def print_summary(s):
    print(f"run {s['folder']}: scene {s['scene']}, {s['status']}")
    if "failure" in s:
        f = s["failure"]
        print(f"  failure     the watchdog stopped it at step {f['step']}, t = {f['time']:g} s ({f['kind']}): "
              f"particle {f['particle']}: {f['quantity']}")
        print(f"  cause       {f['cause']}")
        print(f"  last good   step {f['last_good_step']}, t = {f['last_good_time']:g} s, in {f['checkpoint']}")
    if s["rows"]:
        t0, t1 = s["time_range"]
        print(f"  series      {s['rows']} rows, t = {t0:g} .. {t1:g} s of {s['end_time']:g} s, {s['steps']} steps")
        if s["removed"]:
            print(f"  removed     {s['removed']} fluid particles through the open top, {s['removed_mass']:.6g} kg/m")
        print(f"  mass drift  {s['mass_drift']:+.3e} (removed fluid counted), max speed {s['max_speed']:.4g} m/s, "
              f"max density error {s['max_density_error']:.3e}")
        print("  per level   " + "  ".join(f"{k} {v}" for k, v in s["final_per_level"].items()))
        for name, p in s["probes"].items():
            print(f"  probe {name:<10} first {p['first']:.6g}  last {p['last']:.6g}  min {p['min']:.6g}  max {p['max']:.6g}")
    print(f"  frames      {s['frames']} (XDMF lists {s.get('xdmf_frames', 0)})")
    if "frame" in s:
        fr = s["frame"]
        print(f"  last frame  {fr['file']}: t = {fr['time']:g} s, step {fr['step']}, {fr['particles']} particles "
              f"{fr.get('kinds', {})}, fluid per level {fr.get('fluid_per_level', {})}")
        units = fr["units"]
        print("  fields      " + ", ".join(f"{n} [{units.get(n)}]" for n in fr["fields"]))
    if "summary" in s:
        r = s["summary"]
        print(f"  wall time   {r['wall_seconds']:.3f} s, {r['particle_steps_per_second']:.4g} particle-steps/s, "
              f"{r['threads']} threads")
    for p in s["problems"]:
        print(f"  PROBLEM     {p}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder", help="the run's output folder")
    ap.add_argument("--json", action="store_true", help="print the summary as JSON")
    ap.add_argument("--frame", type=int, default=-1, help="which frame to describe (default: the last)")
    args = ap.parse_args(argv)
    if not os.path.exists(os.path.join(args.folder, "scene.json")):
        print(f"read_output: {args.folder} does not hold a run (no scene.json)", file=sys.stderr)
        return 2
    s = summarize(args.folder, args.frame)
    if args.json:
        print(json.dumps(s, indent=2))
    else:
        print_summary(s)
    return 1 if s["problems"] else 0


if __name__ == "__main__":
    sys.exit(main())
