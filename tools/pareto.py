"""What accuracy costs (issue #17): each run's field error against a converged reference, against its cost, with
the uniform runs as a curve and the dynamic variants as points. Used by tools/validation_report.py.

The reference is a fully refined run at least one resolution finer than any run on the chart; the errors are
tools/field_error.py's (velocity, pressure and volume fraction sampled on one lattice, L2 over the window,
normalised by the reference's own range). A dynamic variant is then set against the uniform curve: the wall time a
uniform run of the same velocity error would take, interpolated on the curve in log-log between the two uniform
runs whose errors bracket it.
"""
import math
import os

import numpy as np

import field_error


# Wall-time ratios of runs timed side by side moved by 19 % between two sessions (docs/PERFORMANCE.md): a ratio
# within this of 1 does not say which is cheaper.
TIMING_SPREAD = 0.2


def finest_spacing(name, k, d0):
    """The finest spacing in a variant: uniform "unrefined" runs have d0 / k; every other run (statically or
    dynamically refined, one level) d0 / (2 k)."""
    return d0 / k / (1.0 if name.startswith("unrefined") else 2.0)


def is_uniform(name):
    return name.startswith("unrefined") or name.startswith("refined")


class FieldErrors:
    """The field errors of runs against one reference run (its output folder), each frame sampled on the lattice of
    two points per coarse spacing d0 over box (x0, y0, x1, y1), over the frames in window (t0, t1)."""

    def __init__(self, reference_out, d0, box, window):
        self.lattice = field_error.Lattice(box[:2], box[2:], d0 / 2.0)
        self.window = window
        self.ref = field_error.sampled_frames(reference_out, self.lattice, window)

    def of(self, out):
        """{E_v, E_p, E_phi, ...} of the run whose output folder is out."""
        return field_error.errors(field_error.sampled_frames(out, self.lattice, self.window), self.ref)


def field_rows(R, reference, d0, fe, cost):
    """Rows for every run of case R (name -> run dict with "out", "k", "summary", "series") finer-grained than the
    reference excluded: name, uniform, finest spacing, wall, evaluations, E_v, E_p, E_phi, frames. fe: the
    FieldErrors against R[reference]."""
    h_ref = finest_spacing(reference, R[reference]["k"], d0)
    rows = []
    for name, r in R.items():
        spacing = finest_spacing(name, r["k"], d0)
        if name == reference or spacing <= h_ref * (1 + 1e-9):
            continue  # not coarser than the reference: not on the chart
        if not os.path.isdir(os.path.join(r["out"], "frames")):
            continue
        e = fe.of(r["out"])
        wall, evals = cost(r)
        completed = r["summary"].get("status", "completed") == "completed"
        rows.append(dict(name=name, uniform=is_uniform(name), spacing=spacing, wall=wall, evaluations=evals,
                         completed=completed, **e))
    return rows


def uniform_front(rows, x_key):
    """The uniform runs that no other uniform run beats in both cost and E_v, by increasing cost. Wall times are
    compared within the timings' spread (TIMING_SPREAD): a run is left off when another is more accurate and at
    most (1 + spread) times as dear, since the two costs cannot be ordered. (Two uniform runs at the same particle
    count, a lattice and a split lattice, differ in wall time by a few per cent; ordering them by that noise put a
    kink into the front that moved a variant's ratio from 1.0x to 0.6x between two reruns of the same runs.) Force
    evaluations are deterministic and compared as they are."""
    spread = TIMING_SPREAD if x_key == "wall" else 0.0
    uni = [r for r in rows if r["uniform"] and r["completed"] and np.isfinite(r["E_v"])]
    kept = [r for r in uni if not any(s is not r and s["E_v"] < r["E_v"] and s[x_key] <= r[x_key] * (1.0 + spread)
                                      for s in uni)]
    front = []
    for r in sorted(kept, key=lambda r: r[x_key]):
        if not front or r["E_v"] < front[-1]["E_v"]:
            front.append(r)
    return front


def equal_error_cost(front, e, x_key):
    """(cost, how) of a uniform run of velocity error e on the front: how = "interpolated" (log-log between the
    two uniform runs that bracket e), "above" (e is larger than every uniform run's error: the cost returned is
    the cheapest uniform run's, which is more accurate, so the variant costs at least cost_d / cost times as
    much as a uniform run of its error), or "below" (e is smaller than every uniform run's: the most accurate
    uniform run's cost, so the ratio is at most cost_d / cost). (None, None) without a front."""
    if not front:
        return None, None
    if e > front[0]["E_v"]:
        return front[0][x_key], "above"
    if e < front[-1]["E_v"]:
        return front[-1][x_key], "below"
    for a, b in zip(front, front[1:]):
        if b["E_v"] <= e <= a["E_v"]:
            f = (math.log(a["E_v"]) - math.log(e)) / (math.log(a["E_v"]) - math.log(b["E_v"]))
            return math.exp(math.log(a[x_key]) + f * (math.log(b[x_key]) - math.log(a[x_key]))), "interpolated"
    return front[0][x_key], "interpolated"  # a front of one run with e equal to its error


def place_labels(ax, points, fontsize=6):
    """Labels beside scatter points, each at the first of a few offsets where it overlaps no label placed
    before it (a greedy pass in display coordinates; labels are approximated by boxes)."""
    ax.figure.canvas.draw()
    placed = []
    char_w, line_h = 0.62 * fontsize, 1.3 * fontsize  # points; the figure is at 72 points per inch
    scale = ax.figure.dpi / 72.0
    offsets = [(3, 2), (3, -8), (-3, 2), (-3, -8), (3, 9), (3, -15), (-3, 9), (-3, -15)]
    for x, y, text in sorted(points, key=lambda p: (p[1], p[0])):
        px, py = ax.transData.transform((x, y))
        w, h = char_w * len(text) * scale, line_h * scale
        for dx, dy in offsets:
            x0 = px + dx * scale - (w if dx < 0 else 0.0)
            y0 = py + dy * scale
            box = (x0, y0, x0 + w, y0 + h)
            if not any(box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3] for b in placed):
                break
        placed.append(box)
        ax.annotate(text, (x, y), fontsize=fontsize, xytext=(dx, dy), textcoords="offset points",
                    ha="right" if dx < 0 else "left")


def chart(rows, reference, title, out_png):
    """Two panels: E_v against wall time and against force evaluations. Uniform runs joined by their front."""
    import matplotlib.pyplot as plt

    families = {"aap": ("o", "C0", "AAP"), "rsp": ("s", "C1", "RSP"), "aap_pl": ("o", "C2", "AAP, steps per level"),
                "rsp_pl": ("s", "C3", "RSP, steps per level"), "aap_coarsen": ("o", "C4", "AAP with coarsening"),
                "rsp_coarsen": ("s", "C5", "RSP with coarsening")}

    def family(name):
        base = name.split("_")[0]
        if "_pl" in name:
            return base + "_pl"
        if "coarsen" in name:
            return base + "_coarsen"
        return base

    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    for ax, x_key, xlabel in ((axes[0], "wall", "wall time (s, one thread)"),
                              (axes[1], "evaluations", "force evaluations (particle-steps)")):
        front = uniform_front(rows, x_key)
        ax.plot([r[x_key] for r in front], [r["E_v"] for r in front], "k-", lw=1, label="uniform runs (front)")
        seen = set()
        labels = []
        for r in rows:
            if not np.isfinite(r["E_v"]):
                continue
            if r["uniform"]:
                marker, colour, legend = ("^", "k", "uniform") if r["name"].startswith("unrefined") else \
                    ("v", "k", "uniform (statically refined)")
            else:
                marker, colour, legend = families.get(family(r["name"]), ("D", "C7", "other"))
                if not r["completed"]:
                    marker, legend = "x", "stopped by the watchdog (its part only)"
            ax.scatter(r[x_key], r["E_v"], s=22, marker=marker, color=colour,
                       label=None if legend in seen else legend)
            seen.add(legend)
            labels.append((r[x_key], r["E_v"], r["name"]))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("E_v: velocity field error vs " + reference)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=6, loc="upper right")
        place_labels(ax, labels)
    fig.suptitle(title + " (below and left of the black line: cheaper than a uniform run of the same error)")
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def verdicts(rows):
    """For each dynamic variant: its cost over a uniform run's of equal E_v, by wall time and by evaluations, with
    how each was found (equal_error_cost)."""
    fw, fe = uniform_front(rows, "wall"), uniform_front(rows, "evaluations")
    out = []
    for r in rows:
        if r["uniform"] or not np.isfinite(r["E_v"]):
            continue
        uw, hw = equal_error_cost(fw, r["E_v"], "wall")
        ue, he = equal_error_cost(fe, r["E_v"], "evaluations")
        out.append(dict(r, wall_ratio=r["wall"] / uw if uw else None, wall_how=hw,
                        evaluation_ratio=r["evaluations"] / ue if ue else None, evaluation_how=he))
    return out


def ratio_text(ratio, how):
    """A ratio as the table shows it: "1.53", ">= 2.1" (less accurate than every uniform run, dearer than the
    cheapest), "<= 0.8" (more accurate than every uniform run)."""
    if ratio is None:
        return "n/a"
    return {"interpolated": f"{ratio:.2f}", "above": f">= {ratio:.2f}", "below": f"<= {ratio:.2f}"}[how]


def words(case_label, rows, reference):
    """The answer in one paragraph: how each dynamic variant compares with a uniform run of the same error."""
    v = [x for x in verdicts(rows) if x["completed"] and x["wall_ratio"] is not None]
    stopped = [x["name"] for x in verdicts(rows) if not x["completed"]]
    if not v:
        return f"**{case_label}**: no dynamic variant to compare.\n"

    def listed(xs):
        return ", ".join(f"{x['name']} {ratio_text(x['wall_ratio'], x['wall_how'])}x"
                         for x in sorted(xs, key=lambda x: x["wall_ratio"]))

    # Cheaper for certain: an interpolated ratio (or an "at most" bound) below 1 by more than the timing spread.
    cheaper = [x for x in v if x["wall_ratio"] < 1.0 - TIMING_SPREAD and x["wall_how"] in ("interpolated", "below")]
    dearer = [x for x in v if x["wall_ratio"] > 1.0 + TIMING_SPREAD or x["wall_how"] == "above"]
    even = [x for x in v if x not in cheaper and x not in dearer]
    parts = [f"**{case_label}** (velocity field error E_v against `{reference}`, wall time one thread; a ratio within "
             f"{100 * TIMING_SPREAD:.0f} % of 1 is within the timings' spread): "]
    parts.append(f"cheaper than a uniform run of the same error: {listed(cheaper) if cheaper else 'none'} "
                 f"(of {len(v)} dynamic variants). ")
    if even:
        parts.append(f"Within the spread: {listed(even)}. ")
    if dearer:
        parts.append(f"Dearer: {listed(dearer)} (\">=\": less accurate than the cheapest uniform run). ")
    best = min(v, key=lambda x: x["wall_ratio"])
    parts.append(f"Best: {best['name']}, {ratio_text(best['wall_ratio'], best['wall_how'])}x the wall time and "
                 f"{ratio_text(best['evaluation_ratio'], best['evaluation_how'])}x the force evaluations of a uniform "
                 "run of its error.")
    if stopped:
        parts.append(" Stopped by the watchdog, not compared: " + ", ".join(stopped) + ".")
    return "".join(parts) + "\n"
