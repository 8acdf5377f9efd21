#!/usr/bin/python3
"""The static force imbalance of a hydrostatic lattice across a 2:1 level jump, for several pressure-term
forms (docs/METHOD.md, "Still water across a level jump").

    /usr/bin/python3 tools/level_jump_residuals.py [--interface | --balance]

A 40 x 30 lattice (spacing d = 1 m, h = 1.2 d, rho = 1, p/rho = g (30 - y)) whose block [15,25] x [10,20] is
split by AAP (daughters at +-d/4, h/2 unless a ratio is given). For each form it prints the largest
|a_i - g| over the particles at least 4 m from the lattice's edges, coarse and fine apart (m/s^2). The
kernel is the cubic spline of core/kernel.hpp, written again here in numpy because this evaluates the sums
outside the solver (every pair against every other, no cell grid).

--interface prints instead the kernel sums sigma_i = sum_j m_j W(r_ij, h_ij) (rho = 1) along a row across the
jump, and the jump's excess: sum_i m_i (sigma_i - sigma of i's level's bulk) over the particles near the block,
per metre of the block's perimeter, coarse and fine apart, for several rules for h_ij. Under a pressure p the
elastic energy changes by p / rho^2 times the change of sum_i m_i rho_i, so a negative excess means a jump that
releases energy as it grows (docs/METHOD.md, "the level jump's interface energy").

--balance prints, for the mean and the quadratic-mean h_ij, the largest residual of the symmetric form before and
after the least-squares pressure change of the particles within 1, 2 and 3 m of the block's edge that minimises it,
and that change's size (docs/METHOD.md, "No pressures balance the split").
"""
import sys

import numpy as np

SIGMA = 10.0 / (7.0 * np.pi)
D, HF, G, TOP = 1.0, 1.2, 9.81, 30.0
ZONE = (15, 10, 25, 20)


def dwdr(r, h):
    q = r / h
    c = SIGMA / h ** 3
    with np.errstate(over="ignore", invalid="ignore"):
        return np.where(q < 1, c * (-3 * q + 2.25 * q * q), np.where(q < 2, c * (-0.75 * (2 - q) ** 2), 0.0))


def lattice(zone, ratio=0.5):
    X, H, M, L = [], [], [], []
    for i in range(40):
        for j in range(30):
            x = np.array([(i + 0.5) * D, (j + 0.5) * D])
            if zone[0] <= x[0] <= zone[2] and zone[1] <= x[1] <= zone[3]:
                for o in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                    X.append(x + 0.25 * D * np.array(o)); H.append(HF * D * ratio); M.append(D * D / 4); L.append(1)
            else:
                X.append(x); H.append(HF * D); M.append(D * D); L.append(0)
    return np.array(X), np.array(H), np.array(M), np.array(L)


def smooth_h(X, H, slope):
    """A transition band: h_i = max(h_i, max_j (h_j - slope r_ij))."""
    return np.array([max(H[i], np.max(H - slope * np.hypot(*(X - X[i]).T))) for i in range(len(X))])


def residuals(form, ratio=0.5, slope=None, zone=ZONE):
    X, H, M, L = lattice(zone, ratio)
    if slope is not None:
        H = smooth_h(X, H, slope)
    p = G * (TOP - X[:, 1])
    sel = np.where((X[:, 0] > 6) & (X[:, 0] < 34) & (X[:, 1] > 4) & (X[:, 1] < 26))[0]
    res = np.zeros(len(sel))
    for k, i in enumerate(sel):
        xij = X[i] - X
        r = np.hypot(xij[:, 0], xij[:, 1])
        r[i] = np.inf
        hi, hj = H[i], H
        mean = dwdr(r, 0.5 * (hi + hj)) / r
        mixed = np.any((H != hi) & (r < 2 * np.maximum(hi, H)))
        if form == "avggrad":
            fi = fj = 0.5 * (dwdr(r, hi) + dwdr(r, hj)) / r
        elif form == "max":
            fi = fj = dwdr(r, np.maximum(hi, hj)) / r
        elif form == "lagrangian":
            fi, fj = dwdr(r, hi) / r, dwdr(r, hj) / r
        else:
            fi = fj = mean
        gw = M[:, None] * mean[:, None] * xij  # V_j grad W (rho = 1)
        if form == "difference" or (form == "band" and mixed):
            a = -((p - p[i])[:, None] * gw).sum(0)
        elif form == "mixed_pairs":
            a = -((np.where(H != hi, p - p[i], p + p[i]))[:, None] * gw).sum(0)
        elif form == "band_corrected" and mixed:
            moment = np.einsum("ja,jb->ab", gw, -xij)
            a = -np.linalg.solve(moment, ((p - p[i])[:, None] * gw).sum(0))
        else:
            a = -(M[:, None] * (p[i] * fi + p * fj)[:, None] * xij).sum(0)
        res[k] = np.hypot(*(a + np.array([0.0, -G])))
    lev = L[sel]
    return res[lev == 0].max(), (res[lev == 1].max() if (lev == 1).any() else float("nan"))


def kernel(r, h):
    q = r / h
    c = SIGMA / h ** 2
    return np.where(q < 1, c * (1 - 1.5 * q * q + 0.75 * q ** 3), np.where(q < 2, c * 0.25 * (2 - q) ** 3, 0.0))


PAIR_H = {"mean (the paper's)": lambda hi, hj: 0.5 * (hi + hj),
          "quadratic mean": lambda hi, hj: np.sqrt(0.5 * (hi * hi + hj * hj)),
          "max": np.maximum}


def kernel_sums(rule, zone=ZONE):
    X, H, M, L = lattice(zone)
    if rule == "averaged kernel":
        sig = np.array([(M * 0.5 * (kernel(np.hypot(*(X - X[i]).T), H[i]) + kernel(np.hypot(*(X - X[i]).T), H))).sum()
                        for i in range(len(X))])
    else:
        sig = np.array([(M * kernel(np.hypot(*(X - X[i]).T), PAIR_H[rule](H[i], H))).sum() for i in range(len(X))])
    return X, M, L, sig


def interface():
    x0, y0, x1, y1 = ZONE
    perimeter = 2.0 * ((x1 - x0) + (y1 - y0))
    print("| h_ij | sigma: coarse at the jump, first and second fine column | excess per m: coarse, fine, total |")
    print("|---|---|---|")
    for rule in list(PAIR_H) + ["averaged kernel"]:
        X, M, L, sig = kernel_sums(rule)
        inner = (X[:, 0] > 5) & (X[:, 0] < 35) & (X[:, 1] > 4) & (X[:, 1] < 26)
        coarse_bulk = sig[(L == 0) & inner & ((X[:, 0] < 10) | (X[:, 0] > 30))].mean()
        fine_bulk = sig[(L == 1) & (np.abs(X[:, 0] - 20) < 1.5) & (np.abs(X[:, 1] - 15) < 1.5)].mean()
        excess = np.where(L == 0, sig - coarse_bulk, sig - fine_bulk) * M
        c, f = excess[inner & (L == 0)].sum() / perimeter, excess[inner & (L == 1)].sum() / perimeter
        row = np.abs(X[:, 1] - 14.6) < 0.2  # the row y = 14.5 (coarse) and 14.75 (fine)
        at = lambda x: sig[row & (np.abs(X[:, 0] - x) < 0.01)][0]  # noqa: E731
        print(f"| {rule} | {at(14.5):.3f}, {at(15.25):.3f}, {at(15.75):.3f} | {c:+.4f}, {f:+.4f}, {c + f:+.4f} |")


def balance_rows(rule, band):
    """The symmetric form's residual g - sum_j m_j (p_i + p_j) F_ij x_ij (rho = 1, F_ij = W'(r_ij, h_ij) / r_ij) as a
    linear map of the pressures: the residual of the hydrostatic pressures, then the least-squares pressure change
    of the particles within `band` of the block's edge that makes it smallest over the particles away from the
    lattice's edges."""
    X, H, M, L = lattice(ZONE)
    p0 = G * (TOP - X[:, 1])
    eq = np.where((X[:, 0] > 6) & (X[:, 0] < 34) & (X[:, 1] > 4) & (X[:, 1] < 26))[0]
    x0, y0, x1, y1 = ZONE
    inside = (X[:, 0] > x0) & (X[:, 0] < x1) & (X[:, 1] > y0) & (X[:, 1] < y1)
    edge = np.minimum.reduce([np.abs(X[:, 0] - x0), np.abs(X[:, 0] - x1), np.abs(X[:, 1] - y0), np.abs(X[:, 1] - y1)])
    outside = np.hypot(np.maximum(0, np.maximum(x0 - X[:, 0], X[:, 0] - x1)),
                       np.maximum(0, np.maximum(y0 - X[:, 1], X[:, 1] - y1)))
    near = np.where(np.where(inside, edge, outside) < band)[0]
    A = np.zeros((2 * len(eq), len(X)))
    for k, i in enumerate(eq):
        xij = X[i] - X
        r = np.hypot(xij[:, 0], xij[:, 1])
        r[i] = np.inf
        f = dwdr(r, PAIR_H[rule](H[i], H)) / r
        t = -(M * f)[:, None] * xij  # d a_i / d p_j, and d a_i / d p_i is their sum
        A[2 * k:2 * k + 2, :] += t.T
        A[2 * k:2 * k + 2, i] += t.sum(0)
    gvec = np.tile([0.0, -G], len(eq))
    r0 = A @ p0 + gvec
    dp, *_ = np.linalg.lstsq(A[:, near], -r0, rcond=None)
    r1 = r0 + A[:, near] @ dp
    mag = lambda r: np.hypot(r[0::2], r[1::2])  # noqa: E731
    lev = L[eq]
    c0sq = 100.0 * G * TOP  # the tank's sound speed, mach factor 10 over the water's height: c0 = 10 sqrt(g H)
    return (mag(r0)[lev == 0].max(), mag(r0)[lev == 1].max(), mag(r1)[lev == 0].max(), mag(r1)[lev == 1].max(),
            np.abs(dp).max() / (G * TOP), np.abs(dp).max() / c0sq, len(near))


def balance():
    print("| h_ij | band (m) | residual before: coarse, fine | after: coarse, fine | max dp / (rho g H) | "
          "max d rho / rho | particles changed |")
    print("|---|---|---|---|---|---|---|")
    for rule in ("mean (the paper's)", "quadratic mean"):
        for band in (1.0, 2.0, 3.0):
            b0c, b0f, b1c, b1f, dp, drho, n = balance_rows(rule, band)
            print(f"| {rule} | {band:g} | {b0c:.2g}, {b0f:.3g} | {b1c:.2g}, {b1f:.3g} | {dp:.4f} | {drho:.2e} | {n} |")


def main():
    if "--interface" in sys.argv[1:]:
        interface()
        return
    if "--balance" in sys.argv[1:]:
        balance()
        return
    rows = [("uniform lattice, no jump", dict(form="symmetric", zone=(-9, -9, -8, -8))),
            ("paper: h_ij mean, daughters h/2", dict(form="symmetric"))]
    rows += [(f"daughters' h ratio {q}", dict(form="symmetric", ratio=q)) for q in (0.6, 0.7, 0.8)]
    rows += [("averaged gradient", dict(form="avggrad")), ("h_ij = max", dict(form="max")),
             ("variable-h (Lagrangian)", dict(form="lagrangian")),
             ("transition band, slope 0.1", dict(form="symmetric", slope=0.1)),
             ("difference form, every pair", dict(form="difference")),
             ("difference form, mixed pairs only", dict(form="mixed_pairs")),
             ("difference form, band", dict(form="band")),
             ("difference form, band, gradient-corrected", dict(form="band_corrected"))]
    print("| pair form | coarse at the jump | fine at the jump |\n|---|---|---|")
    for name, kw in rows:
        c, f = residuals(**kw)
        print(f"| {name} | {c:.2g} | {f:.3g} |")


if __name__ == "__main__":
    main()
