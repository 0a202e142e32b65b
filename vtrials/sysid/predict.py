"""Standard maneuvers predicted with the team's identified model: turning circles and zig-zags.

The team's model (3-DOF MMG, :mod:`vtrials.sysid.mmg`, Y&Y 2015 eq. 4; or 4-DOF with roll,
:mod:`vtrials.sysid.blanke`) with the identified hull terms, a
steering gear that moves the rudder at its rated speed towards the ordered angle, and the shaft held
at its approach speed (MMG practice, Y&Y 2015 §4). Classical fixed-step RK4 at ``dt``.

Metrics by the IMO MSC.137(76) / ITTC 7.5-04-02-01 definitions, counted from EXECUTE: advance (along
the approach heading at 90° change), transfer (across it at 90°), tactical diameter (across it at
180°); zig-zag first and second overshoot angles (the heading's excess over the check angle after the
first and second rudder shifts).
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.errors import InputError

_WHERE = "vtrials.sysid.predict"


def simulate(ship, coeffs: dict, speed: float, n: float, helm, t_end: float, dt: float = 0.05,
             rudder_rate: float | None = None, pitch: float = math.nan, stop=None) -> dict:
    """Integrate from a steady straight approach at ``speed`` (m/s, heading 0), shaft rate ``n``
    (1/s) and, for CP propellers, ``pitch`` (P/D). ``helm(t, state, delta) -> ordered rudder angle``
    (rad), called every step; the rudder moves towards it at ``rudder_rate`` (rad/s; default the
    ship's). The ship's ``rates`` give the dynamics (:class:`vtrials.sysid.mmg.Ship`: 3-DOF,
    :class:`vtrials.sysid.blanke.Ship4`: 4-DOF). Returns arrays t, the ship's state names (x, y, psi,
    u, v, r …) and delta, up to ``t_end`` or the first step at which ``stop(t, state)`` holds."""
    if not (speed > 0 and n > 0 and t_end > 0 and dt > 0):
        raise InputError(_WHERE, "simulate", f"speed {speed}, n {n}, t_end {t_end}, dt {dt}; allowed: all > 0")
    rate = ship.rudder_rate if rudder_rate is None else rudder_rate
    if not rate > 0:
        raise InputError(_WHERE, "rudder_rate", f"{rate}; allowed: > 0 rad/s (the steering gear's rated speed)")
    steps = int(math.ceil(t_end / dt))
    y = ship.initial_state(speed)
    d = 0.0
    out = np.empty((steps + 1, y.size + 2))
    out[0] = 0.0, *y, d
    for k in range(steps):
        t = k * dt
        order = helm(t, y, d)
        d = d + float(np.clip(order - d, -rate * dt, rate * dt))
        k1 = ship.rates(coeffs, y, d, n, pitch)
        k2 = ship.rates(coeffs, y + 0.5 * dt * k1, d, n, pitch)
        k3 = ship.rates(coeffs, y + 0.5 * dt * k2, d, n, pitch)
        k4 = ship.rates(coeffs, y + dt * k3, d, n, pitch)
        y = y + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        if not np.all(np.isfinite(y)):
            raise RuntimeError(f"{_WHERE}: the identified model diverged at t = {t + dt:.2f} s, state {y.tolist()}")
        out[k + 1] = t + dt, *y, d
        if stop is not None and stop(t + dt, y):
            out = out[:k + 2]
            break
    return dict(zip(("t", *ship.state_names, "delta"), out.T))


def _at(t, f, level):
    """First time |f| reaches level (linear interpolation), or None."""
    k = np.flatnonzero(np.abs(f) >= level)
    if k.size == 0 or k[0] == 0:
        return None
    i = int(k[0])
    a = (level - abs(f[i - 1])) / (abs(f[i]) - abs(f[i - 1]))
    return float(t[i - 1] + a * (t[i] - t[i - 1]))


def turning_circle(ship, coeffs, speed, n, rudder_deg: float, t_end: float | None = None, dt: float = 0.05,
                   pitch: float = math.nan) -> dict:
    """Advance, transfer and tactical diameter (m) of a turn with the rudder put over at t = 0."""
    t_end = t_end or 40.0 * ship.L / speed
    delta = math.radians(rudder_deg)
    s = simulate(ship, coeffs, speed, n, lambda t, y, d: delta, t_end, dt, pitch=pitch,
                 stop=lambda t, y: abs(y[2]) > math.radians(181.0))
    out = {}
    for key, level, coord in (("advance_m", 90, "x"), ("transfer_m", 90, "y"), ("tactical_diameter_m", 180, "y")):
        tq = _at(s["t"], s["psi"], math.radians(level))
        if tq is None:
            raise RuntimeError(f"{_WHERE}: the predicted turn did not reach {level}° in {t_end:.0f} s")
        out[key] = abs(float(np.interp(tq, s["t"], s[coord])))
    return out


def zigzag(ship, coeffs, speed, n, rudder_deg: float, check_deg: float, first_side: int,
           t_end: float | None = None, dt: float = 0.05, pitch: float = math.nan) -> dict:
    """First and second overshoot angles (deg) of a δ/ψ zig-zag, first rudder to ``first_side`` (+1
    starboard, −1 port)."""
    t_end = t_end or 30.0 * ship.L / speed
    a, c = math.radians(rudder_deg), math.radians(check_deg)
    side = [1.0 if first_side > 0 else -1.0]
    shifts = []

    def helm(t, y, d):
        if side[0] * y[2] >= c:
            side[0] = -side[0]
            shifts.append(t)
        return side[0] * a

    s = simulate(ship, coeffs, speed, n, helm, t_end, dt, pitch=pitch, stop=lambda t, y: len(shifts) >= 3)
    if len(shifts) < 3:
        raise RuntimeError(f"{_WHERE}: the predicted zig-zag made {len(shifts)} rudder shifts in {t_end:.0f} s; "
                           "3 are needed for two overshoots")
    psi, t = s["psi"] * (1.0 if first_side > 0 else -1.0), s["t"]
    k1 = (t >= shifts[0]) & (t <= shifts[1])
    k2 = (t >= shifts[1]) & (t <= shifts[2])
    return {"first_overshoot_deg": math.degrees(float(psi[k1].max()) - c),
            "second_overshoot_deg": math.degrees(-float(psi[k2].min()) - c)}


def held_back(ship, coeffs, ordered: dict, speed: float, n: float, pitch: float = math.nan) -> dict:
    """Predict a maneuver from the director's sheet (``ordered``: kind, rudder_deg, heading_deg,
    first_side) at the given approach."""
    kind = ordered.get("kind")
    if kind == "turning_circle":
        return turning_circle(ship, coeffs, speed, n, float(ordered["rudder_deg"]), pitch=pitch)
    if kind == "zigzag":
        side = 1 if ordered.get("first_side", "starboard") == "starboard" else -1
        return zigzag(ship, coeffs, speed, n, float(ordered["rudder_deg"]), float(ordered["heading_deg"]), side,
                      pitch=pitch)
    raise InputError(_WHERE, "maneuver.kind", f"{kind!r}; allowed: turning_circle, zigzag")
