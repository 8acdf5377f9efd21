#!/usr/bin/python3
"""ctest check of tools/plot_run.py's particles.png: run sphrefine on a tall, a wide and shallow, and a 3D tiny scene,
plot each, and look at the figures as matplotlib saved them.

    /usr/bin/python3 tools/test_plot_run.py PATH/TO/sphrefine

For either aspect, and for a 3D scene seen from the side (x across, z up): four panels, each showing the whole container (its top included, not only where the fluid
is) at equal scales, a figure within sensible bounds, and panels that fill a fair part of it (not small strips
in a wide empty figure). Exit status 0 on success, 1 on failure.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from checks import Checks  # noqa: E402
import plot_run  # noqa: E402


def scene(name, hi, fluid_hi):
    return {
        "name": name,
        "container": {"lo": [0, 0], "hi": hi},
        "fluid": [{"shape": "rectangle", "lo": [0, 0], "hi": fluid_hi, "spacing": 0.05, "hydrostatic": True}],
        "material": {"rho0": 1000, "mach_factor": 10, "reference_height": fluid_hi[1]},
        "effects": {"gravity": [0, -9.81], "artificial_viscosity": {"alpha": 0.02}, "ghost_walls": "free-slip"},
        "time": {"end": 0.03, "output_interval": 0.01},
        "output": {"frame_interval": 0.01},
    }


def scene_3d(name, hi, fluid_hi):
    """The same in 3D: up is z, and the figure shows the side view (x, z)."""
    s = scene(name, hi, fluid_hi)
    s["container"]["lo"] = [0, 0, 0]
    s["fluid"][0]["lo"] = [0, 0, 0]
    s["material"]["reference_height"] = fluid_hi[2]
    s["effects"]["gravity"] = [0, 0, -9.81]
    return s


# A column in a tall tank (1 m x 2 m), a wide, shallow layer (4 m x 0.5 m, water 0.2 m deep), and a 3D column in
# a tank 1 m long, 0.3 m wide and 0.8 m high, seen from the side.
SCENES = {"tall": scene("tall", [1, 2], [0.5, 0.5]), "wide": scene("wide", [4, 0.5], [4, 0.2]),
          "tank_3d": scene_3d("tank_3d", [1, 0.3, 0.8], [0.5, 0.3, 0.4])}

# Bounds of a readable figure (inches) and the least fraction of it the four panels' drawings should cover: the
# layout that suits the aspect gives 0.52 (wide) and 0.70 (tall) here; a row of four small panels across a
# 16 x 3.8 in figure gave 0.01 for the wide layer.
MAX_SIZE = (16.5, 10.5)
MIN_FILL = 0.4


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    exe = sys.argv[1]
    check = Checks("test_plot_run")

    # Record what each saved figure shows, drawn as it is saved (equal aspect applied).
    saved = {}
    original_savefig = Figure.savefig

    def recording_savefig(fig, fname, *args, **kwargs):
        fig.canvas.draw()
        w, h = fig.get_size_inches()
        panels = []
        for ax in fig.axes:
            if not ax.get_title().startswith("t = "):
                continue  # the colour bar
            box = ax.get_position()
            panels.append({"xlim": sorted(ax.get_xlim()), "ylim": sorted(ax.get_ylim()),
                           "area": box.width * w * box.height * h, "aspect": ax.get_aspect()})
        saved[os.path.basename(str(fname))] = {"size": (w, h), "panels": panels}
        return original_savefig(fig, fname, *args, **kwargs)

    Figure.savefig = recording_savefig
    tmp = tempfile.mkdtemp(prefix="sph_test_plot_run_")
    try:
        for name, sc in SCENES.items():
            path = os.path.join(tmp, name + ".json")
            with open(path, "w") as f:
                json.dump(sc, f)
            out = os.path.join(tmp, name)
            env = dict(os.environ, OMP_NUM_THREADS="1")
            r = subprocess.run([exe, "run", path, "-o", out, "-q"], capture_output=True, text=True, env=env)
            check(r.returncode == 0, f"{name}: sphrefine run exited {r.returncode}: {r.stderr}")
            if r.returncode != 0:
                continue
            saved.clear()
            plot_run.main(out)
            check(os.path.exists(os.path.join(out, "particles.png")), f"{name}: particles.png written")
            fig = saved.get("particles.png")
            check(fig is not None, f"{name}: particles.png saved through matplotlib")
            if fig is None:
                continue
            (x0, y0), (x1, y1) = plot_run.plane(sc["container"]["lo"]), plot_run.plane(sc["container"]["hi"])
            check(len(fig["panels"]) == 4, f"{name}: {len(fig['panels'])} panels")
            for k, p in enumerate(fig["panels"]):
                check(p["xlim"][0] <= x0 and p["xlim"][1] >= x1, f"{name} panel {k}: x range {p['xlim']} misses the container")
                check(p["ylim"][0] <= y0 and p["ylim"][1] >= y1,
                      f"{name} panel {k}: y range {p['ylim']} misses the container (its top is y = {y1})")
                check(p["aspect"] == 1.0 or p["aspect"] == "equal", f"{name} panel {k}: aspect {p['aspect']}")
            w, h = fig["size"]
            check(w <= MAX_SIZE[0] and h <= MAX_SIZE[1], f"{name}: figure {w:.1f} x {h:.1f} in")
            fill = sum(p["area"] for p in fig["panels"]) / (w * h)
            check(fill >= MIN_FILL, f"{name}: the panels cover {fill:.2f} of the figure")
            print(f"{name}: figure {w:.1f} x {h:.1f} in, panels cover {fill:.2f}")
    finally:
        Figure.savefig = original_savefig
        shutil.rmtree(tmp, ignore_errors=True)
    return check.status()


if __name__ == "__main__":
    sys.exit(main())
