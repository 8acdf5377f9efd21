#!/usr/bin/python3
"""Local quantities and probe errors of the validation report (tools/validation_report.py), from a run's time
series (series.csv columns as numpy arrays).

Impact pressure at a wall sensor (the dam break's far wall, Lobovsky's sensor 1):
  - peak: the largest value of the pressure averaged over a sliding window of `window` (in the signal's own time
    unit). A weakly-compressible run's wall pressure carries acoustic noise of several times rho g H from output
    to output at the impact (docs/VALIDATION.md), so its raw maximum measures the noise as much as the load; the
    window is the time the surge front, at Ritter's speed 2 sqrt(g H), takes to cross one coarse kernel support
    2h = 2.4 d0 (h = 1.2 d0): in t* = t sqrt(g/H) units, 1.2 d0 / H. A physical sensor averages over its face too.
    The raw maximum is given beside it.
  - impulse: the time integral of the pressure over a fixed window that holds the impact in every run.
Probe errors: each probe's RMS difference from the reference over a window, divided by the range (max - min) of
the reference's signal over that window. The window starts where the reference first leaves its initial value
by more than 5 % of its range (before that every run sits at the initial state and must agree) and may end
earlier by the caller's rule (the dam break's front, once it reaches the far wall).

    /usr/bin/python3 tools/test_local_quantities.py   checks these definitions (ctest tools.local_quantities)
"""
import numpy as np

DEPARTURE = 0.05  # a signal "has left" its initial value once it differs by 5 % of its range


def sliding_mean(t, y, window):
    """The mean of y over [t - window/2, t + window/2] at every sample, for samples at any spacing: the
    integral of the piecewise-linear signal over the window (trapezoids, cumulative), divided by the window's
    length within the record."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))])

    def integral(a):  # integral of y from t[0] to a (a within the record)
        a = np.clip(a, t[0], t[-1])
        k = np.clip(np.searchsorted(t, a, side="right") - 1, 0, len(t) - 2)
        frac = a - t[k]
        slope = (y[k + 1] - y[k]) / np.where(t[k + 1] > t[k], t[k + 1] - t[k], 1.0)
        return cum[k] + frac * (y[k] + 0.5 * slope * frac)

    lo = np.clip(t - 0.5 * window, t[0], t[-1])
    hi = np.clip(t + 0.5 * window, t[0], t[-1])
    span = hi - lo
    return np.where(span > 0, (integral(hi) - integral(lo)) / np.where(span > 0, span, 1.0), y)


def impact(t, p, window, t_lo, t_hi):
    """(peak of the sliding mean, raw peak, impulse) of a pressure record over t_lo <= t <= t_hi; the impulse is
    the trapezoidal integral of p over that span (the record interpolated at its ends)."""
    t = np.asarray(t, dtype=float)
    p = np.nan_to_num(np.asarray(p, dtype=float))
    if t[-1] < t_hi or t[0] > t_lo:
        return float("nan"), float("nan"), float("nan")
    inside = (t > t_lo) & (t < t_hi)
    ts = np.concatenate([[t_lo], t[inside], [t_hi]])
    ps = np.concatenate([[np.interp(t_lo, t, p)], p[inside], [np.interp(t_hi, t, p)]])
    smooth = sliding_mean(t, p, window)
    w = (t >= t_lo) & (t <= t_hi)
    return float(smooth[w].max()), float(p[w].max()), float(np.trapz(ps, ts))


def extreme(t, y, t_lo, t_hi, largest=True):
    """The largest (or smallest) value of y over t_lo <= t <= t_hi, NaN read as absent."""
    w = (t >= t_lo) & (t <= t_hi) & np.isfinite(y)
    if not w.any():
        return float("nan")
    return float(y[w].max() if largest else y[w].min())


def departure_time(t, y):
    """The first time y differs from its initial value by more than DEPARTURE of its range."""
    y = np.asarray(y, dtype=float)
    fin = np.isfinite(y)
    rng = np.nanmax(y) - np.nanmin(y)
    if not fin.any() or rng <= 0:
        return float(t[0])
    moved = fin & (np.abs(y - y[fin][0]) > DEPARTURE * rng)
    return float(t[np.argmax(moved)]) if moved.any() else float(t[-1])


def probe_error(t, y, t_ref, y_ref, t_start=None, t_end=None):
    """(RMS of y - y_ref over the window / range of y_ref over the window, window start, window end). The
    window runs from the reference's departure from its initial value (or t_start, if later) to t_end (default:
    the shorter record's end); y_ref is interpolated at y's times. NaN samples (a dry gauge) are left out."""
    t = np.asarray(t, dtype=float)
    t_ref = np.asarray(t_ref, dtype=float)
    start = departure_time(t_ref, y_ref)
    if t_start is not None:
        start = max(start, t_start)
    end = min(t[-1], t_ref[-1]) if t_end is None else min(t_end, t[-1], t_ref[-1])
    ok_ref = np.isfinite(y_ref)
    wr = ok_ref & (t_ref >= start) & (t_ref <= end)
    w = (t >= start) & (t <= end) & np.isfinite(y)
    if not wr.any() or not w.any():
        return float("nan"), start, end
    rng = float(y_ref[wr].max() - y_ref[wr].min())
    diff = y[w] - np.interp(t[w], t_ref[ok_ref], y_ref[ok_ref])
    return (float(np.sqrt(np.mean(diff ** 2)) / rng) if rng > 0 else float("nan")), start, end
