#!/usr/bin/python3
"""ctest check of tools/read_output.py: run sphrefine on a tiny scene, then read its output with h5py.

    /usr/bin/python3 tools/test_read_output.py PATH/TO/sphrefine

Checks that the reader finds every row, every frame and every field (each with its units), that the XDMF's
datasets exist with the announced shapes, that frame attributes agree with the time series, and that the
command-line reader exits 0 on the run and 1 on a folder whose frame went missing. Then a block thrown over an
open top's rim: with container.outflow "stop" the watchdog stops the run and the reader says it failed (not
finished, not completed); with "remove" it completes and the reader's mass drift counts the removed mass.
Exit status 0 on success, 1 on failure.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from checks import Checks  # noqa: E402
import read_output  # noqa: E402

SCENE = {
    "name": "tiny",
    "container": {"lo": [0, 0], "hi": [4, 3]},
    "fluid": [{"shape": "rectangle", "lo": [0, 0], "hi": [1, 2], "spacing": 0.1, "hydrostatic": True}],
    "material": {"rho0": 1000, "mach_factor": 10, "reference_height": 2},
    "effects": {
        "gravity": [0, -9.81],
        "artificial_viscosity": {"alpha": 0.02},
        "lennard_jones_wall": {"reference_height": 2},
        "ghost_walls": "free-slip",
        "refinement": {"criterion": "velocity", "v_threshold": 0.4, "check_interval": 20, "max_level": 1},
    },
    "time": {"end": 0.04, "output_interval": 0.005},
    "probes": [{"type": "water_height", "name": "H", "x": 0}, {"type": "surge_front", "name": "Z"}],
    "output": {"frame_interval": 0.01},
}

# A block thrown up and to the right from below the rim (y = 0.5 m) of an open box: above the rim before it
# reaches the right side, it leaves over the top.
THROWN = {
    "name": "thrown",
    "container": {"lo": [0, 0], "hi": [1, 0.5]},
    "fluid": [{"shape": "rectangle", "lo": [0.6, 0.3], "hi": [0.8, 0.45], "spacing": 0.05, "velocity": [2, 5]}],
    "material": {"rho0": 1000, "c0": 20},
    "effects": {"gravity": [0, -9.81], "artificial_viscosity": {"alpha": 0.02}, "ghost_walls": "free-slip"},
    "time": {"end": 0.3, "output_interval": 0.01},
    "output": {"frame_interval": 0.1},
}

UNITS = {"acceleration": "m/s^2", "acceleration_all_pairs": "m/s^2", "density_rate_all_pairs": "kg/m^3/s",
         "velocity_at_step_start": "m/s", "density_at_step_start": "kg/m^3", "acoustic_stiffness": "1", "density": "kg/m^3", "density_half": "kg/m^3", "density_jerk": "kg/m^3/s^2", "density_rate": "kg/m^3/s", "id": "1", "jerk": "m/s^3",
         "kick_density_rate": "kg/m^3/s", "kick_rate": "m/s^2", "kind": "1", "level": "1", "level_time": "s", "mass": "kg/m", "origin": "1", "position": "m", "pressure": "Pa", "role": "1", "smoothing_length": "m",
         "next_time_bin": "1", "spacing": "m", "time_bin": "1", "time_step_limit": "s", "velocity": "m/s", "velocity_half": "m/s", "tie_offset": "m"}

FIELDS = sorted(UNITS)  # every field the store writes has its unit here: one list


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    exe = sys.argv[1]
    check = Checks("test_read_output")

    tmp = tempfile.mkdtemp(prefix="sph_test_read_output_")
    try:
        scene = os.path.join(tmp, "tiny.json")
        with open(scene, "w") as f:
            json.dump(SCENE, f)
        out = os.path.join(tmp, "run")
        env = dict(os.environ, OMP_NUM_THREADS="1")
        r = subprocess.run([exe, "run", scene, "-o", out, "-q"], capture_output=True, text=True, env=env)
        check(r.returncode == 0, f"sphrefine run exited {r.returncode}: {r.stderr}")
        if r.returncode != 0:
            return 1

        s = read_output.summarize(out)
        series = read_output.load_series(out)
        check(s["scene"] == "tiny", "scene name")
        check(s.get("status") == "completed", f"status {s.get('status')}")
        check(s["problems"] == [], f"XDMF problems: {s['problems']}")
        check(s["rows"] >= 9, f"rows {s['rows']}")
        check(abs(series["time"][-1] - 0.04) < 1e-12, "last row at the end time")
        check(np.all(np.diff(series["step"]) > 0), "steps increase")
        check(np.allclose(series["mass"], series["mass"][0], rtol=1e-12), "mass conserved")
        check(abs(series["H"][0] - 2.0) < 1e-9 and abs(series["Z"][0] - 1.0) < 1e-9, "probes at t = 0: H = 2, Z = 1")
        check(s["frames"] == 5 and s["xdmf_frames"] == 5, f"frames {s['frames']} / {s.get('xdmf_frames')}")

        files = read_output.frame_files(out)
        rows_by_step = {int(st): k for k, st in enumerate(series["step"])}
        for k, path in enumerate(files):
            fr = read_output.load_frame(path)
            check(fr["frame"] == k and fr["group"] == f"frame_{k:06d}", f"frame {k} numbering")
            check(sorted(fr["fields"]) == FIELDS, f"frame {k} fields {sorted(fr['fields'])}")
            check(fr.get("units") == UNITS, f"frame {k} units {fr.get('units')}")
            check(fr.get("time_units") == "s", f"frame {k} time_units {fr.get('time_units')}")
            n = fr["particles"]
            check(fr["fields"]["position"].shape == (n, 2) and fr["fields"]["velocity"].shape == (n, 2), "vector shapes")
            for name in FIELDS:
                check(len(fr["fields"][name]) == n, f"frame {k} {name} length")
            kinds = fr["fields"]["kind"]
            check(not np.any(kinds == 2), "no ghosts in frames")
            fluid = kinds == 0
            row = rows_by_step.get(int(fr["step"]))
            check(row is not None, f"frame {k} at a row's step")
            if row is not None:
                check(abs(series["time"][row] - fr["time"]) < 1e-15, f"frame {k} time matches its row")
                check(int(series["fluid"][row]) == int(fluid.sum()), f"frame {k} fluid count")
                m = fr["fields"]["mass"][fluid]
                check(abs(m.sum() - series["mass"][row]) <= 1e-9 * series["mass"][row], f"frame {k} mass")
            ids = fr["fields"]["id"]
            check(len(np.unique(ids)) == len(ids), f"frame {k} ids unique")
        last = read_output.load_frame(files[-1])
        check(np.any(last["fields"]["level"][last["fields"]["kind"] == 0] == 1), "refinement reached the frames")

        # The command-line reader: 0 on the run, 1 once a frame listed in the XDMF is gone, 2 on a non-run.
        r = subprocess.run([sys.executable, os.path.join(HERE, "read_output.py"), out], capture_output=True, text=True)
        check(r.returncode == 0 and "frames      5" in r.stdout, f"read_output.py: {r.returncode} {r.stdout} {r.stderr}")
        broken = os.path.join(tmp, "broken")
        shutil.copytree(out, broken)
        os.remove(os.path.join(broken, "frames", "frame_000002.h5"))
        r = subprocess.run([sys.executable, os.path.join(HERE, "read_output.py"), broken], capture_output=True, text=True)
        check(r.returncode == 1 and "PROBLEM" in r.stdout, f"broken folder: {r.returncode}")
        r = subprocess.run([sys.executable, os.path.join(HERE, "read_output.py"), tmp], capture_output=True, text=True)
        check(r.returncode == 2, f"non-run folder: {r.returncode}")
        # Killed before run.json: not finished.
        os.remove(os.path.join(broken, "run.json"))
        check(read_output.summarize(broken).get("status") == "not finished", "a folder without run.json is not finished")

        # A run the watchdog stopped: "failed", with the failure, never "finished" or "completed".
        thrown = os.path.join(tmp, "thrown.json")
        with open(thrown, "w") as f:
            json.dump(THROWN, f)
        stopped = os.path.join(tmp, "stopped")
        r = subprocess.run([exe, "run", thrown, "-o", stopped, "-q"], capture_output=True, text=True, env=env)
        check(r.returncode == 1, f"the thrown block with outflow stop exited {r.returncode}: {r.stderr}")
        s = read_output.summarize(stopped)
        check(s.get("status") == "failed", f"stopped run: status {s.get('status')}")
        check(s.get("failure", {}).get("kind") == "left_open_top", f"stopped run: failure {s.get('failure')}")
        r = subprocess.run([sys.executable, os.path.join(HERE, "read_output.py"), stopped], capture_output=True, text=True)
        first = r.stdout.splitlines()[0] if r.stdout else ""
        check(first.endswith("failed"), f"read_output.py's first line: {first!r}")
        check("finished" not in r.stdout and "completed" not in r.stdout, f"read_output.py says: {r.stdout}")
        check("through the open top" in r.stdout, f"read_output.py names the failure: {r.stdout}")

        # The same with outflow "remove": completes, the block is removed, the mass drift counts it.
        removed = os.path.join(tmp, "removed")
        r = subprocess.run([exe, "run", thrown, "-o", removed, "-q", "--set", "container.outflow=remove"],
                           capture_output=True, text=True, env=env)
        check(r.returncode == 0, f"the thrown block with outflow remove exited {r.returncode}: {r.stderr}")
        s = read_output.summarize(removed)
        series = read_output.load_series(removed)
        check(s.get("status") == "completed", f"removed run: status {s.get('status')}")
        check(s.get("removed") == 12 and series["fluid"][-1] == 0, f"removed {s.get('removed')}, fluid {series['fluid'][-1]}")
        # M is 0 at the end and the removed mass an exact sum of the same 12 masses: equal up to rounding.
        check(abs(s["mass_drift"]) <= 2 * np.finfo(float).eps, f"mass drift with removed fluid {s['mass_drift']}")
        check(s["summary"]["removed_particles"] == 12, f"run.json removed {s['summary'].get('removed_particles')}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return check.status()


if __name__ == "__main__":
    sys.exit(main())
