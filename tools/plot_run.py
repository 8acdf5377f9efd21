#!/usr/bin/python3
"""Plots one run's output folder: the probes and diagnostics over time (series.png) and the particles
coloured by speed at four times (particles.png).   /usr/bin/python3 tools/plot_run.py RESULTS_FOLDER"""
import os
import sys

import h5py
import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BASE = ["time", "step", "dt", "fluid", "ghosts", "walls", "mass", "momentum_x", "momentum_y", "angular_momentum",
        "kinetic", "potential", "elastic", "total_energy", "max_speed", "max_density_error"]


def main(folder):
    with open(os.path.join(folder, "series.csv")) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(os.path.join(folder, "series.csv"), delimiter=",", skiprows=1, ndmin=2)
    col = {n: data[:, i] for i, n in enumerate(names)}
    probes = [n for n in names if n not in BASE and not n.startswith("level_")]
    panels = [("particles", ["fluid"]), ("energy (J)", ["kinetic", "potential", "total_energy"]),
              ("max |rho/rho0 - 1|", ["max_density_error"]), ("max |v| (m/s)", ["max_speed"])]
    panels += [(p, [p]) for p in probes]
    fig, axes = plt.subplots((len(panels) + 1) // 2, 2, figsize=(11, 2.6 * ((len(panels) + 1) // 2)), squeeze=False)
    for ax, (title, keys) in zip(axes.flat, panels):
        for k in keys:
            ax.plot(col["time"], col[k], label=k)
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

    frames_dir = os.path.join(folder, "frames")
    files = sorted(os.listdir(frames_dir)) if os.path.isdir(frames_dir) else []
    if files:
        picks = [files[int(round(k * (len(files) - 1) / 3))] for k in range(4)]
        fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
        vmax = 1e-9
        snaps = []
        for fn in picks:
            with h5py.File(os.path.join(frames_dir, fn), "r") as h:
                g = h[list(h.keys())[0]]
                kind = g["kind"][...]
                snaps.append((g.attrs["time"], g["position"][...], np.linalg.norm(g["velocity"][...], axis=1),
                              g["spacing"][...], kind))
                vmax = max(vmax, float(np.max(snaps[-1][2][kind == 0], initial=0.0)))
        for ax, (t, x, v, d, kind) in zip(axes, snaps):
            wall = kind == 1
            ax.scatter(x[wall, 0], x[wall, 1], s=1, c="0.6", linewidths=0)
            fl = kind == 0
            sc = ax.scatter(x[fl, 0], x[fl, 1], c=v[fl], s=4 * (d[fl] / d[fl].max()) ** 2, cmap="viridis",
                            vmin=0, vmax=vmax, linewidths=0)
            ax.set_aspect("equal")
            ax.set_title(f"t = {t:.3g} s", fontsize=9)
        fig.colorbar(sc, ax=list(axes), shrink=0.8, label="|v| (m/s)")
        fig.savefig(os.path.join(folder, "particles.png"), dpi=100)
        plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
