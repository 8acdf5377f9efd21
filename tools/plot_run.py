#!/usr/bin/python3
"""Plots one run's output folder: the probes and diagnostics over time (series.png) and the particles
coloured by speed at four times (particles.png).   /usr/bin/python3 tools/plot_run.py RESULTS_FOLDER

A 3D run is shown from the side: x across, z up, seen from the container's low-y face, the particles nearest to
that face drawn on top; its wall particles are left out (they would hide the fluid).

particles.png shows the whole container (walls drawn, the top dashed when open, obstacles filled) at the
same scale in every panel; the panels are laid out in a row, a 2 x 2 grid or a column, whichever gives them
the most room for the container's aspect, and each particle is drawn as wide as its spacing."""
import json
import os
import sys

import h5py
import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from read_output import DIAGNOSTICS  # noqa: E402

BASE = DIAGNOSTICS

# particles.png: the figure's bounds (inches), the room a panel needs beside its drawing (tick labels, title) and
# the colour bar's width.
MAX_WIDTH, MAX_HEIGHT, MIN_WIDTH = 16.0, 10.0, 6.0
PANEL_PAD_W, PANEL_PAD_H, COLORBAR_W = 0.7, 0.75, 1.1
SPLASH_ROOM = 0.25  # the view extends past the container by at most this fraction of its size to show a splash


def plot_series(folder, names, col):
    probes = [n for n in names if n not in BASE and not n.startswith("level_")]
    energy = "energy (J)" if "momentum_z" in names else "energy (J/m)"  # a 2D run's energies are per metre of depth
    panels = [("particles", ["fluid"]), (energy, ["kinetic", "potential", "total_energy"]),
              ("max |rho/rho0 - 1|", ["max_density_error"]), ("max |v| (m/s)", ["max_speed"])]
    panels += [(p, [p]) for p in probes]
    # The mass balance: fluid removed through an open top is counted, so (M + removed) / M0 - 1 stays at rounding.
    m0 = col["mass"][0] if len(col["mass"]) else 1.0
    removed = col.get("removed_mass", np.zeros_like(col["mass"]))
    col = dict(col, mass_balance=(col["mass"] + removed - m0) / m0, removed_fraction=removed / m0)
    panels.insert(2, ("mass (fraction of M0)", ["mass_balance", "removed_fraction"]))
    labels = {"mass_balance": "(M + removed) / M0 - 1", "removed_fraction": "removed / M0"}
    rows = (len(panels) + 1) // 2
    fig, axes = plt.subplots(rows, 2, figsize=(11, 2.6 * rows), squeeze=False)
    for ax, (title, keys) in zip(axes.flat, panels):
        for k in keys:
            ax.plot(col["time"], col[k], label=labels.get(k, k))
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("t (s)")
        ax.grid(alpha=0.3)
        if len(keys) > 1:
            ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "series.png"), dpi=100)
    plt.close(fig)


def particle_layout(width, height, panels=4):
    """(rows, cols, panel width, panel height) in inches: the layout giving each panel's drawing (aspect
    width / height, equal axes) the largest area within the figure's bounds."""
    aspect = width / height
    best = None
    for rows in (1, 2, 4):
        cols = panels // rows
        pw = min((MAX_WIDTH - COLORBAR_W) / cols - PANEL_PAD_W, aspect * ((MAX_HEIGHT - 0.4) / rows - PANEL_PAD_H))
        ph = pw / aspect
        if best is None or pw * ph > best[2] * best[3]:
            best = (rows, cols, pw, ph)
    return best


def plane(v):
    """The drawn coordinates of points or a corner: (x, y) in 2D, (x, z) in 3D (the side view)."""
    v = np.asarray(v, dtype=float)
    return v[..., [0, v.shape[-1] - 1]]


def view_box(scene, snaps):
    """The box every panel shows: the container, extended (by at most SPLASH_ROOM of its size) to fluid outside it."""
    lo = plane(scene["container"]["lo"])
    hi = plane(scene["container"]["hi"])
    size = hi - lo
    fluid = [s["x"][s["kind"] == 0] for s in snaps]
    fluid = np.concatenate(fluid) if fluid else np.zeros((0, 2))
    fluid = fluid[np.all(np.isfinite(fluid), axis=1)]
    if len(fluid):
        lo = np.maximum(np.minimum(lo, fluid.min(axis=0)), lo - SPLASH_ROOM * size)
        hi = np.minimum(np.maximum(hi, fluid.max(axis=0)), hi + SPLASH_ROOM * size)
    margin = 0.03 * size.max()
    return lo - margin, hi + margin


def draw_geometry(ax, scene):
    c = scene["container"]
    (x0, y0), (x1, y1) = plane(c["lo"]), plane(c["hi"])
    ax.plot([x0, x0, x1, x1], [y1, y0, y0, y1], color="0.25", lw=1.2, zorder=3)  # left, bottom, right walls
    ax.plot([x0, x1], [y1, y1], color="0.25", lw=1.2 if not c.get("open_top", True) else 0.8,
            ls="-" if not c.get("open_top", True) else (0, (4, 3)), zorder=3)
    for o in scene.get("obstacles", []):
        (a0, b0), (a1, b1) = plane(o["lo"]), plane(o["hi"])
        ax.add_patch(Rectangle((a0, b0), a1 - a0, b1 - b0, facecolor="0.75", edgecolor="0.25", lw=1.0, zorder=3))


def plot_particles(folder, scene, files):
    picks = [files[int(round(k * (len(files) - 1) / 3))] for k in range(4)]
    snaps = []
    for fn in picks:
        with h5py.File(os.path.join(folder, "frames", fn), "r") as h:
            g = h[list(h.keys())[0]]
            kind = g["kind"][...]
            x = g["position"][...]
            # Drawn back to front: in 3D the particles nearest the low-y face (the viewer) last.
            order = np.argsort(-x[:, 1], kind="stable") if x.shape[1] == 3 else np.arange(len(x))
            snaps.append({"t": float(g.attrs["time"]), "x": plane(x)[order], "kind": kind[order],
                          "speed": np.linalg.norm(g["velocity"][...], axis=1)[order], "d": g["spacing"][...][order],
                          "dim": x.shape[1]})
    vmax = max([1e-9] + [float(np.max(s["speed"][s["kind"] == 0], initial=0.0)) for s in snaps])
    lo, hi = view_box(scene, snaps)
    rows, cols, pw, ph = particle_layout(*(hi - lo))
    fig_w = max(MIN_WIDTH, cols * (pw + PANEL_PAD_W) + COLORBAR_W)
    fig_h = rows * (ph + PANEL_PAD_H) + 0.4
    fig, axes = plt.subplots(rows, cols, figsize=(fig_w, fig_h), sharex=True, sharey=True, squeeze=False,
                             layout="constrained")
    points_per_metre = 72.0 * pw / (hi[0] - lo[0])
    sc = None
    for ax, s in zip(axes.flat, snaps):
        draw_geometry(ax, scene)
        wall = (s["kind"] == 1) & (s["dim"] == 2)
        ax.scatter(s["x"][wall, 0], s["x"][wall, 1], s=1, c="0.6", linewidths=0, zorder=2)
        fl = s["kind"] == 0
        # Each particle as wide as its spacing (area in points^2), so the fluid reads as a continuum at any scale.
        size = np.maximum((s["d"][fl] * points_per_metre) ** 2, 0.5)
        sc = ax.scatter(s["x"][fl, 0], s["x"][fl, 1], c=s["speed"][fl], s=size, cmap="viridis", vmin=0, vmax=vmax,
                        linewidths=0, zorder=1)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_title(f"t = {s['t']:.3g} s", fontsize=9)
        ax.tick_params(labelsize=8)
    for ax in axes[-1, :]:
        ax.set_xlabel("x (m)", fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel("z (m)" if snaps[0]["dim"] == 3 else "y (m)", fontsize=8)
    fig.colorbar(sc, ax=axes, shrink=0.9 if rows > 1 else 1.0, label="|v| (m/s)", aspect=30)
    fig.suptitle(scene.get("name", ""), fontsize=10)
    fig.savefig(os.path.join(folder, "particles.png"), dpi=100)
    plt.close(fig)


def main(folder):
    with open(os.path.join(folder, "series.csv")) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(os.path.join(folder, "series.csv"), delimiter=",", skiprows=1, ndmin=2)
    plot_series(folder, names, {n: data[:, i] for i, n in enumerate(names)})

    frames_dir = os.path.join(folder, "frames")
    files = sorted(os.listdir(frames_dir)) if os.path.isdir(frames_dir) else []
    if files:
        with open(os.path.join(folder, "scene.json")) as f:
            scene = json.load(f)
        plot_particles(folder, scene, files)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
