#!/usr/bin/python3
"""Reference probe series for the case regression tests (tests/test_cases.cpp).

Runs every case file of cases/ and cases/validation/ to its full end time with the release build (one
thread), and stores its time series (time, step, mass and the probe columns) as
tests/data/case_references/<case>.csv, with a header naming the command and the commit. The test runs each
case to a fraction of its end time and compares the probes with these rows.

    /usr/bin/python3 tools/case_references.py [case ...]     (default: every case; SPH_APP=binary to use another build)
"""
import csv
import glob
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# SPH_APP names another sphrefine binary (the mpi preset's, which runs one process as the release build does).
APP = os.environ.get("SPH_APP", os.path.join(ROOT, "build", "release", "app", "sphrefine"))
OUT = os.path.join(ROOT, "tests", "data", "case_references")
RUNS = os.path.join(ROOT, "results", "case_references")
KEEP = ("time", "step", "fluid", "mass")  # plus every probe column (those after max_density_error)


def case_files():
    files = sorted(glob.glob(os.path.join(ROOT, "cases", "*.json")))
    return files + sorted(glob.glob(os.path.join(ROOT, "cases", "validation", "*.json")))


def main():
    wanted = set(sys.argv[1:])
    os.makedirs(OUT, exist_ok=True)
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip() or "unknown"
    for scene in case_files():
        name = os.path.splitext(os.path.basename(scene))[0]
        if wanted and name not in wanted:
            continue
        run = os.path.join(RUNS, name)
        cmd = [APP, "run", scene, "-o", run, "--force", "-q", "--threads", "1"]
        print("case_references:", name, flush=True)
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(run, "series.csv")) as f:
            rows = list(csv.reader(f))
        header = rows[0]
        probes = header[header.index("max_density_error") + 1:]
        columns = [c for c in KEEP if c in header] + probes
        index = [header.index(c) for c in columns]
        rel = os.path.relpath(scene, ROOT)
        with open(os.path.join(OUT, name + ".csv"), "w") as f:
            f.write("# Reference series of %s: the full-length run `sphrefine run %s --threads 1` at commit %s\n"
                    % (rel, rel, commit))
            f.write("# (tools/case_references.py). tests/test_cases.cpp compares a shortened run with these rows.\n")
            f.write(",".join(columns) + "\n")
            for r in rows[1:]:
                f.write(",".join(r[i] for i in index) + "\n")
    print("wrote", OUT)


if __name__ == "__main__":
    main()
