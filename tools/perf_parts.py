#!/usr/bin/python3
"""The time of a run by part of the step, from a perf recording (docs/PERFORMANCE.md, "Where a per-level run's time
goes"): the share of the samples in the pair sweep, the neighbour rebuild (grid build, ghost expansion, cell sort,
gather, ghosts' values), the drift loop (kick, drift, output counts), the bin passes (bin choice, neighbourhood
limits, limiter) and the rest.

    perf record -o perf.data build/release/app/sphrefine run CASE -o OUT --force -q --threads 1
    /usr/bin/python3 tools/perf_parts.py perf.data
"""
import os
import re
import subprocess
import sys

# Each part and the symbol fragments that belong to it, tried in this order (the first match wins).
PARTS = [
    ("sweep", ["PairSweep"]),
    ("bins", ["choose_bins", "neighbourhood_bins", "limit_bins", "copy_next_bins", "next_bins_differ"]),
    ("drift", ["step(double)::{lambda(sph::SmoothingRange"]),
    ("rebuild", ["build_neighbours", "counting_sort", "GhostBuilderT", "Layer::coords", "exclusive_scan"]),
]


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    data = sys.argv[1]
    if not os.path.isfile(data):
        sys.exit(f"{data}: no such perf recording")
    r = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", "symbol", "-g", "none"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"perf report -i {data} failed: {r.stderr.strip()}")
    shares = {name: 0.0 for name, _ in PARTS}
    shares["other"] = 0.0
    for line in r.stdout.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+\[(.)\]\s+(.*)", line)
        if not m:
            continue
        share, symbol = float(m.group(1)), m.group(3)
        part = next((name for name, keys in PARTS if any(k in symbol for k in keys)), "other")
        shares[part] += share
    print("| " + " | ".join(shares) + " |")
    print("|" + "---|" * len(shares))
    print("| " + " | ".join(f"{v:.1f} %" for v in shares.values()) + " |")


if __name__ == "__main__":
    main()
