#!/usr/bin/python3
"""How one step of the integrator (core/integrator.hpp) amplifies an acoustic mode, for each predictor
(time.predictor; docs/METHOD.md, "The predictor").

    /usr/bin/python3 tools/acoustic_amplification.py [--z 0.1,0.2,...]

The model is one linear acoustic mode of frequency omega, the velocity and density perturbations scaled so that
    dv/dt = -omega rho,   drho/dt = omega v
(the pressure term drives v, the continuity term drives rho; the positions are held fixed). One step of length
dt, z = omega dt, as the integrator takes it with one global step:
    open:     vh = v + dt/2 a,  rhoh = rho + dt/2 drho             (a, drho: the last evaluation's rates)
    predict:  v* = vh + dt/2 a + e dt/2 (a - a_prev),  rho* likewise    (e = 1 extrapolated, 0 last_rate)
    evaluate: a' = -omega rho*,  drho' = omega v*
    close:    v' = vh + dt/2 a',  rho' = rhoh + dt/2 drho'
The state (v, rho, a, drho, a_prev, drho_prev) maps linearly onto the next; the largest modulus of that map's
eigenvalues, minus one, is the mode's growth (> 0) or decay (< 0) per step. A symplectic scheme would give 0.
Prints a table of both predictors against z, and the z up to which the extrapolated predictor damps every mode.
"""
import argparse

import numpy as np


def step_matrix(z, extrapolated):
    """The 6x6 map of (v, rho, a, drho, a_prev, drho_prev) over one step of z = omega dt (omega = 1)."""
    dt = z
    e = 1.0 if extrapolated else 0.0
    m = np.zeros((6, 6))
    for k in range(6):
        v, rho, a, drho, a_prev, drho_prev = np.eye(6)[k]
        vh, rhoh = v + 0.5 * dt * a, rho + 0.5 * dt * drho
        v_pred = vh + 0.5 * dt * a + e * 0.5 * dt * (a - a_prev)
        rho_pred = rhoh + 0.5 * dt * drho + e * 0.5 * dt * (drho - drho_prev)
        a_new, drho_new = -rho_pred, v_pred
        m[:, k] = [vh + 0.5 * dt * a_new, rhoh + 0.5 * dt * drho_new, a_new, drho_new, a, drho]
    return m


def growth(z, extrapolated):
    return float(np.max(np.abs(np.linalg.eigvals(step_matrix(z, extrapolated))))) - 1.0


def damping_limit(extrapolated=True, z_max=2.0, points=4001):
    """The smallest z > 0 at which the step stops damping (growth crosses 0 upwards), to 1e-3 in z."""
    zs = np.linspace(1e-3, z_max, points)
    g = [growth(z, extrapolated) for z in zs]
    for k in range(1, len(zs)):
        if g[k - 1] <= 0.0 < g[k]:
            return float(zs[k])
    return float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--z", default="0.115,0.23,0.31,0.41,0.46,0.5,0.62,0.7,0.8,1.0")
    args = ap.parse_args()
    print("| z = omega dt | last_rate: growth per step | extrapolated: growth per step |")
    print("|---|---|---|")
    for z in (float(x) for x in args.z.split(",")):
        print(f"| {z:g} | {growth(z, False):+.2e} | {growth(z, True):+.2e} |")
    print()
    print(f"The extrapolated predictor damps every mode up to z = {damping_limit():.3f}; the last-rate one grows every "
          "mode (z^4/4 a step to leading order).")


if __name__ == "__main__":
    main()
