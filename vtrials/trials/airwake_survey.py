"""The crew's airwake survey (seed 003 §2): hold a relative wind over deck while the mobile anemometer
mast is moved among deck positions, one recording per position.

For each condition the officer of the watch works out course and speed from the wind: the true wind
vector W (earth axes) is the relative wind shown by the reference anemometer, turned through the gyro
heading, plus the ship's velocity over ground from the tracking fixes (as
:meth:`vtrials.trials.crew.Crew.true_wind_from`). For an ordered relative wind of speed S from γ off the
bow, the ship's velocity U e(ψ) must satisfy U e(ψ) = W + S e(ψ + γ) (e(a) = (cos a, sin a); drift
neglected), i.e. sin(β − ψ) = −S sin γ / |W| with β the direction W blows towards, and
U = |W| cos(β − ψ) + S cos γ. Of the two roots he takes the slower speed that is within the ship's speeds
(at least :data:`MIN_SPEED_MPS` for steerage); the shaft setting for U comes from the ship's speed table
(the telegraph orders' calm-water speeds, as the standardization trial gives them: linear between
orders in r/min and pitch). He settles, reads the reference anemometer again and corrects — up to
:data:`MAX_CORRECTIONS` times — until the relative wind is within the condition's tolerance. With a
given shaft setting instead of a speed, only the course is worked out (scanning ψ for the ordered angle).

Everything he decides from comes from instruments (anemometer, gyro, tracking fixes, log).
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.errors import InputError
from vtrials.units import KNOT, RPM

MIN_SPEED_MPS = 2.5  # assumption: the least speed at which the helm holds a course in a seaway
MAX_CORRECTIONS = 3
LOOK_S = 30.0  # the display's averaging window for the relative wind


def masts(crew) -> list[str]:
    names = [n for n in crew.iset.of_kind("sonic_anemometer") if crew.iset.devices[n].mobile]
    if not names:
        raise InputError("scenario", "agenda.trial (kind airwake_survey)", "an airwake survey needs a mobile anemometer mast: an "
                         "[[instrument]] of kind sonic_anemometer with set.mobile = true")
    return names


def reference(crew) -> str | None:
    fixed = [n for n in crew.iset.of_kind("sonic_anemometer") if not crew.iset.devices[n].mobile]
    if fixed:
        return fixed[0]
    cups = crew.iset.of_kind("anemometer")
    return cups[0] if cups else None


def relative_wind(crew, t0: float) -> tuple[float, float] | None:
    """(γ from off the bow [rad], speed [m/s]) of the reference anemometer's mean since t0."""
    name = reference(crew)
    if name is None:
        return None
    t, c = crew.iset.window(name, t0)
    if t.size < 3:
        return None
    if crew.iset.devices[name].kind == "sonic_anemometer":
        u, v = float(np.mean(c["u"])), float(np.mean(c["v"]))
    else:
        u = -float(np.mean(c["speed"] * np.cos(c["angle"])))
        v = -float(np.mean(c["speed"] * np.sin(c["angle"])))
    return math.atan2(-v, -u), math.hypot(u, v)


def true_wind(crew) -> np.ndarray | None:
    """True wind vector (north, east) [m/s] the wind blows towards: relative wind turned by the gyro
    heading plus the ship's velocity over ground from the fixes (last minute)."""
    from vtrials.trials.maneuvering import _rate
    t0 = crew.t - 60.0
    rw = relative_wind(crew, t0)
    if rw is None or crew._gyro is None or crew._track is None:
        return None
    _, g = crew.iset.window(crew._gyro, t0)
    tt, fx = crew.iset.window(crew._track, t0)
    ok = np.isfinite(fx["north"]) & np.isfinite(fx["east"])
    if g["heading"].size < 3 or np.count_nonzero(ok) < 3:
        return None
    psi = math.atan2(np.mean(np.sin(g["heading"])), np.mean(np.cos(g["heading"])))
    gamma, s = rw
    rel = -s * np.array([math.cos(psi + gamma), math.sin(psi + gamma)])
    return rel + np.array([_rate(tt[ok], fx["north"][ok]), _rate(tt[ok], fx["east"][ok])])


def speed_table(crew) -> list[tuple[float, float, float | None]]:
    """(speed [m/s], r/s, pitch) of the ahead telegraph orders in calm water, slowest first (cached)."""
    if getattr(crew, "_speed_table", None) is None:
        from vtrials.physics.simulator import Simulator
        from vtrials.trials.agenda import ORDERS
        v = crew.vessel
        sim = Simulator(v, 1, crew.sim.dt, record_every=0)
        rows = []
        for o in ORDERS:
            if o in v.telegraph:
                rps, pitch = v.telegraph[o]
                s = sim.steady_at_order(0, (rps,) * sim.ns, (pitch,) * sim.ns if pitch is not None else ())
                rows.append((float(s.u), float(rps), None if pitch is None else float(pitch)))
        crew._speed_table = sorted(rows)
    return crew._speed_table


def setting_for(crew, speed: float) -> tuple[float, float | None]:
    """(r/s, pitch) for a speed: linear between the table's orders (clipped at its ends; below the
    slowest order the r/min scale with speed at the slowest order's pitch)."""
    tab = speed_table(crew)
    us = [r[0] for r in tab]
    if speed <= us[0]:
        u, rps, pitch = tab[0]
        return rps * max(speed / u, 0.3), pitch
    if speed >= us[-1]:
        return tab[-1][1], tab[-1][2]
    k = int(np.searchsorted(us, speed)) - 1
    f = (speed - us[k]) / (us[k + 1] - us[k])
    rps = tab[k][1] + f * (tab[k + 1][1] - tab[k][1])
    pitch = None if tab[k][2] is None else tab[k][2] + f * (tab[k + 1][2] - tab[k][2])
    return rps, pitch


def solve_course_speed(wind: np.ndarray, gamma: float, s: float, u_min: float, u_max: float
                       ) -> tuple[float, float, bool]:
    """(course ψ, speed U, attainable) for a relative wind of speed s from γ off the bow in the true wind
    ``wind`` (north, east, towards) — see the module text. Not attainable: the root closest to the
    speed range, clipped."""
    w = float(np.hypot(*wind))
    beta = math.atan2(wind[1], wind[0])
    x = -s * math.sin(gamma) / w if w > 0 else math.copysign(math.inf, -math.sin(gamma) or 1.0)
    best = None
    a0 = math.asin(max(-1.0, min(1.0, x)))
    for a in (a0, math.pi - a0):
        psi = beta - a
        u = w * math.cos(a) + s * math.cos(gamma)
        miss = max(u_min - u, u - u_max, 0.0) + (abs(x) - 1.0 if abs(x) > 1 else 0.0) * 10.0
        key = (miss, u)
        if best is None or key < best[0]:
            best = (key, psi, min(max(u, u_min), u_max), miss == 0.0)
    _, psi, u, ok = best
    return math.atan2(math.sin(psi), math.cos(psi)), u, ok


def course_for_angle(wind: np.ndarray, gamma: float, u: float, psi_now: float) -> float:
    """Course at which a ship at speed u feels the relative wind from γ (scan of ψ, nearest root to
    the present heading among those within 0.5° of the best)."""
    psi = np.linspace(-math.pi, math.pi, 7201)
    rel_n = wind[0] - u * np.cos(psi)
    rel_e = wind[1] - u * np.sin(psi)
    x = rel_n * np.cos(psi) + rel_e * np.sin(psi)
    y = -rel_n * np.sin(psi) + rel_e * np.cos(psi)
    g = np.arctan2(-y, -x)
    err = np.abs(np.angle(np.exp(1j * (g - gamma))))
    near = err <= err.min() + math.radians(0.5)
    d = np.abs(np.angle(np.exp(1j * (psi - psi_now))))
    return float(psi[near][np.argmin(d[near])])


def _wrap(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


def come_to_condition(crew, run, att) -> None:
    """Course (and speed) for the condition, settled and corrected from the reference anemometer."""
    p = run.params
    gamma, s = p["relative_wind"], p["relative_wind_speed"]
    tab = speed_table(crew)
    u_max = tab[-1][0]
    course = crew._course
    for it in range(MAX_CORRECTIONS + 1):
        wind = true_wind(crew)
        if wind is None:  # nothing on the displays yet: steam a minute and look again
            crew.advance(60.0)
            wind = true_wind(crew)
        if wind is None:
            att.approach_notes.append("no wind reading: course not set from the wind")
            break
        if p["hold_speed"]:
            course, u, ok = solve_course_speed(wind, gamma, s, MIN_SPEED_MPS, u_max)
            if not ok:
                att.approach_notes.append(f"relative wind {math.degrees(gamma):.0f}° at {s / KNOT:.1f} kn not "
                                          f"attainable in a {np.hypot(*wind) / KNOT:.1f} kn true wind: closest "
                                          f"speed {u / KNOT:.1f} kn")
            rps, pitch = setting_for(crew, u)
            for k in range(crew.sim.ns):
                crew._order_shaft(k, rps, pitch if (pitch is not None and crew._cp[k]) else crew.pitch_order[k],
                                  "governed")
            crew._t_change = crew.t
        else:
            course = course_for_angle(wind, gamma, crew.log_speed(), course)
        crew.come_to(course, run.helm_limit)
        crew.settle(run, att)
        rw = relative_wind(crew, crew.t - LOOK_S)
        if rw is None:
            break
        off_dir = abs(_wrap(rw[0] - gamma))
        off_spd = abs(rw[1] - s) if s is not None else 0.0
        if off_dir <= p["wind_tolerance"] and off_spd <= p["wind_speed_tolerance"]:
            break
        if it == MAX_CORRECTIONS:
            att.approach_notes.append(f"relative wind {math.degrees(rw[0]):.1f}° {rw[1] / KNOT:.1f} kn after "
                                      f"{MAX_CORRECTIONS} corrections")
    att.course_deg = math.degrees(course) % 360.0


def execute(crew, run, attempt: int):
    """One recording at one mast position (the first of a condition brings the ship to it)."""
    from vtrials.trials.crew import EV_COMEX, EV_EXECUTE, EV_FINEX, Attempt, window_truth
    p = run.params
    names = masts(crew)
    att = Attempt(run, attempt, crew._course * 180.0 / math.pi % 360.0, [], [], list(run.modes), crew.t)
    if run.leg == 1 or attempt > 1:
        if attempt == 1 and run.leg == 1 and not p["hold_speed"]:
            crew.set_shafts(run)
        come_to_condition(crew, run, att)
    else:
        att.approach_steady = True
        att.approach_notes.append("condition held from the previous position")
        att.course_deg = crew._course * 180.0 / math.pi % 360.0
    att.rpm_ordered = [x / RPM for x in crew.rps_order]
    att.pitch_ordered = [x if crew._cp[k] else None for k, x in enumerate(crew.pitch_order)]
    crew.hold(crew._course, run.helm_limit)
    for n in names:  # the mast goes to its socket (data while it is moved are not used)
        crew.iset.devices[n].move_to(crew.t, p["position"])
    crew.advance(p["move_s"])
    att.t_comex = crew.t
    crew.events.append((crew.t, run.number, EV_COMEX))
    att.t_execute = crew.t
    crew.events.append((crew.t, run.number, EV_EXECUTE))
    crew.advance(run.duration)
    att.t_finex = crew.t
    crew.events.append((crew.t, run.number, EV_FINEX))
    rw = relative_wind(crew, att.t_execute)
    ok = rw is not None and abs(_wrap(rw[0] - p["relative_wind"])) <= p["wind_tolerance"] and \
        (p["relative_wind_speed"] is None or abs(rw[1] - p["relative_wind_speed"]) <= p["wind_speed_tolerance"])
    att.run_steady = bool(ok)
    if rw is not None:
        att.run_notes.append(f"relative wind {math.degrees(rw[0]):.1f}° {rw[1] / KNOT:.1f} kn (reference anemometer)")
    ref = window_truth(crew.recent_truth(), att.t_execute, att.t_finex)
    ref.update({"run": run.number, "attempt": attempt, "position": p["position"]})
    crew.truth_refs.append(ref)
    crew._runs_done += 1
    crew.attempts.append(att)
    return att
