#!/usr/bin/python3
"""ctest check of tools/step_limits.py: run sphrefine on a small dam break that refines and steps per level, then
check the tool's table against the frames and the series read here with h5py and numpy directly.

    /usr/bin/python3 tools/test_step_limits.py PATH/TO/sphrefine

Checks: one row per selected frame (--every), at the frame's time; dt0 is series.csv's dt in the row nearest that
time; for each level present, the smallest C 2^l dt_i over its fluid particles, the same times the acoustic
stiffness s_i, and the count of particles with s_i > 1.05; --coarse adds the coarse run's dt. And the tool's clear
errors, each with a non-zero exit: a folder that is not a run, a scene without time.cfl, a run without frames.
Exit status 0 on success, 1 on failure.
"""
import copy
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from checks import Checks  # noqa: E402
import test_read_output  # noqa: E402

TOOL = os.path.join(HERE, "step_limits.py")
FLUID = 0  # Kind::fluid in the frames' kind field (core/types.hpp)

# test_read_output's small column, which collapses: the velocity criterion refines its front within the first checks,
# so two levels are present at the later frames. Here with per-level steps, so the levels have their own bins, and
# run longer, with more frames.
SCENE = copy.deepcopy(test_read_output.SCENE)
SCENE["name"] = "step_limits_check"
SCENE["effects"]["refinement"]["check_interval"] = 10
SCENE["time"] = {"end": 0.15, "output_interval": 0.005, "cfl": 0.2, "stepping": "per_level"}
SCENE["output"] = {"frame_interval": 0.025}


def run(app, scene, folder):
    path = folder + ".json"
    with open(path, "w") as f:
        json.dump(scene, f)
    subprocess.run([app, "run", path, "-o", folder, "-q", "--threads", "1"], check=True, stdout=subprocess.DEVNULL)


def tool(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True)


def series(folder):
    with open(os.path.join(folder, "series.csv")) as f:
        rows = list(csv.DictReader(f))
    return np.array([float(r["time"]) for r in rows]), np.array([float(r["dt"]) for r in rows])


def frames(folder):
    d = os.path.join(folder, "frames")
    out = []
    for name in sorted(n for n in os.listdir(d) if n.startswith("frame_") and n.endswith(".h5")):
        with h5py.File(os.path.join(d, name), "r") as f:
            (g,) = f.values()
            out.append({"time": float(g.attrs["time"]), **{k: g[k][()] for k in
                        ("kind", "level", "time_step_limit", "acoustic_stiffness")}})
    return out


def table(stdout):
    """The rows of the tool's markdown table, as lists of cell strings (header and rule left out)."""
    lines = [l for l in stdout.splitlines() if l.startswith("|")]
    return [[c.strip() for c in l.strip().strip("|").split("|")] for l in lines[2:]]


def main():
    app = sys.argv[1]
    checks = Checks("step_limits")
    tmp = tempfile.mkdtemp(prefix="sph_step_limits_")
    try:
        fine = os.path.join(tmp, "per_level")
        run(app, SCENE, fine)
        coarse_scene = json.loads(json.dumps(SCENE))
        del coarse_scene["effects"]["refinement"]
        coarse_scene["time"]["stepping"] = "global"
        coarse = os.path.join(tmp, "coarse")
        run(app, coarse_scene, coarse)

        t_fine, dt_fine = series(fine)
        t_coarse, dt_coarse = series(coarse)
        frs = frames(fine)
        for every in (1, 2):
            res = tool(fine, "--coarse", coarse, "--every", str(every))
            checks(res.returncode == 0, f"--every {every}: exit {res.returncode}: {res.stderr}")
            rows = table(res.stdout)
            chosen = frs[::every]
            checks(len(rows) == len(chosen), f"--every {every}: {len(rows)} rows for {len(chosen)} frames")
            levels = sorted({int(l) for fr in chosen for l in np.unique(fr["level"][fr["kind"] == FLUID])})
            for row, fr in zip(rows, chosen):
                t = fr["time"]
                checks(abs(float(row[0]) - t) <= 0.05, f"row time {row[0]} for the frame at {t}")  # printed to 0.1 s
                expect_dt0 = dt_fine[int(np.argmin(np.abs(t_fine - t)))]
                checks(np.isclose(float(row[1]), expect_dt0, rtol=5e-4), f"t = {t}: dt0 {row[1]}, series {expect_dt0}")  # 4 digits
                fluid = fr["kind"] == FLUID
                for k, l in enumerate(levels):
                    cell = row[2 + k]
                    m = fluid & (fr["level"] == l)
                    if not m.any():
                        checks(cell == "-", f"t = {t}, level {l} absent: cell {cell!r}")
                        continue
                    own = SCENE["time"]["cfl"] * 2.0 ** l * fr["time_step_limit"][m]
                    undone = own * fr["acoustic_stiffness"][m]
                    parts = cell.split(",")
                    checks(np.isclose(float(parts[0]), own.min(), rtol=5e-4), f"t = {t}, L{l}: {parts[0]} vs {own.min()}")
                    checks(np.isclose(float(parts[1]), undone.min(), rtol=5e-4), f"t = {t}, L{l}: {parts[1]} vs {undone.min()}")
                    stiff = int((fr["acoustic_stiffness"][m] > 1.05).sum())
                    checks(parts[2].strip() == f"{stiff} of {int(m.sum())}", f"t = {t}, L{l}: {parts[2]!r}, {stiff} of {int(m.sum())}")
                expect_coarse = dt_coarse[int(np.argmin(np.abs(t_coarse - t)))]
                checks(np.isclose(float(row[-1]), expect_coarse, rtol=5e-4), f"t = {t}: coarse dt {row[-1]} vs {expect_coarse}")
            checks(levels == [0, 1], f"--every {every}: levels {levels}: the check needs a refined level to read")

        # Clear errors, non-zero exits.
        res = tool(tmp)
        checks(res.returncode != 0 and "no scene.json" in res.stderr, f"not a run: exit {res.returncode}, {res.stderr!r}")
        no_cfl = os.path.join(tmp, "no_cfl")
        shutil.copytree(fine, no_cfl)
        with open(os.path.join(no_cfl, "scene.json")) as f:
            scene = json.load(f)
        scene["time"].pop("cfl", None)
        with open(os.path.join(no_cfl, "scene.json"), "w") as f:
            json.dump(scene, f)
        res = tool(no_cfl)
        checks(res.returncode != 0 and "no time.cfl" in res.stderr, f"no cfl: exit {res.returncode}, {res.stderr!r}")
        shutil.rmtree(os.path.join(no_cfl, "frames"))
        with open(os.path.join(no_cfl, "scene.json"), "w") as f:
            json.dump(SCENE, f)
        res = tool(no_cfl)
        checks(res.returncode != 0 and "no frames" in res.stderr, f"no frames: exit {res.returncode}, {res.stderr!r}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return checks.status()


if __name__ == "__main__":
    sys.exit(main())
