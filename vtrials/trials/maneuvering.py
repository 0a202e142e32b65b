"""How the crew executes maneuvering runs (seed 002 "Tactical", "Acceleration / deceleration",
"Maneuvering"; IMO MSC.137(76)): the approach as for every run (setting, course, steady, COMEX, one
minute), then at EXECUTE the maneuver, watched on the instruments until FINEX:

* ``turn`` — rudder put over smartly and held (the reached angle is not corrected); FINEX when the gyro
  shows the scheduled heading change (540° by default);
* ``speed_change`` — the new engine order (as fast as the machinery allows); the helm holds the course,
  or holds the rudder hard over, or cycles it at set intervals; FINEX when the tracked speed over
  ground is steady (terminal speed, ahead or astern);
* ``zigzag`` — δ/ψ zig-zag by heading thresholds on the approach heading; FINEX at the shift after
  the last overshoot;
* ``direct_spiral`` — the Dieudonné sequence; at each setting the helmsman puts the rudder over (his
  miss is held, not corrected), the crew waits until the gyro's rate of turn is steady, keeps
  ``hold_s`` of data, then goes to the next; a setting that never settles within ``max_setting_s``
  is logged as such and the sequence goes on;
* ``reverse_spiral`` — the helm holds each rate of turn (Bech); same steadiness rule;
* ``pull_out`` — a steady turn, then rudder amidships; FINEX ``hold_s`` later;
* ``backing`` — the approach is made astern at the run's order, the rudder put hard over at EXECUTE;
  FINEX ``hold_s`` later;
* ``steady`` — nothing changes at EXECUTE: the course-keeping helm holds the approach course at the
  approach setting, FINEX ``hold_s`` later (a ship-motion record on a steady heading and speed, seed
  003's 60-118 s records for Compat).

Every decision is taken on instrument readings (gyro, tracking fixes, log); the truth only flows into
the truth references (:func:`maneuver_truth`).
"""

from __future__ import annotations

import math
import re

import numpy as np

from vtrials.physics import steering as H
from vtrials.truth import metrics as TM
from vtrials.trials.agenda import Run
from vtrials.physics.dynamics import NV_PSI_U
from vtrials.units import DEG, KNOT

EV_SETTING = 4  # event code: a new spiral setting (or the pull-out release) — the DAS "mark" button
LOOK_S = 2.0  # how often the crew looks at the gyro during a maneuver


def _gyro(crew, t0: float) -> tuple[np.ndarray, np.ndarray]:
    t, c = crew.iset.window(crew._gyro, t0)
    return t, np.unwrap(c["heading"])


def _rate(t: np.ndarray, psi: np.ndarray) -> float:
    """Least-squares rate of turn [rad/s] of a heading series."""
    if t.size < 3:
        return math.nan
    tc = t - t.mean()
    return float(tc @ (psi - psi.mean()) / (tc @ tc))


def _track_speed(crew, t0: float, t1: float) -> float:
    """Speed over ground [m/s] from a straight-line fit of the tracking fixes in [t0, t1]."""
    t, c = crew.iset.window(crew._track, t0)
    m = (t <= t1) & np.isfinite(c["north"]) & np.isfinite(c["east"])
    if np.count_nonzero(m) < 3:
        return math.nan
    return math.hypot(_rate(t[m], c["north"][m]), _rate(t[m], c["east"][m]))


def _two_windows(t: np.ndarray, x: np.ndarray, window_s: float, stat) -> tuple[float, float] | None:
    if t.size < 10 or t[-1] - t[0] < 1.9 * window_s:
        return None
    mid = t[-1] - window_s
    return stat(t[t < mid], x[t < mid]), stat(t[t >= mid], x[t >= mid])


def spiral_steady(crew, reverse: bool, tol_rate: float = 0.002 * DEG, tol_rudder: float = 0.05 * DEG,
                  tol_rel: float = 0.02) -> bool:
    """Is a spiral setting steady, judged as the director would over two consecutive windows of the
    agenda's steadiness length (at least 2 min)? Direct spiral: the gyro's rate of turn agrees within
    max(``tol_rate``, ``tol_rel``·|r|). Reverse spiral — the helm holds the rate, so the rudder is
    what settles: the mean rudder angle agrees within max(``tol_rudder``, ``tol_rel``·|δ|). Both: the
    log speed no longer changing (the agenda's speed tolerance)."""
    W = max(120.0, crew.st.window_s)
    if not reverse:
        t, psi = _gyro(crew, crew.t - 2 * W)
        rr = _two_windows(t, psi, W, _rate)
        if rr is None or abs(rr[1] - rr[0]) > max(tol_rate, tol_rel * abs(rr[1])):
            return False
    else:
        rud = crew.iset.of_kind("rudder")
        if rud:
            t, c = crew.iset.window(rud[0], crew.t - 2 * W)
            dd = _two_windows(t, c["angle"], W, lambda a, b: float(np.mean(b)))
            if dd is None or abs(dd[1] - dd[0]) > max(tol_rudder, tol_rel * abs(dd[1])):
                return False
    log = crew.display(crew.t - 2 * W)["log"]
    if log is not None and log[0].size:
        vv = _two_windows(log[0], log[1], W, lambda a, b: float(np.mean(b)))
        if vv is None or abs(vv[1] - vv[0]) > crew.st.speed_kn * KNOT:
            return False
    return True


def execute(crew, run: Run, att) -> None:
    """EXECUTE → FINEX of one maneuvering run (the approach is done); fills att.t_finex and notes."""
    p = run.params
    kind = p["type"]
    t_exec = crew.t
    psi0 = float(crew.sim.nav[crew.ship, NV_PSI_U])
    gains = crew.gains
    dmax = crew.vessel.max_rudder
    limit = p.get("max_duration_s") or {"turn": 3600.0, "speed_change": 1800.0, "zigzag": 1800.0,
                                        "pull_out": 3600.0, "backing": 1800.0}.get(kind, 36000.0)
    done = False
    if kind == "turn":
        crew._helm([(H.HOLD, p["rudder"], 0.0)])
        while crew.t - t_exec < limit:
            crew.advance(LOOK_S)
            t, psi = _gyro(crew, t_exec - 1.0)
            if t.size and abs(psi[-1] - psi[0]) >= p["heading_change"]:
                done = True
                break
    elif kind == "zigzag":
        side = 1.0 if p["rudder"] > 0 else -1.0
        # the helmsman counts the heading change from the ordered course, not from where the heading
        # happened to be at EXECUTE
        course = math.radians(att.course_deg)
        base = psi0 + math.atan2(math.sin(course - psi0), math.cos(course - psi0))
        att.base_offset = base - psi0
        crew._helm([(H.ZIGZAG, abs(p["rudder"]), p["check"], base, side, float(p["executes"])),
                    (H.HOLD, 0.0, 0.0)])
        while crew.t - t_exec < limit:
            crew.advance(LOOK_S)
            if crew.sim.helm_phase(crew.ship) >= 1:
                done = True
                break
    elif kind == "speed_change":
        crew._order_all(p["to_rps"], p["to_pitch"], p.get("to_order"))
        mode = p["rudder_mode"]
        if mode == "hold_course":
            lim = min(crew.vessel.autopilot.rudder_limit_deg * DEG, dmax)
            crew._helm([(H.HEADING, psi0, lim, *gains, 0.0)])
        elif mode == "hard_over":
            crew._helm([(H.HOLD, p["rudder"], 0.0)])
        else:
            ph = [(H.HOLD, p["rudder"] * (1 if k % 2 == 0 else -1), p["cycle_s"]) for k in range(H.MAX_PHASES - 1)]
            crew._helm(ph + [(H.HOLD, 0.0, 0.0)])
        # FINEX: the tracked speed steady — two consecutive minutes agree within 0.05 kn, at least 3 min
        while crew.t - t_exec < limit:
            crew.advance(30.0)
            if crew.t - t_exec < 180.0:
                continue
            v1 = _track_speed(crew, crew.t - 120.0, crew.t - 60.0)
            v2 = _track_speed(crew, crew.t - 60.0, crew.t)
            if abs(v2 - v1) < 0.05 * KNOT:
                done = True
                break
    elif kind in ("direct_spiral", "reverse_spiral"):
        settings = p["sequence"] if kind == "direct_spiral" else p["rates"]
        att.settings = []
        rng = np.random.default_rng(np.random.SeedSequence(crew.iset.seed, spawn_key=(7, run.number, att.attempt)))
        t_all = crew.t
        for k, val in enumerate(settings):
            t_set = crew.t
            crew.events.append((t_set, run.number, EV_SETTING))
            if kind == "direct_spiral":
                miss = p["helm_miss"] * float(rng.standard_normal()) if p["helm_miss"] > 0 else 0.0
                order = float(np.clip(val + miss, -dmax, dmax))
                crew._helm([(H.HOLD, order, 0.0)])
            else:
                order = val
                crew._helm([(H.RATE, val, dmax, *gains, 0.0)])
            steady, t_steady = False, math.nan
            while crew.t - t_set < p["max_setting_s"]:
                crew.advance(30.0)
                if crew.t - t_set < 120.0:
                    continue
                if spiral_steady(crew, reverse=(kind == "reverse_spiral")):
                    steady, t_steady = True, crew.t
                    crew.advance(p["hold_s"])
                    break
            att.settings.append({"index": k, "value": val, "ordered": order, "t_set": t_set, "t_steady": t_steady,
                                 "t_end": crew.t, "steady": steady})
            if not steady:
                att.run_notes.append(f"setting {k + 1} ({math.degrees(val):+.2f}{'°' if kind == 'direct_spiral' else '°/s'}) "
                                     f"not steady within {p['max_setting_s']:.0f} s")
            if crew.t - t_all > limit:
                att.run_notes.append("spiral stopped: time limit")
                break
        done = all(s["steady"] for s in att.settings) and len(att.settings) == len(settings)
    elif kind == "pull_out":
        crew._helm([(H.HOLD, p["rudder"], 0.0)])
        released = False
        while crew.t - t_exec < limit:
            crew.advance(LOOK_S)
            t, psi = _gyro(crew, t_exec - 1.0)
            if t.size and abs(psi[-1] - psi[0]) >= p["heading_change"]:
                released = True
                break
        if released:
            crew.events.append((crew.t, run.number, EV_SETTING))
            att.t_release = crew.t
            crew._helm([(H.HOLD, 0.0, 0.0)])
            crew.advance(p["hold_s"])
            done = True
    elif kind == "backing":
        crew._helm([(H.HOLD, p["rudder"], 0.0)])
        crew.advance(p["hold_s"])
        done = True
    elif kind == "steady":
        crew.advance(p["hold_s"])
        done = True
    if not done and kind not in ("direct_spiral", "reverse_spiral"):
        att.run_notes.append(f"FINEX condition not reached within {limit:.0f} s of EXECUTE: run stopped")
    att.completed = done


_ANGLES = ("heading", "wind_direction", "wind_apparent_angle")


def from_execute(cols: dict, t_execute: float, t_end: float) -> dict:
    """The truth columns over [EXECUTE, t_end], starting with a sample AT the EXECUTE instant. The
    truth is stored every ``truth_every`` steps (0.5 s on the patrol vessel's days) and EXECUTE falls
    between samples: counted from the first sample after it, every time since EXECUTE came out short
    by up to a sample interval — on the patrol vessel's time to 90 % of a speed change, an error of
    0–0.45 s beside a measurement good to 0.2 s. The state at EXECUTE is carried on linearly from the
    last two samples before it (the approach; angles along the shorter arc): interpolating toward the
    sample after would mix in the maneuver's first response (a speed already rising)."""
    t = cols["t"]
    w = (t >= t_execute - 1e-9) & (t <= t_end + 1e-9)
    c = {k: v[w] for k, v in cols.items()}
    idx = np.flatnonzero(w)
    if idx.size == 0 or idx[0] == 0 or t[idx[0]] - t_execute <= 1e-9:
        return c
    k = int(idx[0])
    i0, i1 = (k - 2, k - 1) if k >= 2 else (k - 1, k)
    a = (t_execute - t[i0]) / (t[i1] - t[i0])
    for key, v in cols.items():
        x0, x1 = float(v[i0]), float(v[i1])
        d = math.remainder(x1 - x0, 2 * math.pi) if key in _ANGLES else x1 - x0
        c[key] = np.concatenate([[x0 + a * d], c[key]])
    c["t"][0] = t_execute
    return c


def maneuver_truth(run: Run, att, cols: dict) -> dict:
    """Truth references of a maneuvering run from the true state (EXECUTE to FINEX, track through the
    water), by the definitions of :mod:`vtrials.truth.metrics`; spirals: the true mean rate of turn and
    rudder over each setting's data window."""
    p = run.params
    t = cols["t"]
    w = (t >= att.t_execute - 1e-9) & (t <= att.t_finex + 1e-9)
    kind = p["type"]
    # maneuvers timed from EXECUTE start at its instant; the spirals' and steady runs' windows are
    # means over the data, which an interpolated sample would only weigh differently
    c = from_execute(cols, att.t_execute, att.t_finex) if kind in ("turn", "pull_out", "zigzag", "speed_change") \
        else {k: v[w] for k, v in cols.items()}
    out: dict = {"type": kind}
    if c["t"].size < 3:
        return out
    if kind == "turn" or kind == "pull_out":
        out.update(TM.turning(c["t"], c["x_w"], c["y_w"], c["heading"], c["u_r"], c["v_r"], c["r"]))
        out["heel_max_deg"] = float(np.degrees(np.max(np.abs(c["roll"]))))
        out["approach_speed_mps"] = float(math.hypot(c["u_r"][0], c["v_r"][0]))
        out["drift"] = [float(np.mean(c["current_n"])), float(np.mean(c["current_e"]))]
        out["rudder_deg"] = float(np.degrees(np.mean(c["rudder_0"][c["t"] > att.t_execute + 30.0])))
        if kind == "pull_out":
            tr = getattr(att, "t_release", math.nan)
            m = c["t"] >= c["t"][-1] - 60.0
            out["residual_rate_dps"] = float(np.degrees(np.mean(c["r"][m])))
            out["t_release"] = tr
    elif kind == "zigzag":
        # the base course: the true mean heading over the approach (COMEX to EXECUTE), the course the
        # ship was steady on when the rudder was put over (seed 002: EXECUTE after 1 min of steady
        # approach data, then "when the ship's heading has changed 10 deg from the base course");
        # the ordered course is the autopilot's set point, which the approach's mean heading misses
        # by the autopilot's slow wander (0.04° SD on the patrol vessel's 60-s approaches), not a
        # property of the ship. Time to check yaw: from the counter-rudder execute, the instant the
        # true rudder started to move to the other side (the helm reacts a step or more after the
        # threshold), the reduction's definition
        psi = np.unwrap(cols["heading"])
        ma = (t >= getattr(att, "t_comex", att.t_execute - 60.0) - 1e-9) & (t <= att.t_execute + 1e-9)
        # the approach's mean heading on the branch of the heading at EXECUTE, c["heading"][0]
        base = (float(np.mean(psi[ma])) - float(np.interp(att.t_execute, t, psi)) + float(c["heading"][0])
                if np.any(ma) else None)
        side = 1 if p["rudder"] > 0 else -1
        rudders = [k for k in c if re.fullmatch(r"rudder_\d+", k)]
        rud = np.mean([c[k] for k in rudders], axis=0) if rudders else None
        first = TM.zigzag(c["t"], c["heading"], rudder_deg=abs(math.degrees(p["rudder"])),
                          heading_deg=math.degrees(p["check"]), first_side=side, base=base)
        # the counter-rudder execute: the true rudder's move to the other side after the threshold
        t_counter = None
        if "initial_turning_time_s" in first and rud is not None:
            t_counter = TM.rudder_move_start(c["t"], rud, c["t"][0] + first["initial_turning_time_s"],
                                             -side * abs(p["rudder"]))
        out.update(TM.zigzag(c["t"], c["heading"], rudder_deg=abs(math.degrees(p["rudder"])),
                             heading_deg=math.degrees(p["check"]), first_side=side, base=base,
                             t_counter=t_counter))
        out["t_counter_execute"] = t_counter
        out["approach_speed_mps"] = float(math.hypot(c["u_r"][0], c["v_r"][0]))
    elif kind == "speed_change":
        out.update(TM.speed_change(c["t"], c["x_w"], c["y_w"], c["heading"], c["u_r"], c["v_r"]))
        out.update({f"stop_{k}": v for k, v in TM.stopping(c["t"], c["x_w"], c["y_w"], c["heading"], c["u_r"]).items()})
        out["drift"] = [float(np.mean(c["current_n"])), float(np.mean(c["current_e"]))]
    elif kind in ("direct_spiral", "reverse_spiral"):
        pts = []
        for s in getattr(att, "settings", []):
            t0 = s["t_end"] - p["hold_s"] if s["steady"] else s["t_end"] - 120.0
            m = (c["t"] >= t0) & (c["t"] <= s["t_end"])
            # rate of turn = rate of change of heading (not the body yaw rate, which a heeled ship
            # turning steadily has smaller by cos φ); rudder = mean of all rudders
            rate = float(np.polyfit(c["t"][m], c["heading"][m], 1)[0]) if np.count_nonzero(m) > 2 else math.nan
            rud = np.mean([c[k][m] for k in c if re.fullmatch(r"rudder_\d+", k)], axis=0) if m.any() else None
            pts.append({"index": s["index"], "rate": rate,
                        "rudder": float(np.mean(rud)) if rud is not None else math.nan,
                        "speed": float(np.mean(np.hypot(c["u_r"][m], c["v_r"][m]))) if m.any() else math.nan,
                        "steady": s["steady"], "t0": t0, "t1": s["t_end"]})
        out["points"] = pts
    elif kind == "steady":
        out["mean_speed_mps"] = float(np.mean(np.hypot(c["u_r"], c["v_r"])))
        out["mean_heading_rad"] = float(np.angle(np.mean(np.exp(1j * c["heading"]))))
        for k in ("roll", "pitch"):
            out[f"mean_{k}_rad"] = float(np.mean(c[k]))
            out[f"rms_{k}_rad"] = float(np.std(c[k]))
        out["drift"] = [float(np.mean(c["current_n"])), float(np.mean(c["current_e"]))]
    elif kind == "backing":
        m = c["t"] >= att.t_execute
        out["astern_speed_mps"] = float(np.mean(c["u_r"][c["t"] <= att.t_execute + 1.0]))
        out["heading_change_deg"] = float(np.degrees(c["heading"][m][-1] - c["heading"][m][0]))
        out["mean_rate_dps"] = float(np.degrees(np.mean(c["r"][m])))
    return out
