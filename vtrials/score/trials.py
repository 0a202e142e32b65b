"""Scoring: each reduced result against a truth reference computed from the true state by its own
definition, with the error and whether the reduced 95 % interval covers the truth.

Truth references (never the reduction run on cleaner data):

* a run's speed through water, ground speed, current, power: means over its window [EXECUTE, FINEX]
  of the true state (:func:`vtrials.trials.crew.window_truth`);
* power is reduced as a trials team has it — shaft power at the torsionmeters' gauges, P_S = 2π n Q_gauge,
  which carries the stern-tube loss aft of the gauge — so its reference is the same quantity: the true
  delivered power 2π n Q_P plus each gauge's loss 2π n · s c_F n (:func:`gauge_power`); the delivered
  power stays in the truth as ``delivered_power``;
* a spot's speed through water: the heading-balanced mean ½(mean over the base-course runs + mean
  over the reciprocal runs) — the quantity current elimination estimates;
* the speed–power curve: the calm-water steady states at the shaft settings the crew used
  (:mod:`vtrials.truth.calmwater`), interpolated monotonically in log–log between the settings and their
  midpoints;
* a log calibration: the knotmeter's own drawn calibration (:meth:`Knotmeter.true_calibration`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import PchipInterpolator

from vtrials.reduce.estimate import Estimate
from vtrials.reduce.trials import curve_power
from vtrials.truth.calmwater import TWIN_TOL_MPS
from vtrials.units import KNOT


def _cmp(reduced: dict | None, truth: float, scale: float = 1.0) -> dict:
    """Error (reduced − truth) / scale, the reduced 95 % interval and whether it covers the truth."""
    if reduced is None or truth is None or not math.isfinite(truth):
        return {"truth": truth, "reduced": None if reduced is None else reduced.get("value"), "error": None,
                "covered": None}
    e = Estimate(reduced["value"], reduced["std"], reduced.get("dof"))
    lo, hi = e.interval()
    # half_width95 is in the units of "error" (divided by ``scale`` like it) for campaign sharpness
    return {"truth": truth, "reduced": e.value, "std": e.std, "lo95": lo, "hi95": hi,
            "half_width95": 0.5 * (hi - lo) / scale, "error": (e.value - truth) / scale, "covered": bool(e.covers(truth)) if math.isfinite(e.std) else None}


def _truth_of(crew, trial: str) -> dict:
    """Truth references of the accepted attempts of one trial, by run number."""
    acc = {(a.run.number, a.attempt) for a in crew.attempts if a.accepted and a.run.trial == trial}
    return {r["run"]: r for r in crew.truth_refs if (r["run"], r["attempt"]) in acc}


def true_curve(points: list[dict]):
    """P_true(V) [W] from calm-water points (monotone cubic in log–log).

    Points closer in speed than 10 × the twins' steadiness tolerance (:data:`TWIN_TOL_MPS`) are one
    steady state as far as the curve can tell — their secant slope is convergence noise — and only the
    first is kept. (Settings above the engine's limit all end at the limit's speed: the end point
    "3 % above the top spot" then fell 2e-5 m/s from that spot, and the log–log secant of 0.2 between
    them bent the monotone cubic up by 0.3–0.8 % of power over the last interval.)"""
    pts = sorted((p["stw"], p["power"]) for p in points if p["stw"] > 0 and p["power"] > 0)
    kept = []
    for q in pts:
        if not kept or q[0] - kept[-1][0] >= 10.0 * TWIN_TOL_MPS:
            kept.append(q)
    v = np.array([p[0] for p in kept])
    P = np.array([p[1] for p in kept])
    f = PchipInterpolator(np.log(v), np.log(P), extrapolate=False)
    return (lambda x: np.exp(f(np.log(np.asarray(x, float))))), (float(v.min()), float(v.max()))


def gauge_power(iset, delivered: float, rps: list[float]) -> float:
    """Shaft power at the torsionmeters' gauges [W] from the true delivered power [W] and the shaft
    speeds [rev/s] per propeller: P_D + Σ 2π n · s c_F n over the shafts that carry a torsionmeter
    (:meth:`vtrials.instruments.devices.ShaftTorque.loss_power`)."""
    seen = set()
    p = float(delivered)
    for dev in iset.devices.values():
        if dev.kind == "shaft_torque" and dev.index not in seen and dev.index < len(rps):
            seen.add(dev.index)
            p += dev.loss_power(float(rps[dev.index]))
    return p


def _at_gauge(iset, ref: dict, rps: list[float]) -> dict:
    return {**ref, "power": gauge_power(iset, ref["power"], rps), "delivered_power": ref["power"]}


def spot_stw_truth(runs: list[dict]) -> float:
    """A spot's true speed through water from its runs' truth references (``stw``, ``heading``): the
    heading-balanced mean ½(mean over the runs on the first run's course + mean over the reciprocal
    runs) — the quantity current elimination estimates."""
    c0 = runs[0]["heading"]
    base = [x["stw"] for x in runs if math.cos(x["heading"] - c0) > 0]
    recip = [x["stw"] for x in runs if math.cos(x["heading"] - c0) <= 0]
    return 0.5 * (np.mean(base) + np.mean(recip))


def score_standardization(reduced: dict, res, name: str) -> dict:
    crew = res.crew
    truth = {k: _at_gauge(crew.iset, r, [sh["rps"] for sh in r["shafts"]]) for k, r in _truth_of(crew, name).items()}
    runs = []
    for r in reduced["runs"]:
        tr = truth[r["run"]]
        runs.append({"run": r["run"], "label": r["label"], "sog": _cmp(r["vg"], tr["sog"]),
                     "power_measured": {**_cmp(r["power"], tr["power"], scale=tr["power"]),
                                            "note": "error relative to the true power"},
                     "true_stw": tr["stw"],
                     "true_current": [tr["current_n"], tr["current_e"]], "true_wind_speed": tr["wind_speed"]})
    calm = [_at_gauge(crew.iset, p, p["rps"]) for p in res.calm_water.get(name, [])]
    P_true, (vlo, vhi) = true_curve(calm) if len(calm) >= 2 else (None, (math.nan, math.nan))
    spots = []
    worst = 0.0
    for s in reduced["spots"]:
        rr = [truth[k] for k in s["runs"]]
        c0 = rr[0]["heading"]
        stw_true = spot_stw_truth(rr)
        # true current along the spot's first course, per run (what the elimination implies)
        h = (math.cos(c0), math.sin(c0))
        cur_true = [x["current_n"] * h[0] + x["current_e"] * h[1] for x in rr]
        d = {"group": s["group"], "stw": _cmp(s["stw"], stw_true), "stw_error_kn": None,
             "current_along_base": {"reduced": s["current_along_base"], "truth": cur_true,
                                    "error": [a - b for a, b in zip(s["current_along_base"], cur_true)]}}
        d["stw_error_kn"] = d["stw"]["error"] / KNOT
        calm_pt = next((p for p in calm if p.get("group") == s["group"]), None)
        if calm_pt is not None:
            d["calm_water_setting"] = {"stw": calm_pt["stw"], "power": calm_pt["power"]}
        if P_true is not None:
            v = s["stw"]["value"]
            pt = float(P_true(v)) if vlo <= v <= vhi else math.nan
            d["power_at_equal_speed"] = _cmp(s["power"], pt, scale=pt if pt == pt else 1.0)
            d["power_at_equal_speed"]["note"] = "error relative to the true power"
            if s.get("power_fit") and math.isfinite(pt):
                rel = s["power_fit"]["value"] / pt - 1.0
                d["curve_error"] = rel
                worst = max(worst, abs(rel))
        spots.append(d)
    curve = None
    if P_true is not None and reduced.get("curve"):
        lo, hi = reduced["curve"]["speed_range"]
        lo, hi = max(lo, vlo), min(hi, vhi)
        vv = np.linspace(lo, hi, 60)
        rel = curve_power(reduced["curve"], vv) / P_true(vv) - 1.0
        curve = {"max_abs_rel_error": float(np.max(np.abs(rel))), "speed": vv.tolist(), "rel_error": rel.tolist(),
                 "true_points": [{"stw": p["stw"], "power": p["power"], "group": p.get("group")} for p in calm]}
    cover = [sp["stw"]["covered"] for sp in spots if sp["stw"]["covered"] is not None]
    summary = {"spots": len(spots), "max_abs_stw_error_kn": max(abs(sp["stw_error_kn"]) for sp in spots),
               "stw_coverage": sum(cover) / len(cover) if cover else None,
               "max_abs_curve_error_at_spots": worst,
               "max_abs_curve_error": None if curve is None else curve["max_abs_rel_error"]}
    return {"reduced": reduced, "truth": {"runs": [truth[r["run"]] for r in reduced["runs"]],
                                          "calm_water": calm},
            "error": {"summary": summary, "runs": runs, "spots": spots, "curve": curve}}


def score_log_calibration(reduced: dict, res, name: str) -> dict:
    crew = res.crew
    truth = _truth_of(crew, name)
    # the reduction's speed through water is one per group (the joint current fit takes it equal on the
    # group's legs): its reference is the mean of the legs' true values, as for a standardization spot;
    # each leg's own true value (head or tail wind moves it by ~0.01 m/s) is kept beside it
    group_stw = {}
    for leg in reduced["legs"]:
        group_stw.setdefault(leg["group"], []).append(truth[leg["run"]]["stw"])
    legs = []
    for leg in reduced["legs"]:
        tr = truth[leg["run"]]
        c = _cmp(leg["stw"], float(np.mean(group_stw[leg["group"]])))
        legs.append({"run": leg["run"], "group": leg["group"], "stw": c, "stw_leg_truth": tr["stw"],
                     "stw_error_kn": None if c["error"] is None else c["error"] / KNOT,
                     "sog": _cmp(leg["vg"], tr["sog"]),
                     "true_current": [tr["current_n"], tr["current_e"]]})
    cur = reduced["current"]
    tref = cur["t_ref"]
    cur_err = []
    for leg in ([] if "under_determined" in cur else reduced["legs"]):  # an unresolved current has no error
        tr = truth[leg["run"]]
        dt = leg["t_mid"] - tref
        cn, ce = (cur[c]["value"] + sum(cur[f"{c}_{k}"]["value"] * dt ** p for p, k in ((1, "rate"), (2, "accel"))
                                        if f"{c}_{k}" in cur) for c in ("north", "east"))
        if "tidal_period_s" in cur:  # steady stream plus semidiurnal tide about t_ref
            w = 2.0 * math.pi * dt / cur["tidal_period_s"]
            cn, ce = (x + cur[f"{c}_cos"]["value"] * math.cos(w) + cur[f"{c}_sin"]["value"] * math.sin(w)
                      for x, c in ((cn, "north"), (ce, "east")))
        cur_err.append({"run": leg["run"], "reduced": [cn, ce], "truth": [tr["current_n"], tr["current_e"]],
                        "error_mps": math.hypot(cn - tr["current_n"], ce - tr["current_e"])})
    cals = {}
    for inst, cal in reduced["calibrations"].items():
        dev = crew.iset.devices.get(inst)
        if "error" in cal or not hasattr(dev, "true_calibration"):
            continue
        a, b = dev.true_calibration()
        xs = np.asarray(cal["x"])
        line_err = cal["intercept"]["value"] + cal["slope"]["value"] * xs - (a + b * xs)
        cals[inst] = {"intercept": _cmp(cal["intercept"], a), "slope": _cmp(cal["slope"], b),
                      "true_line": {"intercept_mps": a, "slope": b},
                      "line_error_at_points_kn": (line_err / KNOT).tolist(),
                      "true_breakaway_mps": getattr(dev, "v_break", None)}
    cover = [x["stw"]["covered"] for x in legs if x["stw"]["covered"] is not None]
    errs = [abs(x["stw_error_kn"]) for x in legs if x["stw_error_kn"] is not None]
    summary = {"legs": len(legs), "max_abs_stw_error_kn": max(errs) if errs else None,
               "stw_coverage": sum(cover) / len(cover) if cover else None,
               "max_current_error_kn": max(c["error_mps"] for c in cur_err) / KNOT if cur_err else None}
    return {"reduced": reduced, "truth": {"legs": [truth[x["run"]] for x in reduced["legs"]]},
            "error": {"summary": summary, "legs": legs, "current": cur_err, "calibrations": cals}}


def _rel(c: dict) -> dict:
    """Add the relative error to a comparison."""
    if c.get("error") is not None and c.get("truth"):
        c["rel_error"] = c["error"] / abs(c["truth"])
    return c


def _abs_est(d: dict | None) -> dict | None:
    return None if d is None else {**d, "value": abs(d["value"])}


# (reduced key, truth key, truth scale to SI, compare magnitudes)
TURN_KEYS = [("advance", "advance_m", 1.0, False), ("transfer", "transfer_m", 1.0, False),
             ("tactical_diameter", "tactical_diameter_m", 1.0, False),
             ("steady_diameter", "steady_turning_diameter_m", 1.0, False),
             ("steady_speed", "steady_speed_mps", 1.0, False),
             ("steady_rate", "steady_rate_of_turn_dps", math.pi / 180, True),
             ("heel_max", "heel_max_deg", math.pi / 180, True), ("approach_speed", "approach_speed_mps", 1.0, False)]
REACH_KEYS = [("time_to_dead_in_water", "stop_time_to_dead_in_water_s", 1.0, False),
              ("track_reach", "stop_track_reach_m", 1.0, False), ("head_reach", "stop_head_reach_m", 1.0, False),
              ("lateral_deviation", "stop_lateral_deviation_m", 1.0, False),
              ("terminal_speed", "terminal_speed_mps", 1.0, False),
              ("time_to_terminal_speed", "time_to_terminal_speed_s", 1.0, False),
              ("time_to_90_percent", "time_to_90_percent_s", 1.0, False)]
ZIGZAG_KEYS = [("first_overshoot", "first_overshoot_deg", math.pi / 180, False),
               ("second_overshoot", "second_overshoot_deg", math.pi / 180, False),
               ("initial_turning_time", "initial_turning_time_s", 1.0, False),
               ("time_to_check_yaw", "time_to_check_yaw_s", 1.0, False),
               # the reference's period is between the first and third heading-threshold crossings
               # (vtrials.truth.metrics.zigzag), which the reduction reports as period_heading (its
               # ``period`` is between like rudder executes, which holds the helmsman's reaction)
               ("period_heading", "period_s", 1.0, False)]


def _compare(red: dict, tru: dict, keys) -> dict:
    out = {}
    for rk, tk, f, mag in keys:
        if red.get(rk) is None or tru.get(tk) is None:
            continue
        rv = _abs_est(red[rk]) if mag else red[rk]
        tv = abs(tru[tk] * f) if mag else tru[tk] * f
        out[rk] = _rel(_cmp(rv, tv))
    return out


def _spiral_points(red_pts: list, true_pts: list) -> list:
    """Match reduced spiral points to the true per-setting means by their data windows."""
    out = []
    for q in red_pts:
        win = q.get("hold") or q.get("window")
        if not win or not true_pts:
            continue
        tm = 0.5 * (win[0] + win[1])
        tp = min(true_pts, key=lambda x: abs(0.5 * (x["t0"] + x["t1"]) - tm))
        out.append({"rudder": _cmp(q["rudder"], tp["rudder"]), "rate": _cmp(q["rate"], tp["rate"]),
                    "steady": q.get("steady", True), "true_steady": tp["steady"]})
    return out


def drift_corrected_turns(truth: dict) -> dict:
    """Turn references on the track through the water less the trial's mean loop drift.

    A trials team corrects a turning circle for its drift — the track's displacement between
    positions one loop apart (ITTC Recommended Procedure 7.5-04-02-01, Full Scale Manoeuvring
    Trials, turning circle analysis) — which holds the current and also the wind's leeway of the
    circling ship; the
    reduction averages it over the day's circles of both sides. The reference is taken by the same
    definition: the track through the water (current removed exactly) less the true leeway, the mean
    over the trial's turns of each one's water-track drift from 360° to 720° (the part that flips with
    the side of the turn averages out, as in the reduction). Advance, transfer and tactical diameter
    are corrected to first order (position less drift × time from EXECUTE); the water-track values are
    kept as ``*_water_track_m``. A turn that ends a little short of 720° (its FINEX called on the
    crew's gyro) gives the drift of its last 360° (``steady_loop_drift_mps``, the loop its steady
    values come from), as the reduction takes it (:func:`vtrials.reduce.turning.drift_over_loop`):
    leaving such a turn out made the reference the other side's leeway alone on KVLCC2's day of one
    35° circle per side. Turns without a steady loop give no drift; with none, nothing changes."""
    loops = [r.get("loop_drift_mps") or r["steady_loop_drift_mps"] for r in truth.values()
             if r.get("loop_drift_mps") or r.get("steady_loop_drift_mps")]
    if not loops:
        return truth
    dn, de = np.mean(loops, axis=0)
    out = {}
    for k, r in truth.items():
        if r.get("type") not in ("turn", "pull_out") or "approach_heading_rad" not in r:
            out[k] = r
            continue
        c, s = math.cos(r["approach_heading_rad"]), math.sin(r["approach_heading_rad"])
        along, across = dn * c + de * s, -dn * s + de * c
        r = {**r, "leeway_drift_mps": [float(dn), float(de)]}
        if "time_to_90deg_s" in r:
            t90 = r["time_to_90deg_s"]
            r["advance_water_track_m"], r["transfer_water_track_m"] = r["advance_m"], r["transfer_m"]
            r["advance_m"] = r["advance_m"] - along * t90
            r["transfer_m"] = abs(r["transfer_signed_m"] - across * t90)
        if "time_to_180deg_s" in r:
            r["tactical_diameter_water_track_m"] = r["tactical_diameter_m"]
            r["tactical_diameter_m"] = abs(r["tactical_signed_m"] - across * r["time_to_180deg_s"])
        out[k] = r
    return out


def score_maneuvering(reduced: dict, res, name: str) -> dict:
    crew = res.crew
    truth = drift_corrected_turns(_truth_of(crew, name))
    runs = []
    worst = {"turn_rel": 0.0, "reach_rel": 0.0, "overshoot_deg": 0.0}
    cover = []
    for r in reduced["runs"]:
        tr = truth.get(r["run"], {})
        d = {"run": r["run"], "type": r["type"], "label": r.get("label")}
        if "error" in r:
            d["reduction_error"] = r["error"]
        elif r["type"] in ("turn", "pull_out"):
            d.update(_compare(r, tr, TURN_KEYS))
            dd = r.get("drift")
            if dd and tr.get("drift"):
                # the day's drift (the line through the circles at s = 0) is the current plus the circling
                # ship's mean leeway of both sides: its reference by the same definition
                # (drift_corrected_turns' leeway_drift_mps, the mean of the turns' second-loop drifts)
                lee = tr.get("leeway_drift_mps", [0.0, 0.0])
                d["drift_north"] = _cmp(dd["north"], tr["drift"][0] + lee[0])
                d["drift_east"] = _cmp(dd["east"], tr["drift"][1] + lee[1])
            for k in ("advance", "tactical_diameter"):
                if k in d and d[k].get("rel_error") is not None:
                    worst["turn_rel"] = max(worst["turn_rel"], abs(d[k]["rel_error"]))
                    cover.append(d[k]["covered"])
        elif r["type"] == "speed_change":
            d.update(_compare(r, tr, REACH_KEYS))
            for k in ("time_to_dead_in_water", "track_reach"):
                if k in d and d[k].get("rel_error") is not None:
                    worst["reach_rel"] = max(worst["reach_rel"], abs(d[k]["rel_error"]))
        elif r["type"] == "zigzag":
            d.update(_compare(r, tr, ZIGZAG_KEYS))
            for k in ("first_overshoot", "second_overshoot"):
                if k in d and d[k].get("error") is not None:
                    worst["overshoot_deg"] = max(worst["overshoot_deg"], abs(math.degrees(d[k]["error"])))
        elif r["type"] in ("direct_spiral", "reverse_spiral"):
            d["points"] = _spiral_points(r.get("points", []), tr.get("points", []))
            st = res.calm_water.get(f"spiral_run_{r['run']}")
            loop = r.get("loop") or {}
            if st is not None:
                h = st["hysteresis"]
                d["loop"] = {"true_unstable": h["unstable"], "true_width": h["width"], "true_height": h["height"],
                             "reduced_width": loop.get("width"), "reduced_height": loop.get("height"),
                             "reduced_verdict": loop.get("verdict")}
                if isinstance(loop.get("width"), dict):
                    d["loop"]["width"] = _cmp(loop["width"], h["width"])
                if isinstance(loop.get("height"), dict) and h["height"] == h["height"]:
                    d["loop"]["height"] = _cmp(loop["height"], h["height"])
        elif r["type"] == "backing":
            if tr.get("heading_change_deg") is not None and r.get("heading_change") is not None:
                d["heading_change"] = {"reduced": r["heading_change"], "truth": math.radians(tr["heading_change_deg"])}
        runs.append(d)
    imo = reduced.get("imo") or {}
    imo_truth = {}
    if imo:
        from vtrials.reduce import imo as IMO
        L = imo["length_m"]
        t_turns = [truth[r["run"]] for r in reduced["runs"] if r["type"] == "turn" and r.get("rudder_ordered")
                   and abs(r["rudder_ordered"]) >= math.radians(34.0) and r["run"] in truth]
        kw = {}
        if t_turns:
            kw["advance_m"] = max(t.get("advance_m", 0.0) for t in t_turns)
            kw["tactical_diameter_m"] = max(t.get("tactical_diameter_m", 0.0) for t in t_turns)
        z10 = [truth[r["run"]] for r in reduced["runs"] if r["type"] == "zigzag"
               and abs(abs(r.get("rudder_ordered", 0)) - math.radians(10)) < 1e-6 and r["run"] in truth]
        z20 = [truth[r["run"]] for r in reduced["runs"] if r["type"] == "zigzag"
               and abs(abs(r.get("rudder_ordered", 0)) - math.radians(20)) < 1e-6 and r["run"] in truth]
        if z10:
            kw["first_overshoot_10_rad"] = math.radians(max(t.get("first_overshoot_deg", 0.0) for t in z10))
            kw["second_overshoot_10_rad"] = math.radians(max(t.get("second_overshoot_deg", 0.0) for t in z10))
        if z20:
            kw["first_overshoot_20_rad"] = math.radians(max(t.get("first_overshoot_deg", 0.0) for t in z20))
        stops = [truth[r["run"]] for r in reduced["runs"] if r["type"] == "speed_change"
                 and str(r.get("to_order", "")).startswith("back") and r["run"] in truth]
        if stops and any("stop_track_reach_m" in t for t in stops):
            kw["stopping_track_reach_m"] = max(t.get("stop_track_reach_m", 0.0) for t in stops)
        if kw:
            imo_truth = json_ready(IMO.assess(L, imo["speed_mps"], **kw))
    summary = {"runs": len(runs), "max_rel_error_advance_tactical": worst["turn_rel"],
               "advance_tactical_coverage": (sum(bool(c) for c in cover) / len(cover)) if cover else None,
               "max_rel_error_stop_time_reach": worst["reach_rel"],
               "max_abs_overshoot_error_deg": worst["overshoot_deg"]}
    return {"reduced": reduced, "truth": {"runs": [truth.get(r["run"]) for r in reduced["runs"]],
                                          "steady_turn": {k: v for k, v in res.calm_water.items()
                                                          if k.startswith("spiral_run_")},
                                          "imo": imo_truth},
            "error": {"summary": summary, "runs": runs}}


def json_ready(x):
    if isinstance(x, dict):
        return {k: json_ready(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_ready(v) for v in x]
    if hasattr(x, "to_dict"):
        return json_ready(x.to_dict())
    if isinstance(x, np.generic):
        return x.item()
    return x


def score_trial(kind: str, reduced: dict, res, name: str) -> dict:
    if kind == "standardization":
        return score_standardization(reduced, res, name)
    if kind == "log_calibration":
        return score_log_calibration(reduced, res, name)
    if kind == "maneuvering":
        return score_maneuvering(reduced, res, name)
    if kind == "airwake_survey":
        from vtrials.score.airwake import score_airwake_survey
        return score_airwake_survey(reduced, res, name)
    if kind == "seakeeping":
        from vtrials.score.seakeeping import score_seakeeping
        return score_seakeeping(reduced, res, name)
    raise ValueError(f"no scoring for trial kind {kind!r}")
