#!/usr/bin/python3
"""ctest check of tools/pareto.py, the verdicts of the validation report's accuracy-against-cost answer.

- The uniform front keeps the runs no other uniform run beats in both cost and E_v; by wall time, a run is left
  off when another is more accurate and at most TIMING_SPREAD dearer (their costs cannot be ordered), by force
  evaluations (deterministic) only when another is more accurate and no dearer.
- equal_error_cost interpolates in log-log between the two front runs that bracket an error (exact on a power
  law), and says "above" or "below" outside the front.
- words() calls a variant cheaper only when its ratio is below 1 by more than the spread, and dearer when it is
  less accurate than the cheapest uniform run.

    /usr/bin/python3 tools/test_pareto.py
Exit status 0 on success, 1 on failure.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402
import pareto  # noqa: E402

check = Checks("test_pareto")


def run(name, wall, evaluations, e_v, uniform=True):
    return dict(name=name, uniform=uniform, completed=True, wall=wall, evaluations=evaluations, E_v=e_v)


# The drop's case that moved a verdict: two uniform runs at the same particle count, 5 % apart in wall time.
rows = [run("u1", 1.0, 1e6, 0.06), run("lattice4", 7.9, 1.50e7, 0.048), run("split4", 8.3, 1.53e7, 0.041),
        run("u16", 78.0, 1.2e8, 0.030)]
front = [r["name"] for r in pareto.uniform_front(rows, "wall")]
check(front == ["u1", "split4", "u16"], f"by wall time the cheaper, less accurate run within the spread is left off ({front})")
front_e = [r["name"] for r in pareto.uniform_front(rows, "evaluations")]
check(front_e == ["u1", "lattice4", "split4", "u16"], f"by evaluations every non-dominated run stays ({front_e})")
far = rows + [run("lattice4_cheap", 5.0, 1.0e7, 0.048)]  # 1.66x cheaper than split4: beyond the spread
front_far = [r["name"] for r in pareto.uniform_front(far, "wall")]
check("lattice4_cheap" in front_far, f"a run cheaper by more than the spread stays on the front ({front_far})")

# Interpolation is exact on a power law cost = e^-2.
law = [run(f"u{k}", (0.1 / k) ** -2, 1.0, 0.1 / k) for k in (1, 2, 4)]
f = pareto.uniform_front(law, "wall")
cost, how = pareto.equal_error_cost(f, 0.07, "wall")
check(how == "interpolated" and abs(cost - 0.07 ** -2) < 1e-9 * cost, f"log-log interpolation on a power law ({cost}, {how})")
check(pareto.equal_error_cost(f, 0.2, "wall") == (law[0]["wall"], "above"), "an error above every uniform run's")
check(pareto.equal_error_cost(f, 0.01, "wall") == (law[2]["wall"], "below"), "an error below every uniform run's")

# The words: cheaper only beyond the spread; "above" is dearer.
dyn = [run("fast", 0.5 * 0.07 ** -2, 1.0, 0.07, uniform=False),   # 0.5x: cheaper
       run("even", 1.1 * 0.07 ** -2, 1.0, 0.07, uniform=False),   # 1.1x: within the spread
       run("poor", 200.0, 1.0, 0.2, uniform=False)]               # less accurate than every uniform run
text = pareto.words("Case", law + dyn, "ref")
check("cheaper than a uniform run of the same error: fast 0.50x" in text, "a 0.5x variant is called cheaper")
check("Within the spread: even 1.10x" in text, "a 1.1x variant is within the spread")
check("Dearer:" in text and "poor >= " in text.split("Dearer:")[1], "a variant less accurate than every uniform run is dearer")
check(math.isclose(pareto.TIMING_SPREAD, 0.2), "the spread is the 20 % measured between sessions")

sys.exit(check.status())
