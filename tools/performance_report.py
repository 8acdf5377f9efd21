#!/usr/bin/python3
"""The measured part of docs/PERFORMANCE.md, from the Google Benchmark JSON files scripts/bench writes.

Reads results/bench/*.json (medians of the repetitions), writes docs/figures/perf_*.png and replaces the
block between the bench markers of docs/PERFORMANCE.md (the hand-written analysis around it stays).
"""
import argparse
import glob
import json
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIGURES = os.path.join(ROOT, "docs", "figures")
DOC = os.path.join(ROOT, "docs", "PERFORMANCE.md")
BEGIN, END = "<!-- bench:begin (scripts/bench, tools/performance_report.py) -->", "<!-- bench:end -->"

# ../shared/ANCHORS.md: DualSPHysics 5.4 (OpenMP CPU build) on this kind of 2-core machine, fluid
# particle-steps per second, median of 5 runs, its own 2D dam break at three resolutions.
PEER = {0: (4050, 1.30e6, 2.34e6), 1: (29768, 1.52e6, 2.75e6), 2: (250632, 1.54e6, 2.87e6)}
# ../shared/ANCHORS.md, DualSPHysics' 3D CaseDambreak: fluid particle-steps/s at 1 and 2 threads per dp index.
PEER3D = {0: (1.96e5, 3.81e5), 1: (2.00e5, 3.94e5), 2: (2.13e5, 4.20e5)}


def load(results):
    """name -> list of median entries (the aggregate rows), plus the context of the first file."""
    runs, context = {}, None
    for path in sorted(glob.glob(os.path.join(results, "*.json"))):
        with open(path) as f:
            data = json.load(f)
        context = context or data.get("context", {})
        benches = data.get("benchmarks", [])
        cv = {b.get("run_name"): b["real_time"] for b in benches if b.get("aggregate_name") == "cv"}
        rows = [b for b in benches if b.get("aggregate_name", "median") == "median"]
        for b in rows:
            b["cv"] = cv.get(b.get("run_name"))  # coefficient of variation of the repetitions (a fraction)
        runs[os.path.splitext(os.path.basename(path))[0]] = rows
    return runs, context


def ms(b):
    """Real time of one iteration in milliseconds."""
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
    return b["real_time"] * scale


def args_of(name):
    """The integer arguments of a benchmark name: BM_X/100000/2/real_time -> [100000, 2]."""
    parts = name.split("/")[1:]
    out = []
    for p in parts:
        m = re.fullmatch(r"(?:[A-Za-z_]+:)?(\d+)", p)
        if m:
            out.append(int(m.group(1)))
    return out


def fmt_count(n):
    """1000 -> 1e3, 4000000 -> 4e6, 29768 -> 29,768 (round powers as powers, other counts in full)."""
    n = int(n)
    exp = len(str(n)) - 1
    if exp >= 3 and n % 10 ** exp == 0:
        return "%de%d" % (n // 10 ** exp, exp)
    return "{:,}".format(n)


def step_rows(runs):
    rows = {}
    for key, bs in runs.items():
        if not key.startswith("step_"):
            continue
        for b in bs:
            a = args_of(b["name"])
            if len(a) < 2 or not b["name"].startswith("BM_Step_WithGhosts"):
                continue
            rows[(a[0], a[1])] = b
    return rows


def figure_step(rows):
    ns = sorted({n for n, _ in rows})
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    for t, style in ((1, "o-"), (2, "s-")):
        xs = [n for n in ns if (n, t) in rows]
        us = [1e6 / rows[(n, t)]["items_per_second"] for n in xs]
        ax[0].plot(xs, us, style, label="%d thread%s" % (t, "" if t == 1 else "s"))
    ref = [1e6 / rows[(n, 1)]["items_per_second"] for n in ns if (n, 1) in rows and 1e4 <= n <= 1e6]
    if ref:
        mid = sum(ref) / len(ref)
        ax[0].axhspan(0.8 * mid, 1.2 * mid, color="0.85", label="+-20 % of the 1e4-1e6 mean (1 thread)")
    ax[0].set_xscale("log")
    ax[0].set_ylim(bottom=0)
    ax[0].set_xlabel("fluid particles N")
    ax[0].set_ylabel("microseconds per particle-step")
    ax[0].set_title("time per particle-step (flat = linear cost)")
    ax[0].legend(fontsize=8)
    xs = [n for n in ns if (n, 1) in rows and (n, 2) in rows]
    ax[1].plot(xs, [ms(rows[(n, 1)]) / ms(rows[(n, 2)]) for n in xs], "o-", label="whole step")
    ax[1].axhline(1.8, color="r", ls="--", lw=1, label="target 1.8x")
    ax[1].axhline(2.0, color="0.5", ls=":", lw=1, label="ideal 2x")
    ax[1].set_xscale("log")
    ax[1].set_ylim(0.8, 2.1)
    ax[1].set_xlabel("fluid particles N")
    ax[1].set_ylabel("speed-up, 2 threads over 1")
    ax[1].set_title("strong scaling (2 cores)")
    ax[1].legend(fontsize=8)
    xs = [n for n in ns if (n, 1) in rows]
    ax[2].plot(xs, [rows[(n, 1)]["peak_rss_bytes_per_particle"] for n in xs], "o-", label="peak resident set / N")
    ax[2].plot(xs, [rows[(n, 1)]["store_bytes_per_particle"] for n in xs], "s--", label="particle store (data + scratch, ghosts included) / N")
    ax[2].set_xscale("log")
    ax[2].set_yscale("log")
    ax[2].set_xlabel("fluid particles N")
    ax[2].set_ylabel("bytes per fluid particle")
    ax[2].set_title("memory")
    ax[2].legend(fontsize=8)
    fig.suptitle("sph_bench_step: dam-break block with ghost walls, Lennard-Jones walls and viscosity")
    fig.tight_layout()
    path = os.path.join(FIGURES, "perf_step.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def figure_components(runs, step):
    """Bars: one step against the sweep per effect set and the split pass, at 1e5 and 1e6, 1 and 2 threads."""
    items = []
    for b in runs.get("sweep", []):
        a = args_of(b["name"])
        label = b["name"].split("/")[0].replace("BM_", "").replace("_", " ")
        items.append((label, a[0], a[1], ms(b)))
    for b in runs.get("split", []):
        a = args_of(b["name"])
        if b["name"].startswith("BM_Split") and len(a) == 3 and a[1] == 10:
            items.append(("split " + b["name"].split("_")[2].split("/")[0] + " 10 %", a[0], a[2], ms(b)))
    for (n, t), b in step.items():
        if n in (100000, 1000000):
            items.append(("whole step", n, t, ms(b)))
    fig, axes = plt.subplots(1, 2, figsize=(14, 4.5))
    for ax, n in zip(axes, (100000, 1000000)):
        sel = sorted({i[0] for i in items if i[1] == n})
        for k, t in enumerate((1, 2)):
            vals = [next((i[3] for i in items if i[0] == lab and i[1] == n and i[2] == t), 0.0) for lab in sel]
            ax.barh([y + 0.4 * k for y in range(len(sel))], vals, height=0.4,
                    label="%d thread%s" % (t, "" if t == 1 else "s"))
        ax.set_yticks([y + 0.2 for y in range(len(sel))])
        ax.set_yticklabels(sel, fontsize=8)
        ax.set_xlabel("milliseconds")
        ax.set_title("N = %s" % fmt_count(n))
        ax.legend(fontsize=8)
    fig.suptitle("components against one whole step")
    fig.tight_layout()
    path = os.path.join(FIGURES, "perf_components.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--results", default=os.path.join(ROOT, "results", "bench"))
    args = ap.parse_args()
    os.makedirs(FIGURES, exist_ok=True)
    runs, context = load(args.results)
    if not runs:
        raise SystemExit("performance_report: no benchmark JSON in %s (run scripts/bench)" % args.results)
    md = [BEGIN, "",
          "Generated by `scripts/bench` on %s (%s CPUs, %s build of Google Benchmark's context: %s). "
          "Medians of the repetitions; real (wall) time; cv is the repetitions' coefficient of variation (this "
          "machine is a 2-vCPU virtual machine whose speed drifts by up to ~20 %% between minutes)."
          % (context.get("date", "?"), context.get("num_cpus", "?"), context.get("library_build_type", "?"),
             context.get("host_name", "?")), ""]

    step = step_rows(runs)
    if step:
        fig = figure_step(step)
        rows = []
        for n in sorted({n for n, _ in step}):
            for t in (1, 2):
                b = step.get((n, t))
                if not b:
                    continue
                b1 = step.get((n, 1))
                rows.append([fmt_count(n), fmt_count(b["fluid"]), t, "%.3g" % ms(b), "%.3g" % b["items_per_second"],
                             "%.3f" % (1e6 / b["items_per_second"]),
                             "%.2f" % (ms(b1) / ms(b)) if b1 and t == 2 else "",
                             "%.0f" % b["peak_rss_bytes_per_particle"], "%.0f" % b["store_bytes_per_particle"],
                             "%.1f" % b["pairs_per_particle"],
                             "%.0f %%" % (100 * b["cv"]) if b.get("cv") is not None else ""])
        md += ["### Whole step against N and threads (`sph_bench_step`, BM_Step_WithGhosts)", "",
               "A dam-break block (the paper's 25 m column at N particles) in its 50 m x 80 m tank with ghost walls, "
               "Lennard-Jones walls and viscosity; `sim.step()` repeated (grid, ghosts, sweep, integration, "
               "watchdog). Peak resident set per particle from a process that ran only that N.", ""]
        md += table(["N", "fluid", "threads", "ms/step", "particle-steps/s", "us/particle-step", "speed-up",
                     "peak RSS B/particle", "store B/particle", "pairs/particle", "cv"], rows)
        ref = [1e6 / step[(n, 1)]["items_per_second"] for n in sorted({n for n, _ in step}) if (n, 1) in step and 1e4 <= n <= 1e6]
        if ref:
            mid = sum(ref) / len(ref)
            spread = max(abs(r / mid - 1) for r in ref)
            md += ["", "Time per particle-step, 1 thread, 1e4-1e6: mean %.3f us, largest deviation %.0f %% (target +-20 %%)."
                   % (mid, 100 * spread)]
        md += ["", "![step](figures/%s)" % os.path.basename(fig), ""]

    if runs.get("sweep") or runs.get("split"):
        md += ["![components](figures/%s)" % os.path.basename(figure_components(runs, step)), ""]

    if runs.get("sweep"):
        rows = []
        by = {}
        for b in runs["sweep"]:
            a = args_of(b["name"])
            by[(b["name"].split("/")[0], a[1])] = b
        for name in sorted({k[0] for k in by}):
            b1, b2 = by.get((name, 1)), by.get((name, 2))
            rows.append([name.replace("BM_", ""), "%.3g" % ms(b1) if b1 else "", "%.3g" % ms(b2) if b2 else "",
                         "%.2f" % (ms(b1) / ms(b2)) if b1 and b2 else ""])
        md += ["### The pair sweep per effect set, 1e5 particles (`sph_bench_step`)", ""]
        md += table(["benchmark", "1 thread (ms)", "2 threads (ms)", "speed-up"], rows)
        md += [""]

    if runs.get("grid"):
        by = {}
        for b in runs["grid"]:
            a = args_of(b["name"])
            by[(b["name"].split("/")[0], a[0], a[1])] = b
        rows = []
        for n in sorted({k[1] for k in by}):
            for t in (1, 2):
                r = by.get(("BM_Store_ReorderSorted", n, t))
                c = by.get(("BM_Copy_ReorderBytes", n, t))
                g = by.get(("BM_Grid_BuildSorted", n, t))
                if r and c:
                    rows.append([fmt_count(n), t, "%.3g" % ms(g) if g else "", "%.3g" % ms(r), "%.3g" % ms(c),
                                 "%.2f" % (ms(r) / ms(c))])
        md += ["### Grid build and store reorder against a plain copy (`sph_bench_grid`)", "",
               "Reorder: one gather of every field of a store already in cell order (the steady state); copy: "
               "memcpy of the same bytes. Target: reorder within 3x of the copy.", ""]
        md += table(["N", "threads", "grid build (ms)", "reorder (ms)", "copy (ms)", "reorder / copy"], rows)
        md += [""]

    if runs.get("split"):
        by = {}
        for b in runs["split"]:
            by[b["name"].split("/real_time")[0]] = b
        rows = []
        for key, b in sorted(by.items(), key=lambda kv: args_of(kv[0])):
            a = args_of(key)
            if key.startswith("BM_Split") and len(a) == 3:
                st = by.get("BM_Step_SameStore/%d/%d" % (a[0], a[2]))
                rows.append([key.split("/")[0].replace("BM_Split_", ""), fmt_count(a[0]), "%d %%" % a[1], a[2],
                             "%.3g" % ms(b), "%.3g" % ms(st) if st else "",
                             "%.0f %%" % (100 * ms(b) / ms(st)) if st else ""])
        md += ["### The split pass against one step (`sph_bench_split`)", ""]
        md += table(["pattern", "N", "marked", "threads", "split (ms)", "one step (ms)", "split / step"], rows)
        md += [""]

    if runs.get("scene"):
        rows = [[b["name"].split("/")[1], "%.4g" % ms(b)] for b in runs["scene"]]
        md += ["### The same scene with and without each effect (`sph_bench_scene`, 1 thread)", ""]
        md += table(["variant", "ms"], rows)
        md += [""]

    if runs.get("peer"):
        rows = []
        for b in runs["peer"]:
            a = args_of(b["name"])
            if len(a) < 3:
                continue
            count, p1, p2 = PEER[a[0]]
            ours = b["particle_steps_per_s"]
            theirs = p1 if a[1] == 1 else p2
            rows.append([int(b["fluid"]), "%.3f" % (a[2] / 1000), a[1], "%.3g" % ours, "%.3g" % theirs,
                         "%.2fx" % (ours / theirs), "%.1f" % b["pairs_per_particle"], "%d" % b["steps"]])
        rows.sort(key=lambda r: (r[0], r[2]))
        for r in rows:
            r[0] = fmt_count(r[0])
        md += ["### The peer: DualSPHysics 5.4's dam break (`sph_bench_peer`)", "",
               "Fluid particle-steps per second of the whole solver run from rest (no output), ours at h/d = sqrt(2) "
               "like the peer's; its figures are `../shared/ANCHORS.md`'s (medians of 5). Target 1.5x.", ""]
        md += table(["fluid particles", "h/d", "threads", "sphrefine", "DualSPHysics", "ratio", "pairs/particle",
                     "steps"], rows)
        md += [""]

    if runs.get("dims"):
        # BM_Step_Tank<D>/N/threads: the still tank in 2D and 3D; the cost per pair and per particle-step.
        by = {}
        for b in runs["dims"]:
            name = b["name"]
            dim = 3 if "<3>" in name else 2
            a = args_of(name.split(">", 1)[1])
            by[(dim, a[0], a[1])] = b
        rows = []
        for (dim, n, t) in sorted(by):
            b = by[(dim, n, t)]
            ns_pair = 1e9 / b["pairs_per_s"]
            other = by.get((2, n, t))
            ratio = "%.2f" % (ns_pair / (1e9 / other["pairs_per_s"])) if dim == 3 and other else ""
            rows.append([dim, fmt_count(n), fmt_count(b["fluid"]), t, "%.3g" % ms(b), "%.3g" % b["items_per_second"],
                         "%.3f" % (1e6 / b["items_per_second"]), "%.1f" % b["pairs_per_particle"], "%.1f" % ns_pair,
                         ratio])
        md += ["### 2D and 3D: the cost of a pair and of a particle-step (`sph_bench_step`, BM_Step_Tank)", "",
               "The still tank (2D: 25 m x 10 m; 3D: 1 m x 0.4 m x 0.5 m of water) at N fluid particles, h = 1.2 d, ghost "
               "walls, viscosity; `sim.step()` repeated. ns/pair is the step's wall time over the pair interactions it "
               "evaluated (each side of a pair counted). Targets (issue #18): 3D per pair at most 1.5x 2D; 3D per "
               "particle-step flat within 20 % from 1e4 to 1e6.", ""]
        md += table(["D", "N", "fluid", "threads", "ms/step", "particle-steps/s", "us/particle-step", "pairs/particle",
                     "ns/pair", "3D / 2D per pair"], rows)
        ref = [1e6 / by[(3, n, 1)]["items_per_second"] for n in sorted({k[1] for k in by}) if (3, n, 1) in by]
        if ref:
            mid = sum(ref) / len(ref)
            md += ["", "3D time per particle-step, 1 thread, %s-%s: mean %.3f us, largest deviation %.0f %% (target +-20 %%)."
                   % (fmt_count(min(k[1] for k in by)), fmt_count(max(k[1] for k in by)), mid,
                      100 * max(abs(r / mid - 1) for r in ref))]
        md += [""]

    if runs.get("peer3d"):
        rows = []
        for b in runs["peer3d"]:
            a = args_of(b["name"])
            if len(a) < 3:
                continue
            p1, p2 = PEER3D[a[0]]
            ours = b["particle_steps_per_s"]
            theirs = p1 if a[1] == 1 else p2
            rows.append([int(b["fluid"]), int(b["walls"]), "%.3f" % (a[2] / 1000), a[1], "%.3g" % ours, "%.3g" % theirs,
                         "%.2fx" % (ours / theirs), "%.3g" % b["pairs_per_s"], "%.1f" % b["pairs_per_particle"],
                         "%d" % b["steps"]])
        rows.sort(key=lambda r: (r[0], r[2], r[3]))
        for r in rows:
            r[0] = fmt_count(r[0])
            r[1] = fmt_count(r[1])
        md += ["### The peer in 3D: DualSPHysics' CaseDambreak (`sph_bench_peer`, BM_Peer_DamBreak3D)", "",
               "Its 3D dam break (a 0.4 x 0.67 x 0.3 m block, a 1.6 x 0.67 x 0.4 m tank, a 0.12 x 0.12 x 0.45 m column) "
               "from rest over its windows, whole solver run, no output, density diffusion 0.1, c0 = 20 sqrt(g H); ours "
               "with ghost walls and Lennard-Jones wall particles at dp / 2 (the walls column), at its h = sqrt(3) dp and "
               "at our default 1.2 dp. Its figures are `../shared/ANCHORS.md`'s (its fluid counts 30,624 / 128,310 / "
               "638,400; medians of 3), measured on another day: the ratio is indicative.", ""]
        md += table(["fluid particles", "wall particles", "h/d", "threads", "sphrefine", "DualSPHysics", "ratio",
                     "pairs/s", "pairs/particle", "steps"], rows)
        md += [""]

    if runs.get("busy"):
        # BM_Program/<case>/<variant>/<quiet|busy>: whole `sphrefine run` processes, 1 s of the dam break.
        times = {}
        for b in runs["busy"]:
            parts = b["name"].split("/")
            if len(parts) >= 4:
                times[(parts[1], parts[2], parts[3])] = ms(b) / 1e3
        rows = []
        for (case, variant) in sorted({(c, v) for (c, v, _) in times}):
            quiet, busy = times.get((case, variant, "quiet")), times.get((case, variant, "busy"))
            if quiet and busy:
                rows.append([case, variant.replace("_", " "), "%.2f" % quiet, "%.2f" % busy, "%.1fx" % (busy / quiet)])
        md += ["### The program on busy cores (`sph_bench_busy`)", "",
               "`sphrefine run cases/dam_break.json` to t = 1 s as a whole process, on quiet cores and with a busy loop "
               "on every core (threads of the benchmark, started before the run and stopped after it). `default` is "
               "the program as a user starts it (threads from the work, passive wait policy); `old 2threads active` "
               "forces what it did before (`--threads 2`, `OMP_WAIT_POLICY=active`). Target: busy at most 2x quiet.", ""]
        md += table(["case", "variant", "quiet (s)", "busy (s)", "busy / quiet"], rows)
        md += [""]

    md += [END]
    block = "\n".join(md)
    text = open(DOC).read() if os.path.exists(DOC) else "# Performance\n"
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + block + text[text.index(END) + len(END):]
    else:
        text = text.rstrip("\n") + "\n\n## Measured (regenerated by `scripts/bench`)\n\n" + block + "\n"
    with open(DOC + ".tmp", "w") as f:
        f.write(text)
    os.replace(DOC + ".tmp", DOC)
    print("wrote %s and docs/figures/perf_*.png" % DOC)


if __name__ == "__main__":
    main()
