"""Reducing a maneuvering-trial record (tactical circles, accelerations and decelerations, spirals,
zig-zags, pull-outs, backing) run by run, from the record alone.

Channels used (found by instrument kind): the tracking system's fixes (range radar, else GNSS, else
acoustic range), the gyro heading, the vertical gyro's roll, the rudder synchros (mean of all
rudders), the director's log sheet (EXECUTE times, the maneuver ordered, spiral setting marks). Each
run type goes to its reduction:

* turns — :func:`vtrials.reduce.turning.turning_metrics` (drift from positions 360° of heading apart,
  drift-corrected track, advance, transfer, tactical and steady diameter, steady speed and rate, heel,
  drift angle), then rate of turn against rudder per approach speed with rudder-breakdown detection;
* speed changes — :func:`vtrials.reduce.reach.reach_analysis` with the drift of the day's circles
  interpolated to the run's time (seed 002: runs interspersed with circles for that reason);
* zig-zags — :func:`vtrials.reduce.zigzag.zigzag_metrics`;
* direct spirals — :func:`vtrials.reduce.spiral.direct_spiral` (settings found in the rudder record);
  reverse spirals — :func:`vtrials.reduce.spiral.reverse_spiral_points` on the director's data windows,
  and the loop from those points;
* pull-out and backing — rates of turn from the gyro before and after.

IMO MSC.137(76) verdicts from whichever of the standard maneuvers the trial contains.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.records import Record
from vtrials.reduce import imo as IMO
from vtrials.reduce import reach as RE
from vtrials.reduce import spiral as SPI
from vtrials.reduce import turning as TU
from vtrials.reduce import zigzag as ZZ
from vtrials.reduce.estimate import Estimate

TRACKING = ("range_radar", "gnss", "acoustic_range")


def _kinds(rec: Record) -> dict:
    out: dict = {}
    for name in rec.instruments:
        out.setdefault(rec.meta(name).get("kind"), []).append(name)
    return out


class Channels:
    """The channels a maneuvering reduction reads, as arrays (SI)."""

    def __init__(self, rec: Record):
        k = _kinds(rec)
        self.tracking = next((n for kind in TRACKING for n in k.get(kind, [])), None)
        if self.tracking is None:
            raise ValueError(f"{rec.path}: no tracking system in the record")
        t, n = rec.channel(self.tracking, "north")
        _, e = rec.channel(self.tracking, "east")
        ok = np.isfinite(n) & np.isfinite(e)
        self.t, self.north, self.east = t[ok], n[ok], e[ok]
        g = k.get("heading", [None])[0]
        self.t_heading, self.heading = rec.channel(g, "heading") if g else (None, None)
        if self.heading is not None:
            self.heading = np.unwrap(self.heading)
        a = k.get("attitude", [None])[0]
        self.t_roll, self.roll = rec.channel(a, "roll") if a else (None, None)
        rud = k.get("rudder", [])
        if rud:
            self.t_rudder, r0 = rec.channel(rud[0], "angle")
            vals = [r0] + [np.interp(self.t_rudder, *rec.channel(r, "angle")) for r in rud[1:]]
            self.rudder = np.mean(vals, axis=0)
        else:
            self.t_rudder, self.rudder = None, None

    def window(self, t0: float, t1: float):
        m = (self.t >= t0) & (self.t <= t1)
        mh = (self.t_heading >= t0) & (self.t_heading <= t1)
        out = {"t": self.t[m], "north": self.north[m], "east": self.east[m], "t_heading": self.t_heading[mh],
               "heading": self.heading[mh]}
        if self.roll is not None:
            mr = (self.t_roll >= t0) & (self.t_roll <= t1)
            out.update(t_roll=self.t_roll[mr], roll=self.roll[mr])
        if self.rudder is not None:
            mu = (self.t_rudder >= t0) & (self.t_rudder <= t1)
            out.update(t_rudder=self.t_rudder[mu], rudder=self.rudder[mu])
        return out


def _rate(t, psi) -> Estimate:
    tc = t - t.mean()
    s = float(tc @ (psi - psi.mean()) / (tc @ tc))
    res = psi - psi.mean() - s * tc
    se = math.sqrt(float(res @ res) / max(t.size - 2, 1) / float(tc @ tc))
    return Estimate(s, se, max(t.size - 2, 1))


def _clean(d):
    """Estimates and numpy values → JSON-ready."""
    if isinstance(d, Estimate):
        return d.to_dict()
    if isinstance(d, dict):
        return {k: _clean(v) for k, v in d.items()}
    if isinstance(d, (list, tuple)):
        return [_clean(v) for v in d]
    if isinstance(d, np.ndarray):
        return d.tolist()
    if isinstance(d, np.generic):
        return d.item()
    if hasattr(d, "to_dict"):
        return _clean(d.to_dict())
    return d


def reduce_maneuvering(rec: Record) -> dict:
    ch = Channels(rec)
    runs = sorted([r for r in rec.run_log if r["accepted"]], key=lambda r: r["run"])
    L = float(rec.team.get("length_m", math.nan))
    out_runs = []
    drift_times, drifts = [], []
    turns = []
    # turns first: their drifts serve the speed changes
    for r in runs:
        if r["maneuver"].get("type") not in ("turn",):
            continue
        w = ch.window(r["t_comex"] - 5.0, r["t_finex"])
        approach = r["t_execute"] - r["t_comex"]
        try:
            res = TU.turning_metrics(w["t"], w["north"], w["east"], w["heading"], r["t_execute"],
                                     t_heading=w["t_heading"], roll=w.get("roll"), t_roll=w.get("t_roll"),
                                     rudder=w.get("rudder"), t_rudder=w.get("t_rudder"), approach_s=approach)
        except (ValueError, np.linalg.LinAlgError) as exc:
            out_runs.append({"run": r["run"], "type": "turn", "error": str(exc)})
            continue
        d = {"run": r["run"], "type": "turn", "label": r["label"], "t_execute": r["t_execute"],
             "t_finex": r["t_finex"], "rudder_ordered": r["maneuver"].get("rudder"), **_clean(res.to_dict())}
        out_runs.append(d)
        turns.append((r, res))
        if res.drift is not None:
            drift_times.append(0.5 * (r["t_execute"] + r["t_finex"]))
            drifts.append(res.drift)
    for r in runs:
        kind = r["maneuver"].get("type")
        p = r["maneuver"]
        if kind == "turn":
            continue
        w = ch.window(r["t_comex"] - 5.0, r["t_finex"])
        approach = r["t_execute"] - r["t_comex"]
        d: dict = {"run": r["run"], "type": kind, "label": r["label"], "t_execute": r["t_execute"],
                   "t_finex": r["t_finex"], "completed": r.get("completed", True)}
        try:
            if kind == "speed_change":
                drift = RE.interpolate_drift(drift_times, drifts, 0.5 * (r["t_execute"] + r["t_finex"])) \
                    if drifts else None
                res = RE.reach_analysis(w["t"], w["north"], w["east"], r["t_execute"], heading=w["heading"],
                                        t_heading=w["t_heading"], drift=drift, approach_s=approach,
                                        seed=int(r["run"]))
                d.update(_clean(res.to_dict()))
                d["drift_used"] = None if drift is None else {"north": drift.north.to_dict(),
                                                              "east": drift.east.to_dict(),
                                                              "extrapolated": drift.extrapolated}
                d["to_order"] = p.get("to_order")
            elif kind == "zigzag":
                res = ZZ.zigzag_metrics(w["t_heading"], w["heading"], w["t_rudder"], w["rudder"],
                                        check_angle=p["check"], approach_s=approach)
                d.update(_clean(res.to_dict()))
                d["rudder_ordered"] = p["rudder"]
                sp = ch.window(r["t_comex"], r["t_execute"])
                if sp["t"].size >= 3:
                    vn, ve = _rate(sp["t"], sp["north"]).value, _rate(sp["t"], sp["east"]).value
                    d["approach_sog"] = math.hypot(vn, ve)
            elif kind == "direct_spiral":
                wr = ch.window(r["t_execute"], r["t_finex"])
                res = SPI.direct_spiral(wr["t_heading"], wr["heading"], wr["t_rudder"], wr["rudder"])
                d.update(_clean(res.to_dict()))
                d["settings_logged"] = r.get("settings", [])
            elif kind == "reverse_spiral":
                segs = [(s["t_end"] - p["hold_s"], s["t_end"]) for s in r.get("settings", []) if s["steady"]]
                pts = SPI.reverse_spiral_points(w["t_heading"], w["heading"], w["t_rudder"], w["rudder"], segs)
                d["points"] = [{"rate": _clean(q.rate), "rudder": _clean(q.rudder), "window": list(q.window)}
                               for q in pts]
                try:
                    d["loop"] = _clean(SPI.hysteresis_loop(pts).to_dict())
                except (ValueError, np.linalg.LinAlgError) as exc:
                    d["loop"] = {"error": str(exc)}
                d["not_steady"] = [s["index"] for s in r.get("settings", []) if not s["steady"]]
            elif kind == "pull_out":
                tr = r.get("t_release", math.nan)
                before = ch.window(tr - 60.0, tr)
                after = ch.window(r["t_finex"] - 60.0, r["t_finex"])
                d["rate_before_release"] = _clean(_rate(before["t_heading"], before["heading"]))
                d["residual_rate"] = _clean(_rate(after["t_heading"], after["heading"]))
            elif kind == "backing":
                ap = ch.window(r["t_comex"], r["t_execute"])
                vn, ve = _rate(ap["t"], ap["north"]), _rate(ap["t"], ap["east"])
                d["approach_sog"] = math.hypot(vn.value, ve.value)
                af = ch.window(r["t_execute"], r["t_finex"])
                d["heading_change"] = float(af["heading"][-1] - af["heading"][0])
                d["mean_rate"] = _clean(_rate(af["t_heading"], af["heading"]))
        except (ValueError, np.linalg.LinAlgError, IndexError) as exc:
            d["error"] = f"{type(exc).__name__}: {exc}"
        out_runs.append(d)
    out_runs.sort(key=lambda x: x["run"])
    # rate of turn against rudder, per approach speed and side; rudder breakdown
    breakdown = []
    if turns:
        spd = [res.approach_speed.value for _, res in turns]
        rud = [res.rudder_steady.value if res.rudder_steady is not None else r["maneuver"]["rudder"]
               for r, res in turns]
        rate = [res.steady_rate if res.steady_rate is not None else Estimate(math.nan, math.nan) for _, res in turns]
        for g in TU.rudder_breakdown(spd, rud, rate, speed_tol=0.5):
            breakdown.append(_clean({"speed": g.speed, "side": g.side, "rudder": g.rudder, "rate": g.rate,
                                     "rate_std": g.rate_std, "breakdown": g.breakdown,
                                     "breakdown_rudder": g.breakdown_rudder}))
    return {"kind": "maneuvering", "tracking": ch.tracking, "runs": out_runs, "rate_vs_rudder": breakdown,
            "drift_circles": {"times": drift_times, "drifts": [_clean(x) for x in drifts]},
            "imo": imo_verdicts(out_runs, runs, L)}


def imo_verdicts(out_runs: list[dict], log: list[dict], L: float) -> dict:
    """IMO MSC.137(76) verdicts from the standard maneuvers present (35° turns, 10/10 and 20/20
    zig-zags, a full-astern stop)."""
    if not math.isfinite(L):
        return {}
    byrun = {r["run"]: r for r in log}

    def est(x):
        return None if x is None else Estimate(x["value"], x["std"], x.get("dof"))

    kw: dict = {}
    speeds = []
    turns = [d for d in out_runs if d["type"] == "turn" and d.get("advance")]
    full = [d for d in turns if d.get("rudder_ordered") is not None
            and abs(d["rudder_ordered"]) >= math.radians(34.0)]
    if full:
        worst = max(full, key=lambda d: d["advance"]["value"])
        kw["advance_m"] = est(worst["advance"])
        worst_t = max(full, key=lambda d: d["tactical_diameter"]["value"] if d.get("tactical_diameter") else -1)
        if worst_t.get("tactical_diameter"):
            kw["tactical_diameter_m"] = est(worst_t["tactical_diameter"])
        speeds += [d["approach_speed"]["value"] for d in full if d.get("approach_speed")]
    zz10 = [d for d in out_runs if d["type"] == "zigzag" and d.get("first_overshoot")
            and abs(abs(d["rudder_ordered"]) - math.radians(10.0)) < 1e-6]
    zz20 = [d for d in out_runs if d["type"] == "zigzag" and d.get("first_overshoot")
            and abs(abs(d["rudder_ordered"]) - math.radians(20.0)) < 1e-6]
    if zz10:
        worst = max(zz10, key=lambda d: d["first_overshoot"]["value"])
        kw["first_overshoot_10_rad"] = est(worst["first_overshoot"])
        if worst.get("second_overshoot"):
            kw["second_overshoot_10_rad"] = est(worst["second_overshoot"])
        if worst.get("initial_turning_time") and worst.get("approach_sog"):
            it = worst["initial_turning_time"]
            kw["initial_turning_m"] = Estimate(it["value"] * worst["approach_sog"], it["std"] * worst["approach_sog"])
        speeds += [d["approach_sog"] for d in zz10 if d.get("approach_sog")]
    if zz20:
        kw["first_overshoot_20_rad"] = est(max(zz20, key=lambda d: d["first_overshoot"]["value"])["first_overshoot"])
    stops = [d for d in out_runs if d["type"] == "speed_change" and d.get("track_reach")
             and str(d.get("to_order", "")).startswith("back")]
    if stops:
        kw["stopping_track_reach_m"] = est(max(stops, key=lambda d: d["track_reach"]["value"])["track_reach"])
    if not kw or not speeds:
        return {}
    V = float(np.mean(speeds))
    res = IMO.assess(L, V, **kw)
    return {"length_m": L, "speed_mps": V, "verdicts": _clean(res)}


__all__ = ["reduce_maneuvering", "imo_verdicts", "Channels"]
