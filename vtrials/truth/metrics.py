"""Maneuver metrics computed from the TRUE state history, by their definitions.

These are the references scoring compares reduced results against; they are computed from the
true track relative to the water (position minus the integrated current), never by running a
reduction on clean data. Definitions: IMO MSC.137(76) / MSC/Circ.1053 and ITTC 7.5-04-02-01.

All inputs are SI arrays (time [s], positions [m], heading [rad, unwrapped], velocities [m/s],
rate [rad/s]); outputs are SI except where the key says deg or dps.
"""

from __future__ import annotations

import math

import numpy as np


def _first_crossing(t: np.ndarray, f: np.ndarray, level: float, start: int = 0) -> tuple[float, int] | None:
    """First time at index ≥ start where f reaches level from below (linear interpolation)."""
    idx = np.flatnonzero(f[start:] >= level)
    if idx.size == 0:
        return None
    k = start + int(idx[0])
    if k == 0:
        return float(t[0]), 0
    f0, f1 = f[k - 1], f[k]
    a = (level - f0) / (f1 - f0) if f1 != f0 else 1.0
    return float(t[k - 1] + a * (t[k] - t[k - 1])), k


def _interp(t: np.ndarray, y: np.ndarray, tq: float) -> float:
    return float(np.interp(tq, t, y))


def fit_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares circle through points (Kåsa 1976 algebraic fit, refined by Gauss–Newton on the
    geometric distances). Returns centre x, centre y, radius."""
    A = np.column_stack([x, y, np.ones_like(x)])
    b = x ** 2 + y ** 2
    sol, *_ = np.linalg.lstsq(A, b, rcond=None)
    cx, cy = sol[0] / 2.0, sol[1] / 2.0
    R = math.sqrt(sol[2] + cx ** 2 + cy ** 2)
    for _ in range(20):
        dx, dy = x - cx, y - cy
        d = np.hypot(dx, dy)
        res = d - R
        J = np.column_stack([-dx / d, -dy / d, -np.ones_like(d)])
        step, *_ = np.linalg.lstsq(J, -res, rcond=None)
        cx, cy, R = cx + step[0], cy + step[1], R + step[2]
        if np.max(np.abs(step)) < 1e-12 * max(1.0, abs(R)):
            break
    return float(cx), float(cy), float(abs(R))


def turning(t, x_w, y_w, heading, u_r, v_r, r, *, steady_from_deg: float = 360.0,
            steady_to_deg: float = 720.0) -> dict:
    """Turning-circle metrics from EXECUTE (index 0 of the arrays).

    advance: distance along the approach heading from EXECUTE to 90° heading change; transfer:
    distance perpendicular to it at 90°; tactical diameter: perpendicular at 180°.

    Steady turn, over the steady loop between ``steady_from_deg`` and ``steady_to_deg`` of heading
    change (the last 360° recorded if the turn is shorter; ends at the interpolated crossings):
    steady turning diameter = least-squares circle fitted to the water track less the loop's own drift
    (its displacement between the loop's ends over the loop's duration — the wind's leeway of the
    circling ship, which ITTC 7.5-04-02-01's drift correction removes loop by loop; a circle fitted
    to the open loop is off by up to drift·T/(2π) in radius, depending on where the loop starts); steady rate of turn = heading change over the loop / its duration (the mean rate
    of change of heading, as the independent MMG reference of the tests defines it: ∫|r|dt / T);
    steady speed = mean speed through the water over the loop.
    """
    t = np.asarray(t, float)
    psi0 = heading[0]
    dpsi = np.abs(heading - psi0)
    c, s = math.cos(psi0), math.sin(psi0)
    ex, ey = x_w - x_w[0], y_w - y_w[0]
    xi = ex * c + ey * s
    eta = -ex * s + ey * c
    out: dict = {}
    out["approach_heading_rad"] = float(psi0)
    c90 = _first_crossing(t, dpsi, math.radians(90.0))
    if c90 is not None:
        out["advance_m"] = _interp(t, xi, c90[0])
        out["transfer_m"] = abs(_interp(t, eta, c90[0]))
        out["transfer_signed_m"] = _interp(t, eta, c90[0])
        out["time_to_90deg_s"] = c90[0] - t[0]
    c180 = _first_crossing(t, dpsi, math.radians(180.0))
    if c180 is not None:
        out["tactical_diameter_m"] = abs(_interp(t, eta, c180[0]))
        out["tactical_signed_m"] = _interp(t, eta, c180[0])
        out["time_to_180deg_s"] = c180[0] - t[0]
    # the water track's own drift over the second loop (360° to 720°: same heading, one loop apart):
    # the wind's leeway of the circling ship, which a trials team's drift correction also removes
    c360 = _first_crossing(t, dpsi, 2.0 * math.pi)
    c720 = _first_crossing(t, dpsi, 4.0 * math.pi)
    if c360 is not None and c720 is not None and c720[0] > c360[0]:
        dt = c720[0] - c360[0]
        out["loop_drift_mps"] = [(_interp(t, x_w, c720[0]) - _interp(t, x_w, c360[0])) / dt,
                                 (_interp(t, y_w, c720[0]) - _interp(t, y_w, c360[0])) / dt]
    total = float(dpsi[-1])
    lo, hi = math.radians(steady_from_deg), math.radians(steady_to_deg)
    if total < hi:
        lo, hi = total - 2 * math.pi, total
    if lo >= math.radians(90.0):
        m = (dpsi >= lo) & (dpsi <= hi)
        c_lo = _first_crossing(t, dpsi, lo)
        t_lo = c_lo[0] if c_lo is not None else float(t[0])
        c_hi = _first_crossing(t, dpsi, hi) if hi < total else None
        t_hi = c_hi[0] if c_hi is not None else float(t[-1])
        if np.count_nonzero(m) >= 10 and t_hi > t_lo:
            T = t_hi - t_lo
            dn = (_interp(t, x_w, t_hi) - _interp(t, x_w, t_lo)) / T
            de = (_interp(t, y_w, t_hi) - _interp(t, y_w, t_lo)) / T
            _, _, R = fit_circle(x_w[m] - dn * (t[m] - t_lo), y_w[m] - de * (t[m] - t_lo))
            out["steady_turning_diameter_m"] = 2.0 * R
            out["steady_loop_drift_mps"] = [float(dn), float(de)]
            out["steady_loop_s"] = [float(t_lo), float(t_hi)]
            out["steady_speed_mps"] = float(np.mean(np.hypot(u_r[m], v_r[m])))
            # rate of turn: the rate of change of heading (a heeled ship's body yaw rate is smaller by
            # cos φ cos θ), its mean over the loop
            dh = _interp(t, heading, t_hi) - _interp(t, heading, t_lo)
            out["steady_rate_of_turn_dps"] = float(np.degrees(abs(dh) / T))
            out["steady_drift_angle_deg"] = float(np.degrees(np.mean(np.arctan2(-v_r[m], u_r[m]))))
    return out


def _peak(t: np.ndarray, f: np.ndarray, i0: int, i1: int) -> tuple[float, float]:
    """Maximum of f over [i0, i1) refined by a parabola through the three samples around it."""
    k = i0 + int(np.argmax(f[i0:i1]))
    if 0 < k < len(f) - 1:
        y0, y1, y2 = f[k - 1], f[k], f[k + 1]
        den = y0 - 2 * y1 + y2
        if den < 0:
            d = 0.5 * (y0 - y2) / den
            h = t[k + 1] - t[k]
            return float(y1 - 0.25 * (y0 - y2) * d), float(t[k] + d * h)
    return float(f[k]), float(t[k])


def rudder_move_start(t, rudder, t_after: float, level_to: float) -> float | None:
    """Start [s] of the first rudder move after ``t_after`` toward ``level_to`` [rad] (the
    counter-rudder execute of a zig-zag): the straight line through the true angles between 10 % and
    90 % of the swing from the level held at ``t_after``, intersected with that level (the instant
    the rudder leaves it, exact for a steering gear moving at its rate limit). None if the rudder
    does not pass half the swing."""
    t = np.asarray(t, float)
    d = np.asarray(rudder, float)
    k0 = min(int(np.searchsorted(t, t_after)), len(t) - 1)
    L0 = float(d[k0])
    sw = float(level_to) - L0
    if sw == 0.0:
        return None
    frac = (d[k0:] - L0) / sw
    beyond = np.flatnonzero(frac >= 0.5)
    if beyond.size == 0:
        return None
    a = b = k0 + int(beyond[0])
    while a - 1 > k0 and (d[a - 1] - L0) / sw > 0.1:
        a -= 1
    while b + 1 < len(d) and (d[b + 1] - L0) / sw < 0.9:
        b += 1
    if b == a:
        a = max(a - 1, k0)
    if b <= a:
        return None
    slope, icpt = np.polyfit(t[a:b + 1], d[a:b + 1], 1)
    return float((L0 - icpt) / slope) if slope != 0.0 else None


def zigzag(t, heading, *, rudder_deg: float, heading_deg: float, first_side: int,
           base: float | None = None, t_counter: float | None = None) -> dict:
    """Zig-zag (δ/ψ) metrics from EXECUTE (index 0): first and second overshoot angles and times,
    initial turning time (EXECUTE to the first heading threshold), time to check yaw, and the period
    (first to third threshold crossing). Heading changes are counted from ``base`` [rad] (the initial
    course; default the heading at EXECUTE). Time to check yaw (from the second execute, the
    counter-rudder, to the first heading extreme, where the yaw is checked): from ``t_counter`` [s]
    (the instant the rudder started to move to the other side) when given, else from the first
    threshold crossing (an ideal helm that reverses the rudder at the threshold)."""
    t = np.asarray(t, float)
    s = 1.0 if first_side > 0 else -1.0
    a = math.radians(heading_deg)
    f = s * (heading - (heading[0] if base is None else base))
    out: dict = {"rudder_deg": rudder_deg, "heading_deg": heading_deg}
    c1 = _first_crossing(t, f, a)
    if c1 is None:
        return out
    out["initial_turning_time_s"] = c1[0] - t[0]
    c2 = _first_crossing(t, -f, a, c1[1])
    end1 = c2[1] if c2 is not None else len(t)
    pk1, tp1 = _peak(t, f, c1[1], end1)
    out["first_overshoot_deg"] = math.degrees(pk1 - a)
    out["time_to_check_yaw_s"] = tp1 - (c1[0] if t_counter is None else t_counter)
    out["first_overshoot_time_s"] = tp1 - t[0]
    if c2 is None:
        return out
    c3 = _first_crossing(t, f, a, c2[1])
    end2 = c3[1] if c3 is not None else len(t)
    pk2, tp2 = _peak(t, -f, c2[1], end2)
    out["second_overshoot_deg"] = math.degrees(pk2 - a)
    out["second_overshoot_time_s"] = tp2 - t[0]
    if c3 is not None:
        out["period_s"] = c3[0] - c1[0]
    return out


def _axes(x_w, y_w, heading):
    psi0 = heading[0]
    c, s = math.cos(psi0), math.sin(psi0)
    ex, ey = x_w - x_w[0], y_w - y_w[0]
    return ex * c + ey * s, -ex * s + ey * c


def stopping(t, x_w, y_w, heading, u_r) -> dict:
    """Stopping metrics from EXECUTE (index 0) on the water track (IMO MSC.137(76) / MSC/Circ.1053).

    Dead in the water: the first instant the surge speed through the water reaches zero.
    track_reach_m: distance sailed along the water track until then; head_reach_m: along the
    approach heading; lateral_deviation_m: across it (+ to starboard).
    """
    t = np.asarray(t, float)
    along, cross = _axes(x_w, y_w, heading)
    path = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x_w), np.diff(y_w)))])
    out: dict = {"approach_speed_mps": float(u_r[0])}
    c = _first_crossing(t, -np.asarray(u_r), 0.0)
    if c is None:
        out["not_stopped"] = True
        return out
    td = c[0]
    out["time_to_dead_in_water_s"] = td - t[0]
    out["track_reach_m"] = _interp(t, path, td)
    out["head_reach_m"] = _interp(t, along, td)
    out["lateral_deviation_m"] = _interp(t, cross, td)
    out["heading_change_deg"] = math.degrees(_interp(t, heading, td) - heading[0])
    return out


STERNWAY_MPS = 0.1  # a speed through the water counts as astern only with u below −0.1 m/s


def signed_speed(u, v) -> np.ndarray:
    """Speed through the water, negative with sternway: |V| = √(u² + v²), signed by the surge u only
    where the ship clearly goes astern (u < −STERNWAY_MPS). A ship lying stopped drifts sideways in
    the wind at up to ~1 m/s with a surge of a few cm/s either way; sign(u)·|V| then flipped the
    initial speed of an acceleration from rest between ±|V| on a surge no trials team can resolve
    against its current's uncertainty (a few cm/s). The reduction uses the same rule
    (:mod:`vtrials.reduce.reach`)."""
    u = np.asarray(u, float)
    return np.where(u < -STERNWAY_MPS, -1.0, 1.0) * np.hypot(u, v)


def speed_change(t, x_w, y_w, heading, u_r, v_r, *, settle_fraction: float = 0.02) -> dict:
    """Acceleration / deceleration metrics from EXECUTE (index 0), on the signed speed through the
    water (:func:`signed_speed`).

    Terminal speed: mean speed through the water over the last 10 % of the run (at least the last
    5 s). time_to_terminal_speed_s: from EXECUTE until the speed enters, for good, the band
    ±settle_fraction × |terminal − initial| around the terminal speed; reach_m: distance along the
    approach heading by then (track_distance_m along the water track).
    """
    t = np.asarray(t, float)
    U = signed_speed(u_r, v_r)
    along, _ = _axes(x_w, y_w, heading)
    path = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x_w), np.diff(y_w)))])
    n_last_5s = len(t) - int(np.searchsorted(t, t[-1] - 5.0))
    n_tail = max(int(0.1 * len(t)), n_last_5s, 2)
    UT = float(np.mean(U[-n_tail:]))
    U0 = float(U[0])
    out = {"initial_speed_mps": U0, "terminal_speed_mps": UT}
    band = settle_fraction * abs(UT - U0)
    outside = np.flatnonzero(np.abs(U - UT) > band)
    k = int(outside[-1]) + 1 if outside.size else 0
    if k >= len(t):
        out["not_settled"] = True
        return out
    if k > 0:
        # interpolate the entry into the band between samples k-1 and k
        f0, f1 = abs(U[k - 1] - UT) - band, abs(U[k] - UT) - band
        a = f0 / (f0 - f1) if f0 != f1 else 1.0
        te = t[k - 1] + a * (t[k] - t[k - 1])
    else:
        te = t[0]
    out["time_to_terminal_speed_s"] = te - t[0]
    out["reach_m"] = _interp(t, along, te)
    out["track_distance_m"] = _interp(t, path, te)
    c90 = _first_crossing(t, np.sign(UT - U0) * (U - U0), 0.9 * abs(UT - U0))
    if c90 is not None:
        out["time_to_90_percent_s"] = c90[0] - t[0]
    return out
