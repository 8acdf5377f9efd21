#!/usr/bin/python3
"""Runs across ranks on this machine (issue #19), measured by whole-process timing of the mpi build's sphrefine.

  - The step at 1e6 particles (the paper's dam break at d = 0.025 m: 1e6 fluid particles): 1 rank x 1 thread,
    1 rank x 2 threads, 2 ranks x 1 thread. A step's time is the difference of two runs' wall time (run.json;
    end times for about 20 and 40 steps, 28 and 57 in fact) over the steps between: the set-up, the first outputs
    and MPI's start-up cancel.
  - The share of a step spent in the exchange (halos and migration): run.json's exchange.seconds_most (the most
    one rank spent in exchanges, waiting for the other included) over the run's wall time, same difference.
  - The dynamic dam break (AAP) at 4x the paper's count (3600 particles to start, to t = 4 s): on 2 ranks x 1
    thread against 1 rank x 1 and x 2 threads, and the recuts, with the loads before and after and their cost.
  - Memory per rank: the largest peak resident set of the ranks (run.json's peak_rss_bytes) at 1, 2 and 4 ranks of
    one thread, the 1e6-particle dam break for 15 steps (set-up included: each rank builds only its share).

usage: mpi_bench.py SPHREFINE OUT.json  (run it on an otherwise idle machine)
"""
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_WAIT_POLICY="PASSIVE",
           OMPI_MCA_rmaps_base_oversubscribe="1")


def run(exe, ranks, threads, scene, out, sets):
    cmd = ["mpirun", "-np", str(ranks), "--bind-to", "none", exe, "run", str(scene), "-o", str(out), "--force",
           "--quiet", "--threads", str(threads)]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, env=ENV, check=True)
    return json.loads((Path(out) / "run.json").read_text())


def step_cost(exe, ranks, threads, work):
    d = 0.025
    dt = 0.2 * 1.2 * d / (10 * (9.81 * 25) ** 0.5)  # C h / c0: the first steps' dt
    base = ["fluid[0].spacing=0.025", "output.frames=false", "probes=[]"]
    rows = {}
    for steps in (20, 40):
        end = (steps - 0.5) * dt
        r = run(exe, ranks, threads, ROOT / "cases/dam_break.json", work / f"step_{ranks}x{threads}_{steps}",
                base + [f"time.end={end}", f"time.output_interval={end}"])
        rows[steps] = r
    a, b = rows[20], rows[40]
    n = b["steps_this_run"] - a["steps_this_run"]
    step = (b["wall_seconds"] - a["wall_seconds"]) / n
    out = {"ranks": ranks, "threads": threads, "steps": n, "seconds_per_step": step,
           "fluid": b["fluid_per_level"][0], "peak_rss_bytes_most_rank": b.get("peak_rss_bytes")}
    if "exchange" in b:
        ex = (b["exchange"]["seconds_most"] - a["exchange"]["seconds_most"]) / n
        out["exchange_seconds_per_step"] = ex
        out["exchange_share"] = ex / step
        out["bytes_per_step"] = (b["exchange"]["bytes_sent"] - a["exchange"]["bytes_sent"]) / n
        out["halo_copies_per_step"] = (b["exchange"]["halo_copies"] - a["exchange"]["halo_copies"]) / n
    print(json.dumps(out), flush=True)
    return out


def memory(exe, work):
    base = ["fluid[0].spacing=0.025", "output.frames=false", "probes=[]", "time.end=0.0004",
            "time.output_interval=0.0004"]
    rows = []
    for ranks in (1, 2, 4):
        r = run(exe, ranks, 1, ROOT / "cases/dam_break.json", work / f"memory_{ranks}", base)
        rows.append({"ranks": ranks, "steps": r["steps_this_run"], "peak_rss_mib_largest_rank": r["peak_rss_bytes"] / 2**20})
        print(json.dumps(rows[-1]), flush=True)
    return rows


def main():
    exe, out = sys.argv[1], Path(sys.argv[2])
    work = out.parent / "mpi_bench_runs"
    work.mkdir(parents=True, exist_ok=True)
    result = {"step_1e6": [step_cost(exe, r, t, work) for (r, t) in ((1, 1), (1, 2), (2, 1))],
              "memory_1e6": memory(exe, work)}
    # The dynamic dam break at 4x (d / 2, 3600 particles to start), AAP splits, on 2 ranks.
    dyn = run(exe, 2, 1, ROOT / "cases/dam_break_aap.json", work / "dynamic_2ranks",
              ["fluid[0].spacing=0.4166666666666667", "output.frames=false"])
    one = run(exe, 1, 1, ROOT / "cases/dam_break_aap.json", work / "dynamic_1rank",
              ["fluid[0].spacing=0.4166666666666667", "output.frames=false"])
    two = run(exe, 1, 2, ROOT / "cases/dam_break_aap.json", work / "dynamic_1rank_2threads",
              ["fluid[0].spacing=0.4166666666666667", "output.frames=false"])
    result["dynamic_dam_break_4x"] = {
        "ranks": 2, "wall_seconds": dyn["wall_seconds"], "wall_seconds_one_rank": one["wall_seconds"],
        "wall_seconds_one_rank_two_threads": two["wall_seconds"], "fluid_per_level": dyn["fluid_per_level"],
        "exchange": dyn["exchange"]}
    print(json.dumps(result["dynamic_dam_break_4x"]), flush=True)
    out.write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
