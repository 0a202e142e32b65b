"""Reducing a trial record: what the trials team does with the data of a standardization or a
speed-log calibration trial, from the record file alone.

Inputs (all from :class:`vtrials.records.netcdf.Record`): the instrument groups (found by their ``kind``, not
their names), the director's log sheet (``run_log``: run numbers, courses, settings, COMEX / EXECUTE /
FINEX times, accepted runs), the team's knowledge (ship particulars, windage coefficients, surveyed
sensor positions, nominal calibrations) and the tank prediction in the record's attributes.

* :func:`run_statistics` — per run: mean, σ, standard error, min, max of every channel over the run
  window [EXECUTE, FINEX] (seed 002 tabulates these for every run), SOG/COG from each tracking system
  (straight-line fit) and from the LORAN display, shaft power per shaft (P_S = 2π n Q from the torque and
  r/min meters: the power in the shaft at the torsionmeter's gauge, between engine and stern tube —
  it includes the stern-tube loss aft of the gauge, which the team cannot measure), net thrust
  (static load removed), relative wind. "power" is this shaft power at the gauge throughout (runs,
  spots, curve), as a trials team reports it; the direct power method is applied to it (its
  corrections are power increments at unchanged r/min, where the stern-tube loss, a function of r/min,
  does not change). The scoring reference is the same quantity (vtrials/score/trials.py).
* :func:`reduce_standardization` — the spots' speeds through water from one joint fit of the day's
  runs (a speed per spot, the current's change with time common to the day:
  :func:`vtrials.reduce.current.joint_spot_current_fit`; its budget is the tracking uncertainty
  propagated through the fit, scaled by the fit's own scatter on its dof); power corrected per run for
  the wind by the direct power method (R_AA from the measured relative wind and the ship's coefficients, η_D from the
  tank prediction); speed–power, r/min, torque and thrust against speed through water (cubic in
  log–log, a power law whose exponent may vary with speed); the ITTC iterative method over all runs as
  the alternative analysis.
* :func:`reduce_log_calibration` — per leg ground speed; the current and the speeds through water from
  a joint least-squares fit of every leg (|U_g h_i + c(t_i)|: one U per speed group, a current
  vector, with a linear trend when the legs allow); the four-leg closed form (seed 000 App. A) and the
  reciprocal-pair shortcut as the classic cross-checks; the knotmeter (and EM log) regression with
  its statistics and 95 % band; the smoothing study of the 10-s counts.

Everything is SI; results are plain dicts (JSON-ready) with Estimates as {value, std, dof, lo95, hi95}.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, stats

from vtrials.records.netcdf import Record
from vtrials.reduce import current as CUR
from vtrials.reduce import logcal as LC
from vtrials.reduce import runstats as RS
from vtrials.reduce import speedpower as SP
from vtrials.reduce import stawave as STA
from vtrials.reduce.estimate import Estimate

TRACKING_PREFERENCE = ("range_radar", "gnss", "acoustic_range")


# ----------------------------------------------------------------------------------------- helpers
def _est(e: Estimate | None) -> dict | None:
    return None if e is None else e.to_dict()


def _by_kind(rec: Record) -> dict:
    out: dict = {}
    for name in rec.instruments:
        out.setdefault(rec.meta(name).get("kind"), []).append(name)
    return out


def _angular(kind: str, channel: str) -> bool:
    return channel in ("heading", "cog") or (kind == "anemometer" and channel == "angle")


def _fix_errors(meta: dict, north, east) -> list:
    """The tracking system's fix errors as its data sheet gives them, in the form
    :func:`vtrials.reduce.runstats.sog_from_track` takes: (G, sd, τ) per error source.

    Range–range radar: each transponder's range error (multipath, white) maps into the fix through
    the two range lines, δp = M⁻¹ δr with M's rows the unit vectors from the surveyed stations to the
    fix (the geometric dilution the fix suffers where the lines cross at a narrow angle). GNSS: the
    stated correlated parts per axis, and the rest of the stated horizontal accuracy as white."""
    north, east = np.asarray(north, float), np.asarray(east, float)
    kind = meta.get("kind")
    if kind == "range_radar" and meta.get("range_errors"):
        p = np.column_stack([north, east])
        ua = p - np.asarray(meta["transponder_a"], float)
        ub = p - np.asarray(meta["transponder_b"], float)
        ua /= np.linalg.norm(ua, axis=1)[:, None]
        ub /= np.linalg.norm(ub, axis=1)[:, None]
        det = ua[:, 0] * ub[:, 1] - ua[:, 1] * ub[:, 0]
        if np.any(np.abs(det) < 1e-6):
            return []  # on the baseline: the fix has no geometry (the residuals' statistics only)
        # M = [ua; ub] (2×2 per sample): columns of M⁻¹ = the fix's response to each range's error
        g_a = np.column_stack([ub[:, 1], -ub[:, 0]]) / det[:, None]
        g_b = np.column_stack([-ua[:, 1], ua[:, 0]]) / det[:, None]
        return [(g, sd, tau) for sd, tau in meta["range_errors"] for g in (g_a, g_b)]
    if kind == "gnss" and meta.get("horizontal_accuracy_m"):
        corr = [tuple(map(float, x)) for x in meta.get("correlated_errors", [])]
        white = math.sqrt(max(float(meta["horizontal_accuracy_m"]) ** 2 - sum(sd * sd for sd, _ in corr), 0.0))
        axes = (np.tile([1.0, 0.0], (north.size, 1)), np.tile([0.0, 1.0], (north.size, 1)))
        return [(g, sd, tau) for sd, tau in corr + [(white, 0.0)] if sd > 0 for g in axes]
    return []


def accepted_runs(rec: Record) -> list[dict]:
    """The log sheet's accepted runs, in run order (one entry per run number)."""
    return sorted([r for r in rec.run_log if r["accepted"]], key=lambda r: r["run"])


# the angle at which two lines of position may cross for a fix to be accepted (hydrographic practice for
# two-range and two-angle fixes: between 30 and 150 deg; NOAA Office of Coast Survey, Field Procedures
# Manual; IHO C-13 Manual on Hydrography ch. 2)
FIX_CUT_DEG = (30.0, 150.0)


def run_statistics(rec: Record, run: dict, min_cut: bool = False) -> dict:
    """Everything the team tabulates for one run window [EXECUTE, FINEX] (SI units).

    ``min_cut``: a range–range radar whose two range lines cross at less than 30° or more than 150°
    somewhere in the window (:data:`FIX_CUT_DEG`; its ``crossing_angle`` channel) is not taken as the
    run's tracking (its statistics are still listed): near the baseline through the two stations the
    fix loses its geometry and, on crossing it, jumps to the mirror side — a 320-m tanker's 16-h day
    wanders ±35 km and crosses a shore pair's baseline 20 km off (SOG errors to 3 m/s, 50 times the
    stated σ, on 3 of 24 KVLCC2 trial days); the next system in :data:`TRACKING_PREFERENCE` tracks it."""
    t0, t1 = run["t_execute"], run["t_finex"]
    kinds = _by_kind(rec)
    channels = {}
    for name in rec.instruments:
        kind = rec.meta(name).get("kind")
        st = {}
        for ch in rec.channels(name):
            t, x = rec.channel(name, ch)
            if np.ndim(x) > 1:  # a spectrum per sample (wave buoy, wave radar): no run statistics of it
                st[ch] = None
                continue
            try:
                st[ch] = RS.channel_stats(t, x, t0, t1, angular=_angular(kind, ch)).to_dict()
            except ValueError:  # fewer than two samples in the window (e.g. a slow display)
                st[ch] = None
        channels[name] = st
    out = {"run": run["run"], "label": run["label"], "group": run["group"], "leg": run["leg"],
           "course": math.radians(run["course_deg"]), "t_mid": 0.5 * (t0 + t1), "t_execute": t0,
           "t_finex": t1, "steady": bool(run["approach_steady"] and run["run_steady"]),
           "notes": run["approach_notes"] + run["run_notes"], "channels": channels, "sog": {}}
    for kind in TRACKING_PREFERENCE:
        for name in kinds.get(kind, []):
            t, n = rec.channel(name, "north")
            _, e = rec.channel(name, "east")
            ok = np.isfinite(n) & np.isfinite(e)
            try:
                fit = RS.sog_from_track(t[ok], n[ok], e[ok], t0, t1,
                                        fix_errors=_fix_errors(rec.meta(name), n[ok], e[ok]))
                out["sog"][name] = {"sog": _est(fit.sog), "cog": _est(fit.cog), "kind": kind,
                                    "along_rms": fit.along_rms, "cross_rms": fit.cross_rms, "n": fit.n}
            except ValueError:
                pass
    for name in kinds.get("loran", []):
        t, v = rec.channel(name, "sog")
        tu, vu = RS.updates_from_samples(t, v)
        try:
            out["sog"][name] = {"sog": _est(RS.sog_from_displayed(tu, vu, t0, t1)), "kind": "loran"}
        except ValueError:
            pass
    def usable(name):
        if not min_cut or out["sog"][name]["kind"] != "range_radar" or "crossing_angle" not in rec.channels(name):
            return True
        tc, cut = rec.channel(name, "crossing_angle")
        w = (tc >= t0) & (tc <= t1)
        c = np.degrees(cut[w])
        ok = bool(c.size) and bool(np.all(np.isfinite(c))) and FIX_CUT_DEG[0] <= c.min() and c.max() <= FIX_CUT_DEG[1]
        if not ok:
            out["notes"] = out["notes"] + [f"{name}: range lines cross outside {FIX_CUT_DEG[0]:g}-"
                                           f"{FIX_CUT_DEG[1]:g} deg in the window; not used for tracking"]
        return ok

    primary = next((n for k in TRACKING_PREFERENCE for n in kinds.get(k, []) if n in out["sog"] and usable(n)), None)
    if primary is None:
        raise ValueError(f"run {run['run']}: no tracking fixes in the window")
    out["tracking"] = primary
    s = out["sog"][primary]["sog"]
    out["vg"] = Estimate(s["value"], s["std"], s["dof"])
    # the run's residual acceleration along its track: from a receiver's Doppler velocity where there
    # is one (far less noisy than the fixes' curvature), else from the tracking fixes (not Loran's)
    gnss = kinds.get("gnss", [])
    try:
        if gnss:
            t, v = rec.channel(gnss[0], "sog")
            _, c = rec.channel(gnss[0], "cog")
            a, a_se = SP.along_track_acceleration_from_velocity(t, v, c, t0, t1)
            out["accel"] = {"value": a, "std": a_se, "source": f"{gnss[0]} velocity"}
        elif out["sog"][primary].get("kind") != "loran":
            t, n = rec.channel(primary, "north")
            _, e = rec.channel(primary, "east")
            a, a_se = SP.along_track_acceleration(t, n, e, t0, t1)
            out["accel"] = {"value": a, "std": a_se, "source": f"{primary} fixes"}
    except ValueError:
        pass
    # shafts: power from the torque and r/min meters, net thrust, indicated pitch
    shafts = {}
    for name in kinds.get("shaft_torque", []):
        m = rec.meta(name)
        st = channels[name]["torque"]
        if st is not None:  # the zero logged at the pre-trial zero setting is removed
            z = float(m.get("zero_reading_N_m", 0.0))
            st = {**st, "mean": st["mean"] - z, "min": st["min"] - z, "max": st["max"] - z,
                  "calibration_std": math.hypot(float(m.get("zero_uncertainty_N_m", 0.0)),
                                                float(m.get("scale_uncertainty", 0.0)) * (st["mean"] - z))}
        shafts.setdefault(m["shaft_index"], {})["torque"] = st
    for name in kinds.get("shaft_rpm", []):
        m = rec.meta(name)
        st = channels[name]["rps"]
        if st is not None:  # the counter's stated accuracy: common to every run with this counter
            st = {**st, "calibration_std": float(m.get("calibration_uncertainty_rps", 0.0))}
        shafts.setdefault(m["shaft_index"], {})["rps"] = st
    for name in kinds.get("thrust", []):
        m = rec.meta(name)
        st = channels[name]["thrust"]
        if st is not None:
            shafts.setdefault(m["shaft_index"], {})["thrust"] = {**st, "mean": st["mean"] - m["nominal_static_load_N"]}
    for name in kinds.get("pitch_indicator", []):
        shafts.setdefault(rec.meta(name)["shaft_index"], {})["pitch"] = channels[name]["pitch"]
    power, syst = [], []
    for k in sorted(shafts):
        sh = shafts[k]
        if sh.get("torque") and sh.get("rps"):
            q, n = sh["torque"], sh["rps"]
            p = RS.shaft_power_estimate(Estimate(q["mean"], q["se"], max(q["n_eff"] - 1, 1)),
                                        Estimate(n["mean"], n["se"], max(n["n_eff"] - 1, 1)))
            sh["power"] = _est(p)
            power.append(p)
            # calibration (zero and scale of the torsionmeter, the counter's accuracy): common to every
            # run with these meters
            syst.append(2 * math.pi * math.hypot(n["mean"] * q.get("calibration_std", 0.0),
                                                 q["mean"] * n.get("calibration_std", 0.0)))
    out["shafts"] = {str(k): v for k, v in sorted(shafts.items())}
    if power:
        out["power"] = Estimate(sum(p.value for p in power), math.sqrt(sum(p.std ** 2 for p in power)))
        out["power_calibration_std"] = math.sqrt(sum(x * x for x in syst))
    # relative wind (the first anemometer in name order: the mast)
    anem = kinds.get("anemometer", [])
    if anem:
        a = anem[0]
        ts, sp = rec.channel(a, "speed")
        _, an = rec.channel(a, "angle")
        w = (ts >= t0) & (ts <= t1)
        sp, an = sp[w], an[w]
        m = rec.meta(a)
        if m.get("airwake_speed") is not None:  # the mast's airwake, known from its survey: removed
            sp, an = SP.correct_airwake(sp, an, m["airwake_speed"], m.get("airwake_direction_rad", [0.0]))
        vx = float(np.mean(sp * np.cos(an)))
        vy = float(np.mean(sp * np.sin(an)))
        out["wind"] = {"instrument": a, "speed": math.hypot(vx, vy), "angle": math.atan2(vy, vx),
                       "speed_se": channels[a]["speed"]["se"] if channels[a]["speed"] else math.nan,
                       "height_m": -float(rec.meta(a)["surveyed_position_m"][2])}
    return out


def _mom(values, stds) -> Estimate:
    """Current elimination over a spot's runs (alternating courses): 2 runs → simple average; 3 → 1:2:1
    mean of means; 4 → ITTC (1, 3, 3, 1)/8; n → repeated averaging (binomial weights)."""
    v = np.asarray(values, float)
    n = v.size
    if n == 2:
        return CUR.two_run_average(v, stds)
    if n == 3:
        return CUR.three_run_mean_of_means(v, stds)
    if n == 4:
        return CUR.ittc_mean_of_means(v, stds)
    return CUR.mean_of_means(v, stds)


def _method_name(n: int) -> str:
    return {2: "two-run average", 3: "mean of means 1:2:1", 4: "ITTC mean of means (1:3:3:1)/8"}.get(
        n, f"mean of means over {n} runs")


def _wind_cx(team: dict):
    w = team.get("windage")
    if not w:
        return None
    ang = np.asarray(w["angles_rad"])
    cx_body = np.asarray(w["C_X"])

    def cx(psi):
        a = np.abs(np.arctan2(np.sin(psi), np.cos(psi)))
        return -np.interp(a, ang, cx_body)  # resistance positive (body C_X is negative in head wind)
    return cx, float(w["A_F_m2"])


def _eta_d(tank: dict, v):
    if not tank:
        return None
    return np.interp(v, tank["speed_mps"], tank["eta_D"])


def _xi_p(tank: dict, v):
    """Overload factor ξ_P of the tank's load-variation test at speed v (None if the tank did none)."""
    if not tank or not tank.get("xi_P"):
        return None
    return float(np.interp(v, tank["speed_mps"], tank["xi_P"]))


def _tank_log_slope(tank: dict):
    """v ↦ d ln P / d ln V of the tank prediction's power (central differences between its speeds,
    interpolated; 3 — the cubic law — where the record has no tank prediction)."""
    if not tank or len(tank.get("speed_mps", [])) < 2:
        return lambda v: 3.0
    lv, lp = np.log(tank["speed_mps"]), np.log(tank["power_W"])
    q = np.gradient(lp, lv)
    return lambda v: float(np.interp(math.log(max(v, 1e-9)), lv, q))


# ----------------------------------------------------------------------------------- standardization
def _along_course(run: dict) -> Estimate:
    """A run's speed over ground along its course line, V_G cos(χ − ψ_c) [m/s] (χ the course over
    ground, ψ_c the run's nominal course): the distance made good along the measured course per unit
    time, which is what the current elimination's V_G = V_S ± V_C assumes. The track's speed magnitude
    carries the cross-course current as well, √((V_S + V_C∥)² + V_C⊥²) ≈ V_S + V_C∥ + V_C⊥²/2V_S — a
    bias the mean of means cannot remove (0.01 m/s for a 5 m/s ship in a 0.35 m/s cross tide). Standard
    uncertainty from the speed's and the course's (first-order propagation)."""
    s = run["sog"][run["tracking"]]
    if "cog" not in s:  # a log's displayed speed: no course of its own (the magnitude is all there is)
        return run["vg"]
    v, sv = run["vg"].value, run["vg"].std
    d = s["cog"]["value"] - run["course"]
    sd = s["cog"]["std"]
    c = math.cos(d)
    return Estimate(v * c, math.hypot(c * sv, v * math.sin(d) * sd), run["vg"].dof)


OFF_COURSE = math.radians(20.0)  # a run's track this far from its ordered course is not on the measured course


def _runs_on_the_course(rec: Record, runs: list[dict]) -> tuple[list[dict], list[dict]]:
    """The runs the speed analysis may use, and those it sets aside with the reason.

    ITTC 7.5-04-01-01.1 (2017) §5: runs that do not meet the steadiness criteria are rejected. A run
    the director flagged unsteady (the log sheet: the approach never settled and the run went ahead)
    is set aside when its spot keeps a run on each course without it; and a run whose track is more
    than 20° off its ordered course (a slow ship that could not hold its heading in a strong beam
    wind) is not on the measured course at all, whatever the log sheet says."""
    log = {r["run"]: r for r in accepted_runs(rec)}
    out, bad = [], []
    for r in runs:
        s = r["sog"][r["tracking"]]
        off = abs(RS.wrap_pi(s["cog"]["value"] - r["course"])) if "cog" in s else 0.0
        if off > OFF_COURSE:
            bad.append({"run": r["run"], "reason": f"track {math.degrees(off):.0f}° off the ordered course"})
        else:
            out.append(r)
    keep = []
    for r in out:
        if not r["steady"]:
            others = [x for x in out if x["group"] == r["group"] and x is not r and x["steady"]]
            sides = {math.copysign(1.0, math.cos(x["course"] - r["course"])) for x in others}
            if sides == {1.0, -1.0}:
                notes = "; ".join(log[r["run"]]["approach_notes"] + log[r["run"]]["run_notes"])
                bad.append({"run": r["run"], "reason": f"flagged unsteady ({notes})"})
                continue
        keep.append(r)
    return keep, bad


def reduce_standardization(rec: Record) -> dict:
    team = rec.team
    runs, excluded = _runs_on_the_course(rec, [run_statistics(rec, r) for r in accepted_runs(rec)])
    if not runs:
        raise ValueError(f"{rec.path}: no accepted runs")
    groups = sorted({r["group"] for r in runs})
    tank = rec.attr("tank_prediction", {})
    windinfo = _wind_cx(team)
    rho_air = 1.225
    disp = (rec.attr("condition", {}) or {}).get("displacement_m3") or team.get("displacement_m3")
    rho_w = float(team.get("water_density", 1025.0))
    for r in runs:
        r["vg_course"] = _along_course(r)
    tt = np.array([r["t_mid"] for r in runs])
    vg = np.array([r["vg_course"].value for r in runs])
    vg_se = np.array([r["vg_course"].std for r in runs])
    hd = np.array([r["course"] for r in runs])
    pw = np.array([r["power"].value for r in runs])
    # the spots' speeds through water: one joint fit of every run (a speed per spot, the day's current)
    joint = CUR.joint_spot_current_fit(tt, vg, vg_se, hd, [r["group"] for r in runs])
    stw = dict(zip(joint.groups, joint.vs))
    _through_water_acceleration(runs, joint, hd)
    # the ITTC iterative analysis over all runs, as the alternative analysis (its power law across a CP
    # ship's combinator line is model error: nothing of it enters the spots' budgets)
    iterative = None
    for model, k in (("tidal", 4), ("linear", 2), ("constant", 1)):
        if len(runs) - (k + 3) < 2:
            continue
        try:
            iterative = CUR.ittc_iterative(tt, vg, hd, pw, model=model)
            break
        except (ValueError, np.linalg.LinAlgError, RuntimeError):
            continue
    slope = _tank_log_slope(tank)
    kinds = _by_kind(rec)
    spots = []
    for g in groups:
        rs = [r for r in runs if r["group"] == g]
        n = len(rs)
        v = [r["vg_course"].value for r in rs]
        vs = stw[g]
        p_ms = np.array([r["power"].value for r in rs])
        p_ms_se = np.array([r["power"].std for r in rs])
        # wind: R_AA per run from the measured relative wind, then the direct power method
        d_r = np.zeros(n)
        d_r_se = np.zeros(n)
        d_r_coef = np.zeros(n)  # the wind coefficient's part of d_r_se: one error, signed per run
        d_r_wave = np.zeros(n)  # STAWAVE's part: a method error, not seen in the runs' scatter
        wind_used = []
        if windinfo is not None and all("wind" in r for r in rs):
            cx, a_xv = windinfo
            cx_rel = float(team["windage"].get("C_rel_std", 0.05))  # the wind-tunnel data's stated accuracy
            wr = SP.wind_resistance([r["wind"]["speed"] for r in rs], [r["wind"]["angle"] for r in rs], v, cx,
                                    a_xv, rho_air, z_anemometer=rs[0]["wind"]["height_m"], z_ref=10.0,
                                    v_wr_std=[r["wind"]["speed_se"] for r in rs], cx_rel_std=cx_rel,
                                    heading=[r["course"] for r in rs] if n > 1 else None)
            d_r, d_r_se, d_r_coef = wr.r_aa, wr.std, wr.coef_sens
            wind_used = [{"r_aa": float(a), "v_wt": float(b), "psi_wt": float(c)}
                         for a, b, c in zip(wr.r_aa, wr.v_wt, wr.psi_wt)]
        # waves: STAWAVE-2 on the runs with the observed sea within ±45° of the bow (ITTC 7.5-04-01-01.1)
        waves_used = []
        sea = team.get("sea_observed")
        if sea and all(team.get(k) for k in ("length_m", "beam_m", "draught_m")):
            L_, B_, T_ = team["length_m"], team["beam_m"], team["draught_m"]
            c_b = float(disp or team.get("displacement_m3", 0.0)) / (L_ * B_ * T_)
            d_r, d_r_se = np.array(d_r, dtype=float), np.array(d_r_se, dtype=float)
            for i, r in enumerate(rs):
                raw, raw_se = STA.run_wave_resistance(sea, r["course"], vs.value, L_, B_, T_, c_b, rho=rho_w)
                d_r[i] += raw
                d_r_se[i] = math.hypot(d_r_se[i], raw_se)
                d_r_wave[i] = raw_se
                waves_used.append({"r_aw": raw, "std": raw_se})
        # the runs' residual acceleration (SP.acceleration_resistance): inertia is not calm-water power
        r_acc = np.zeros(n)
        if disp and all("accel" in r for r in rs):
            r_acc, r_acc_se = SP.acceleration_resistance([r["accel"]["value"] for r in rs], disp, rho_w,
                                                         accel_std=[r["accel"]["std"] for r in rs])
            d_r, d_r_se = d_r + r_acc, np.hypot(d_r_se, r_acc_se)
        eta = _eta_d(tank, vs.value)
        xi = _xi_p(tank, vs.value)
        if eta is not None:
            p_id, p_id_se = SP.direct_power_method(p_ms, d_r, vs.value, float(eta), p_ms_std=p_ms_se,
                                                   delta_r_std=d_r_se, xi_p=xi)
            p_coef, p_wave = d_r_coef * vs.value / float(eta), d_r_wave * vs.value / float(eta)
        else:
            p_id, p_id_se = p_ms, p_ms_se
            p_coef, p_wave = np.zeros(n), np.zeros(n)
        w = CUR.mean_of_means_weights(n)
        P_ms = _mom(p_ms, p_ms_se)
        # the torsionmeters' calibration uncertainty is common to the spot's runs: added after averaging
        cal = float(np.mean([r.get("power_calibration_std", 0.0) for r in rs]))
        P_ms = Estimate(P_ms.value, math.hypot(P_ms.std, cal), P_ms.dof)
        # a curve point is the power AT the reduced speed: the speed's uncertainty moves along the curve
        # by its slope, d ln P / d ln V of the tank prediction (3 for a cubic law where there is none)
        p_speed = float(np.dot(w, p_id)) * slope(vs.value) * vs.std / vs.value
        rps = _mom([np.mean([float(s["rps"]["mean"]) for s in r["shafts"].values() if s.get("rps")]) for r in rs],
                   [1e-3] * n)
        torque = float(np.dot(w, [sum(s["torque"]["mean"] for s in r["shafts"].values() if s.get("torque"))
                                  for r in rs]))
        thrust = float(np.dot(w, [sum(s["thrust"]["mean"] for s in r["shafts"].values() if s.get("thrust"))
                                  for r in rs])) if all(any(s.get("thrust") for s in r["shafts"].values())
                                                       for r in rs) else None
        s_i = np.cos(np.array([r["course"] for r in rs]) - rs[0]["course"])
        current_along = [float(si * (vgi - vs.value)) for si, vgi in zip(s_i, v)]
        spots.append({"group": g, "runs": [r["run"] for r in rs], "n_runs": n,
                      "method": f"joint fit of the day's runs (current change: {joint.model})",
                      "stw": _est(vs), "power_measured": _est(P_ms), "power": None,
                      "power_speed_std": p_speed, "power_calibration_std": cal,
                      "_corrected": (np.asarray(p_id, float), np.asarray(p_id_se, float), np.sign(s_i), vs.dof,
                                     _log_speed_factor(rs, kinds, slope(vs.value)), np.asarray(p_coef, float),
                                     np.asarray(p_wave, float)),
                      "rps": rps.value, "torque": torque, "thrust": thrust,
                      "current_along_base": current_along, "wind": wind_used, "waves": waves_used,
                      "eta_D": None if eta is None else float(eta), "xi_P": xi,
                      "r_acc": [float(x) for x in np.atleast_1d(r_acc)],
                      "steady": all(r["steady"] for r in rs)})
    _spot_powers(spots)
    # the faired speed–power curve: monotone cubic through the spots in log–log (trial practice fairs
    # the curve through the spots; a global law — the ITTC power law below — cannot follow a resistance
    # hump to 1 %)
    order = np.argsort([s["stw"]["value"] for s in spots])
    V = np.array([spots[i]["stw"]["value"] for i in order])
    Pp = np.array([spots[i]["power"]["value"] for i in order])
    Ps = np.array([spots[i]["power"]["std"] for i in order])
    curve = None
    if len(spots) >= 2 and np.all(np.diff(V) > 0):
        curve = {"kind": "pchip-loglog", "speed": V.tolist(), "power": Pp.tolist(), "rel_std": (Ps / Pp).tolist(),
                 "speed_range": [float(V.min()), float(V.max())]}
        for s in spots:
            s["power_fit"] = {"value": float(curve_power(curve, s["stw"]["value"])),
                              "rel_std": s["power"]["std"] / s["power"]["value"]}
    runs_out = []
    for r in runs:
        d = {k: v for k, v in r.items() if k not in ("vg", "vg_course", "power")}
        d["vg"] = _est(r["vg"])
        d["vg_course"] = _est(r["vg_course"])
        pw = r.get("power")
        d["power"] = None if pw is None else _est(Estimate(pw.value, math.hypot(pw.std, r.get("power_calibration_std", 0.0))))
        runs_out.append(d)
    out = {"kind": "standardization", "tracking": runs[0]["tracking"], "runs": runs_out, "spots": spots,
           "curve": curve, "excluded_runs": excluded,
           "joint_fit": {"current_model": joint.model, "dof": joint.dof, "chi2": joint.chi2,
                         "birge_ratio": math.sqrt(joint.scale), "offsets": list(joint.offset),
                         "current_change": [float(x) for x in joint.current_change(tt)],
                         "residuals": [float(x) for x in joint.residuals], "runs": [r["run"] for r in runs]}}
    if iterative is not None:
        out["ittc_iterative"] = {"model": iterative.model, "vs": list(map(float, iterative.vs)),
                                 "vs_std": list(map(float, iterative.vs_std)),
                                 "current": list(map(float, iterative.current)),
                                 "a": _est(iterative.a), "b": _est(iterative.b), "q": _est(iterative.q),
                                 "dof": iterative.dof, "runs": [r["run"] for r in runs]}
    return out


def _through_water_acceleration(runs: list[dict], joint, hd: np.ndarray) -> None:
    """Each run's acceleration through the water: its acceleration over ground (from the fixes) less
    the rate of change of the day's fitted current along its course (the joint fit's tidal or linear
    change, ``joint.current_rate``), with that rate's uncertainty added.

    Only the acceleration through the water costs power. In a tidal stream whose speed changes in time,
    the horizontal pressure gradient that drives the stream carries a floating ship along with the water
    (Froude–Krylov and added-mass force of the current's acceleration, (ρ∇ + m_x) dV_c/dt; the
    simulator's hydrostatics component applies it): the ship's speed over ground follows the stream
    with no change of thrust. Taken as inertia, the stream's acceleration (KVLCC2's days: ~2e-5 m/s²
    RMS along the course, 8 % of resistance per 1e-4 m/s²) entered each run's corrected power with the
    sign of its course (KVLCC2's days: 2e-5 m/s² RMS along the course, where 1e-4 m/s² is ~4 % of its
    resistance). The mean of means cancels most of it, but not the same-course scatter of a spot's runs,
    an hour apart while the tide turns, from which the spot power's budget is taken (KVLCC2: same-course
    difference of the corrected powers 1.5 % RMS, 0.5 % with the true through-water acceleration)."""
    s0 = hd[0]
    for r, h in zip(runs, hd):
        acc = r.get("accel")
        if acc is None:
            continue
        rate, rate_se = joint.current_rate(r["t_mid"])
        sgn = 1.0 if math.cos(h - s0) >= 0.0 else -1.0
        r["accel"] = {**acc, "value": float(acc["value"] - sgn * rate[0]),
                      "std": float(math.hypot(acc["std"], rate_se[0])),
                      "source": f"{acc.get('source', 'fixes')}, less the fitted current's rate of change"}


def _log_speed_factor(rs: list[dict], kinds: dict, k: float) -> np.ndarray | None:
    """(L_i / L̄)^k per run: how much of a run's power is its own speed through water, from a speed log's
    mean reading L_i per run (the Doppler log's fore-aft speed, else the EM log) and the curve's slope
    k = d ln P / d ln V. At constant shaft speed a run into a gust or a stronger wind goes slower and
    needs less power; the ratio of one log's readings carries that change without the log's scale
    error (common to the runs), which cancels. None without a log reading on every run."""
    for kind, ch in (("doppler_log", "u"), ("em_log", "speed")):
        for name in kinds.get(kind, []):
            st = [((r["channels"].get(name) or {}).get(ch) or {}).get("mean") for r in rs]
            if all(x is not None and math.isfinite(x) and x > 0 for x in st):
                L = np.asarray(st, float)
                return (L / L.mean()) ** k
    return None


def _spot_powers(spots: list[dict]) -> None:
    """Each spot's corrected power (mean of means of its runs' direct-power-method powers) and its
    budget, named term by term (GUM, JCGM 100:2008; ITTC 7.5-02-01-01):

    * run-to-run scatter of the corrected power AT EQUAL SPEED (gusts, helm, sea): the relative scatter
      of runs on the SAME course at the same spot, pooled over the day's spots (dof = number of such
      repeats less one per course and spot), after each run's power is brought to the spot's mean speed
      through water by the speed log's relative reading (:func:`_log_speed_factor`). A run's power
      differs from the next for a real reason — at the same shaft speed a run into more wind is slower
      and needs less power (~k ΔV/V: several per cent on opposite courses, 1–4 % between two runs on
      the same course an hour apart on KVLCC2 in an NPD-gusted wind) — and the reference, the true
      curve at the spot's reduced speed, moves with it, because the spot's speed is the same balanced
      mean of the runs' speeds as its power is of their powers. Counting that change as scatter made
      the KVLCC2 interval twice as wide as its errors (campaign of 200 trial days: coverage 1.000,
      sharpness 2.08). Without a log the raw corrected powers are used (conservative). A day without
      same-course repeats (two-run spots) falls back to the spot's own scatter std/√2 over both courses;
    * the errors of the resistance corrections that the runs' scatter cannot show: the wind
      coefficient's (one error common to the runs, signed by each run's wind resistance, so that head
      and tail wind cancel in the mean only as far as they do) and STAWAVE's. The runs' own noise —
      of their mean power, relative wind and acceleration, the rest of each run's stated uncertainty
      (:func:`vtrials.reduce.speedpower.direct_power_method`) — is what the scatter measures, and is
      not counted twice; a single-run spot takes it as stated;
    * the torsionmeters' zero and scale calibration, common to the spot's runs;
    * the spot speed's uncertainty carried along the curve (``power_speed_std``).

    The interval is Student-t on the Welch–Satterthwaite dof of the scatter and speed terms."""
    ss, dof = 0.0, 0
    for sp in spots:
        p_id, _, sgn, _, f, _, _ = sp["_corrected"]
        q = p_id if f is None else p_id / f
        for c in (-1.0, 1.0):
            x = q[sgn == c]
            if x.size >= 2:
                rel = x / x.mean() - 1.0
                ss += float(np.sum(rel ** 2))
                dof += x.size - 1
    sigma_rel = math.sqrt(ss / dof) if dof > 0 else None
    for sp in spots:
        p_id, p_id_se, sgn, v_dof, f, p_coef, p_wave = sp.pop("_corrected")
        n = p_id.size
        w = CUR.mean_of_means_weights(n) if n > 1 else np.ones(1)
        if sigma_rel is not None:
            scatter, nu = sigma_rel * p_id, dof
        else:
            q = p_id if f is None else p_id / f
            scatter, nu = np.full(n, np.std(q, ddof=1) / math.sqrt(2) if n > 1 else 0.0), max(n - 1, 1)
        value = float(np.dot(w, p_id))
        if n == 1 and sigma_rel is None:  # one run, nothing to pool: its own stated uncertainty
            scatter = np.sqrt(np.maximum(p_id_se ** 2 - p_coef ** 2 - p_wave ** 2, 0.0))
        u_scatter2 = float(np.sum((w * scatter) ** 2))
        # on top of the scatter, the errors the runs share: the wind coefficient's (one error, signed
        # with each run's wind resistance) and STAWAVE's
        u_runs2 = float(np.dot(w, p_coef)) ** 2 + float(np.sum((w * p_wave) ** 2))
        u_speed = sp["power_speed_std"]
        u2 = u_scatter2 + u_runs2 + sp["power_calibration_std"] ** 2 + u_speed ** 2
        den = u_scatter2 ** 2 / nu + (u_speed ** 4 / v_dof if v_dof else 0.0)
        nu_eff = u2 ** 2 / den if den > 0 else None
        sp["power"] = Estimate(value, math.sqrt(u2), nu_eff).to_dict()
        sp["power_scatter_rel_std"] = None if sigma_rel is None else sigma_rel


def curve_power(curve: dict, v) -> np.ndarray:
    """Power [W] of a reduced faired curve (:func:`reduce_standardization`) at speeds v [m/s]; NaN
    outside the measured range."""
    from scipy.interpolate import PchipInterpolator
    f = PchipInterpolator(np.log(curve["speed"]), np.log(curve["power"]), extrapolate=False)
    return np.exp(f(np.log(np.asarray(v, float))))


# ----------------------------------------------------------------------------------- log calibration
def _current_basis(t, model, t_ref: float, span: float):
    """The time functions of the current model of the log-calibration fits, their names and the factor
    that turns the fit's coefficients into the reported ones. ``model`` 0–2: a polynomial of that degree
    in (t − t_ref)/span (coefficients reported per second^k); ``"tidal"``: a steady stream plus the
    principal semidiurnal tide, 1, cos ω(t − t_ref), sin ω(t − t_ref) with ω = 2π/12.42 h (the current
    model of the ITTC iterative method, ITTC 7.5-04-01-01.1 (2017), without its linear trend; m/s)."""
    tt = np.asarray(t, float) - t_ref
    if model == "tidal":
        w = 2.0 * math.pi / CUR.TIDAL_PERIOD
        return [np.ones_like(tt), np.cos(w * tt), np.sin(w * tt)], ["0", "cos", "sin"], np.ones(3)
    k = np.arange(int(model) + 1)
    return [(tt / span) ** j for j in k], [str(j) for j in k], span ** -k.astype(float)


def _joint_current_fit(t, heading, vg, vg_std, group, order, reading=None, ratio=None):
    """|U_i h(ψ_i) + c(t_i)| least squares: the legs' speeds through water U_i, and the current c =
    (c_N, c_E) in time (:func:`_current_basis`: ``order`` 0–2, a polynomial of that degree about the
    mean leg time, coefficients per second^k; ``"tidal"``, steady stream plus semidiurnal tide). ψ_i is
    the direction of the leg's water track (its course plus the measured drift angle,
    :func:`_leg_drift`).

    Without ``reading``, U_i = U_g, one unknown per group. With ``reading`` (a log's mean reading per
    leg, NaN where it shows nothing), the legs with a reading take U_i = β₀ + β₁ · reading_i — the log's
    calibration line solved inside the current fit, so each leg's own speed through water (head or
    tail wind moves it, and the log sees it) enters, and the line's uncertainty comes from the legs'
    tracking errors through the same fit; legs without a reading keep a U per group.

    With ``ratio`` (per leg, the ratio of a log's mean reading on the leg to its mean over the leg's
    group), a group's legs take U_i = U_g · ratio_i: at constant shaft speed a leg into the wind is
    slower through the water than one with it (±3 % on KVLCC2 in 15 kn, the big ship still settling an
    hour after the turn), and the log sees it, its scale error cancelling in the ratio. U_g is then the
    speed through water at the group's mean reading — the mean of the legs' speeds, the reference of a
    group's speed (:func:`vtrials.score.trials.score_log_calibration`) — and the leg-to-leg change no
    longer passes for scatter (τ) or for current.

    Legs weighed by 1/(σᵢ² + τ²), τ the scatter beyond the tracking's stated σ that makes χ² = dof
    (:func:`vtrials.reduce.current.ship_scatter`: the ship's own leg-to-leg speed changes for the
    groups' fit; the log's departures from a straight line, e.g. cross-flow at low speed, for the
    calibration fit). Returns a dict: ``names`` of the parameters, ``x``, ``cov`` (from the weights,
    absolute), ``A`` (the linearised estimator, parameters per leg speed over ground), ``dof``,
    ``t_ref``, ``residuals`` [m/s], ``tau``, ``groups`` (those with a U) and ``chi2``."""
    t, heading, vg, vg_std = (np.asarray(a, dtype=float) for a in (t, heading, vg, vg_std))
    has = np.zeros(vg.size, bool) if reading is None else np.isfinite(np.asarray(reading, float))
    rd = np.where(has, 0.0 if reading is None else np.asarray(reading, float), 0.0)
    ncal = 2 if has.any() else 0
    groups = sorted({g for g, h in zip(group, has) if not h})
    gi = np.array([groups.index(g) if not h else -1 for g, h in zip(group, has)])
    G = len(groups)
    tm = float(np.mean(t))
    span = max(float(np.ptp(t)), 1.0)
    basis, suffix, scale = _current_basis(t, order, tm, span)
    nb = len(basis)
    hc, hs = np.cos(heading), np.sin(heading)
    rr = np.ones(vg.size) if ratio is None else np.asarray(ratio, float)

    def model(x):
        U = x[ncal:ncal + G][np.maximum(gi, 0)] * rr if G else np.zeros(vg.size)
        if ncal:
            U = np.where(has, x[0] + x[1] * rd, U)
        c = x[ncal + G:]
        cn = sum(c[2 * k] * basis[k] for k in range(nb))
        ce = sum(c[2 * k + 1] * basis[k] for k in range(nb))
        return np.hypot(U * hc + cn, U * hs + ce)

    x0 = np.concatenate([[0.0, 1.0][:ncal], [np.mean(vg[gi == k] / rr[gi == k]) for k in range(G)],
                         np.zeros(2 * nb)])
    if ncal:  # start the line from the plain regression of ground speed on reading
        x0[:2] = np.polyfit(rd[has], vg[has], 1)[::-1] if np.ptp(rd[has]) > 0 else (0.0, 1.0)
    n, p = vg.size, x0.size
    dof = n - p

    def solve(tau):
        w = 1.0 / np.sqrt(vg_std ** 2 + tau ** 2)
        res = optimize.least_squares(lambda x: (model(x) - vg) * w, x0, method="lm", xtol=1e-14, ftol=1e-14)
        return w, res.jac, res.x, res.fun / w, float(res.fun @ res.fun)

    fit0 = solve(0.0)
    tau, (w, J, x, r, chi2) = CUR.ship_scatter(solve, fit0[4], dof, fit0[3], vg_std)
    cov = np.linalg.pinv(J.T @ J)
    A = np.linalg.pinv(J) * w[None, :]
    # the polynomial current's coefficients per second^k (the fit's are per span^k)
    unit = np.concatenate([np.ones(ncal + G), np.repeat(scale, 2)])
    names = ["intercept", "slope"][:ncal] + [f"U[{g}]" for g in groups] + \
        [f"{c}_{k}" for k in suffix for c in ("north", "east")]
    return {"names": names, "x": x * unit, "cov": cov * np.outer(unit, unit), "A": A * unit[:, None],
            "dof": dof, "t_ref": tm, "residuals": r, "tau": tau, "groups": groups, "chi2": chi2}


def _leg_drift(runs: list[dict], kinds: dict) -> tuple[np.ndarray, str]:
    """Drift angle β [rad] per leg — the angle of the water track off the heading (leeway in wind: up to
    4° on the patrol vessel's slow legs in 15 kn) — from the mean surge and sway of a water-track
    Doppler log (atan2(v̄, ū)), and where it came from. Without one, β = 0 and the water track is taken
    along the ordered course. The Doppler's misalignment about the vertical turns every leg's β by the
    same angle, which turns the whole picture (water tracks and current) about the vertical: the ground
    speeds' magnitudes, and so the speeds through water and the calibration, do not see it (only the
    current's direction does)."""
    for name in kinds.get("doppler_log", []):
        b = []
        for r in runs:
            u, v = r["channels"][name].get("u"), r["channels"][name].get("v")
            if u is None or v is None or u["mean"] <= 0.0:
                break
            b.append(math.atan2(v["mean"], u["mean"]))
        else:
            return np.array(b), f"{name} (water-track Doppler log: mean sway over mean surge per leg)"
    return np.zeros(len(runs)), "not measured (no water-track Doppler log): water track taken along the course"


def _reading_noise(runs: list[dict], name: str, reading) -> float:
    """Standard error [reading units] of one leg's mean reading of log ``name``: the root mean square of
    the legs' own standard errors (:func:`vtrials.reduce.runstats.channel_stats`, autocorrelation
    counted) over the legs with a reading — pooled, because a 300-s wander leaves one 10-min leg only
    one or two independent looks at it."""
    se = [((r["channels"].get(name) or {}).get("speed") or {}).get("se") for r, x in zip(runs, reading)
          if math.isfinite(x)]
    se = [x for x in se if x is not None and math.isfinite(x)]
    return math.sqrt(float(np.mean(np.square(se)))) if se else 0.0


def reduce_log_calibration(rec: Record) -> dict:
    runs = [run_statistics(rec, r, min_cut=True) for r in accepted_runs(rec)]
    kinds = _by_kind(rec)
    t = np.array([r["t_mid"] for r in runs])
    hd = np.array([r["course"] for r in runs])
    vg = np.array([r["vg"].value for r in runs])
    grp = [r["group"] for r in runs]
    vs = np.array([r["vg"].std for r in runs])
    drift, drift_source = _leg_drift(runs, kinds)
    # each leg's speed through water relative to its group's, from a log's relative readings
    ratio, ratio_source = np.ones(len(runs)), None
    for g in sorted(set(grp)):
        sel = [i for i, x in enumerate(grp) if x == g]
        f = _log_speed_factor([runs[i] for i in sel], kinds, 1.0) if len(sel) > 1 else None
        if f is not None:
            ratio[sel] = f
            ratio_source = "log readings"
    groups, U, cur, fit, under = resolve_current(t, hd, vg, vs, grp, drift=drift, ratio=ratio)
    dof, resid = fit["dof"], fit["residuals"]
    # classic cross-checks per group: the four-leg closed form and the reciprocal-pair shortcut
    classic = {}
    for g in groups:
        rs = [r for r in runs if r["group"] == g]
        if len(rs) == 4:
            try:
                fl = CUR.four_leg_current(*[r["vg"].value for r in rs], heading0=rs[0]["course"],
                                          std=[r["vg"].std for r in rs])
                classic[g] = {"method": "four-leg (seed 000 App. A)", "u": _est(fl.u), "c": _est(fl.c),
                              "theta": _est(fl.theta)}
            except ValueError as exc:
                classic[g] = {"method": "four-leg", "error": str(exc)}
        elif len(rs) == 2:
            pr = CUR.reciprocal_pair_speed(rs[0]["vg"].value, rs[1]["vg"].value,
                                           std=[rs[0]["vg"].std, rs[1]["vg"].std])
            classic[g] = {"method": "reciprocal pair √((Vx² + Vy²)/2) (uncorrected)", "u": _est(pr),
                          "two_run_average": 0.5 * (rs[0]["vg"].value + rs[1]["vg"].value)}
    # the log readings per leg, and the calibration regressions
    knot = kinds.get("knotmeter", [])
    em = kinds.get("em_log", [])
    legs = []
    for r in runs:
        leg = {"run": r["run"], "group": r["group"], "course": r["course"], "t_mid": r["t_mid"],
               "vg": _est(r["vg"]), "stw": _est(U[r["group"]]), "tracking": r["tracking"],
               "loran_sog": next((_s["sog"] for _s in r["sog"].values() if _s.get("kind") == "loran"), None)}
        for name in knot:
            st = r["channels"][name]["speed"]
            leg[f"{name}_speed"] = None if st is None else st["mean"]
        for name in em:
            st = r["channels"][name]["speed"]
            leg[f"{name}_speed"] = None if st is None else st["mean"]
        legs.append(leg)
    calibrations = {}
    for name in knot + em:
        pts = {}
        for leg in legs:
            xv = leg.get(f"{name}_speed")
            if xv is None or xv <= 0.0:  # below break-away (or astern): the log shows nothing
                continue
            pts.setdefault(leg["group"], []).append(xv)
        gs = sorted(pts)
        if len(gs) < 3:
            calibrations[name] = {"error": f"only {len(gs)} speeds with readings: no regression"}
            continue
        undet = [g for g in gs if U[g] is None]
        if undet:
            calibrations[name] = {"error": f"speed through water under-determined at group(s) {undet}: no regression"}
            continue
        xr = np.array([np.mean(pts[g]) for g in gs])
        yr = np.array([U[g].value for g in gs])
        ys = np.array([U[g].std for g in gs])
        cal = LC.calibrate(xr, yr, std=ys, absolute_sigma=False)
        group_line = {"method": "weighted regression of the groups' speeds through water on their mean "
                                "readings (Montgomery & Runger ch. 11)",
                      "intercept": _est(cal.beta0), "slope": _est(cal.beta1), "r2": cal.r2, "see": cal.see,
                      "chi2_red": cal.scale2, "n": cal.n, "dof": cal.dof}
        xs = np.linspace(0.0, float(xr.max()) * 1.05, 50)
        entry = {"x": xr.tolist(), "y": yr.tolist(), "y_std": ys.tolist(), "groups": gs,
                 "excluded_groups": sorted(set(groups) - set(gs)), "band_x": xs.tolist()}
        if "under_determined" in cur:  # no current model to solve the line in: the group regression
            lo, hi = cal.band(xs)
            calibrations[name] = {**group_line, **entry, "band_lo": np.asarray(lo).tolist(),
                                  "band_hi": np.asarray(hi).tolist()}
            continue
        reading = np.array([np.nan if (leg.get(f"{name}_speed") is None or leg[f"{name}_speed"] <= 0.0)
                            else leg[f"{name}_speed"] for leg in legs])
        # each leg's mean reading has its own error (the log's wander over the leg), measured from the
        # readings within the legs (their standard errors, pooled over the day: one leg's is too rough):
        # a known part of every leg's scatter about the line, on top of its tracking σ
        u_read = _reading_noise(runs, name, reading)
        has = np.isfinite(reading)
        k0 = np.polyfit(reading[has], vg[has], 1)[0] if np.ptp(reading[has]) > 0 else 1.0
        vs_cal = np.sqrt(vs ** 2 + np.where(has, (k0 * u_read) ** 2, 0.0))
        jf = _joint_current_fit(t, hd + drift, vg, vs_cal, grp, fit["order"], reading=reading)
        b, C = jf["x"][:2], jf["cov"][:2, :2]
        sd = np.sqrt(np.diag(C))
        # dof of each coefficient. An EM log's reading wanders slowly (its zero drifts over minutes):
        # the legs' stated σ hold that wander as measured within the legs, and a 10-min leg shows too
        # little of a 300-s wander for it to be known — as uncertain as the scatter τ found beside it,
        # so Student's t on the fit's dof whatever τ. With the stated σ taken as exact where χ² < dof
        # (τ = 0; Welch–Satterthwaite dof infinite), those days (18 % of 200 KVLCC2 days) were 69 %
        # covered (z rms 1.6), intercept and slope 91.0 % overall; on t: 95.5 / 96.0 %, sharpness 1.22 /
        # 1.26. A knotmeter's reading noise is its counts' (white, well measured within a leg): there
        # Welch–Satterthwaite with the τ part on the fit's dof (on t its intercept over-covered, 98.5 %
        # [0.957, 0.995] over 200 patrol days)
        slow_wander = name in em
        if slow_wander:
            nu = [jf["dof"], jf["dof"]]
        else:
            nu = [CUR.scatter_budget(jf["A"][k], vs_cal, jf["tau"], np.zeros(vs.size), jf["dof"])[1] for k in (0, 1)]
        se = np.sqrt(np.maximum(C[0, 0] + 2.0 * xs * C[0, 1] + xs ** 2 * C[1, 1], 0.0))
        q_t = float(stats.t.ppf(0.975, jf["dof"])) if slow_wander else 1.96
        line = b[0] + b[1] * xs
        fitted = b[0] + b[1] * xr
        ss_res = float(np.sum((yr - fitted) ** 2))
        ss_tot = float(np.sum((yr - yr.mean()) ** 2))
        calibrations[name] = {
            "method": "line solved inside the joint current fit, one speed through water per leg from its "
                      "reading (legs weighed by their tracking σ and the scatter τ beyond it; "
                      + ("Student's t on the fit's dof)" if slow_wander else "Welch–Satterthwaite dof)"),
            "intercept": _est(Estimate(float(b[0]), float(sd[0]), nu[0])),
            "slope": _est(Estimate(float(b[1]), float(sd[1]), nu[1])),
            "correlation": float(C[0, 1] / (sd[0] * sd[1])),
            "r2": 1.0 - ss_res / ss_tot if ss_tot > 0 else None,
            "see": float(np.sqrt(np.sum(jf["residuals"] ** 2) / jf["dof"])),
            "scatter_tau": jf["tau"], "chi2_red": jf["chi2"] / jf["dof"],
            "n": int(np.count_nonzero(np.isfinite(reading))), "legs_in_fit": int(reading.size),
            "parameters": jf["names"], "dof": jf["dof"], "current_order": fit["order"],
            **entry, "band_lo": (line - q_t * se).tolist(), "band_hi": (line + q_t * se).tolist(),
            "group_regression": group_line}
    # smoothing study on the knotmeter counts of every leg (seed 000 Figs. 4–5)
    smoothing = {}
    for name in knot:
        tc, cnt = rec.channel(name, "counts")
        window = float(rec.meta(name).get("count_window_s", 10.0))
        per_leg = []
        for r in runs:
            w = (tc >= r["t_execute"]) & (tc <= r["t_finex"])
            if np.count_nonzero(w) >= 6 and np.any(cnt[w] > 0):
                sm = LC.smoothing_study(tc[w], cnt[w], [1, 2, 3, 4, 6])
                per_leg.append({"run": r["run"], "k": sm.k.tolist(),
                                "std_kn": (np.asarray(sm.std) / window).tolist()})
        smoothing[name] = per_leg
    out = {"kind": "log_calibration", "tracking": runs[0]["tracking"], "legs": legs,
           "drift_angle": {"source": drift_source, "per_leg": drift.tolist()},
            "groups": {str(g): _est(U[g]) for g in groups},
            "current": {k: (_est(v) if isinstance(v, Estimate) else v) for k, v in cur.items()},
            "fit": {"dof": dof, "residual_rms": None if resid is None else float(np.sqrt(np.mean(resid ** 2))),
                    "trend": fit["trend"], "current_order": fit.get("order"),
                    "ship_scatter": fit.get("ship_scatter")},
            "classic": {str(g): v for g, v in classic.items()}, "calibrations": calibrations,
            "smoothing": smoothing,
            "runs": [{k: v for k, v in r.items() if k not in ("vg", "power")} | {"vg": _est(r["vg"])} for r in runs]}
    if under:
        out["under_determined"] = under
    return out


def resolve_current(t, heading, vg, vg_std, group, drift=None, ratio=None):
    """Speed through water per group and the current from the legs' ground speeds, or the reason they
    cannot be resolved.

    The joint least-squares fit (:func:`_joint_current_fit`) has G + 2 unknowns (G + 4 with a linear
    trend, G + 6 with a quadratic one: the richest that leaves at least 3 legs over). It is identified
    only when there are more legs than unknowns (else no degrees of freedom remain for its uncertainty)
    and its linearised design [group indicators, cos ψ, sin ψ (, their time-weighted copies)] has full
    rank: legs all on one axis (reciprocal pairs only) leave the current across that axis unresolved;
    then the current is reported as under-determined (``current = {"under_determined": why}``) and each group's speed
    through water falls back to the classic per-group estimate that needs no current: the mean of a
    reciprocal pair's ground speeds (the along-axis current cancels; seed 000 eq. 3), or the four-leg
    closed form (seed 000 App. A); a group with neither is under-determined too. ``heading`` is each
    leg's course, which sets the geometry (the axes and the rank); ``drift`` [rad] its measured drift
    angle, so that the fit takes the water track along heading + drift; ``ratio`` each leg's log reading
    over its group's mean reading (:func:`_joint_current_fit`), None to take the group's legs equal.

    The current's change in time: over a day shorter than half the semidiurnal period (12.42 h) the
    richest polynomial (quadratic, linear, constant) that leaves at least 3 legs over; over a longer day
    (a VLCC's: an hour to settle after every turn, 14 legs in 16 h) the steady stream plus the
    semidiurnal tide (the ITTC iterative method's model without its trend), which a quadratic cannot
    follow through more than half a period, and which, on less than half a period, is too close to a
    polynomial to be told apart from it.

    Returns (groups, U {group: Estimate | None}, current dict, fit dict, under-determined list).
    """
    t, heading, vg, vg_std = (np.asarray(a, dtype=float) for a in (t, heading, vg, vg_std))
    groups = sorted(set(group))
    G = len(groups)
    n = vg.size
    gi = np.array([groups.index(g) for g in group])
    tm = float(np.mean(t))

    def design(order):
        basis = _current_basis(t, order, tm, max(float(np.ptp(t)), 1.0))[0]
        cols = [(gi == k).astype(float) for k in range(G)]
        for b in basis:
            cols += [np.cos(heading) * b, np.sin(heading) * b]
        return np.column_stack(cols)

    def npar(order):
        return G + 2 * len(_current_basis(t[:1], order, tm, 1.0)[0])

    # the current's change with time: over a long day the steady stream plus the semidiurnal tide, else
    # the richest polynomial (quadratic: a tide's curvature over a few hours; linear; constant), the
    # first that leaves at least 3 legs over and is resolved by the legs
    models = (("tidal",) if np.ptp(t) >= 0.5 * CUR.TIDAL_PERIOD else ()) + (2, 1)
    order = next((k for k in models if n - npar(k) >= 3 and np.linalg.matrix_rank(design(k)) == npar(k)), 0)
    trend = order != 0
    p = npar(order)
    rank = int(np.linalg.matrix_rank(design(order)))
    if n > p and rank == p:
        track = heading if drift is None else heading + np.asarray(drift, dtype=float)
        f = _joint_current_fit(t, track, vg, vg_std, group, order)
        if ratio is not None:  # the log's relative readings, where they explain the legs better
            fr = _joint_current_fit(t, track, vg, vg_std, group, order, ratio=ratio)
            if (fr["tau"], fr["chi2"]) < (f["tau"], f["chi2"]):
                f = fr
        x, cov, dof, tau = f["x"], f["cov"], f["dof"], f["tau"]
        sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
        # the groups' speeds carry τ in full (normal quantile): τ stands for the ship's leg-to-leg scatter
        # and for what the current polynomial leaves; counting it only through the groups' departure from
        # their legs' plain mean (as for standardization spots) covered 0.915 over 84 campaign replicates
        U = {g: Estimate(float(x[k]), float(sd[k])) for k, g in enumerate(groups)}
        cur = {"north": Estimate(float(x[G]), float(sd[G])),
               "east": Estimate(float(x[G + 1]), float(sd[G + 1])), "trend": trend, "order": order,
               "t_ref": f["t_ref"]}
        terms = ((1, "cos"), (2, "sin")) if order == "tidal" else ((1, "rate"), (2, "accel"))
        for k, name in terms[:(p - G) // 2 - 1]:
            cur[f"north_{name}"] = Estimate(float(x[G + 2 * k]), float(sd[G + 2 * k]))
            cur[f"east_{name}"] = Estimate(float(x[G + 2 * k + 1]), float(sd[G + 2 * k + 1]))
        if order == "tidal":
            cur["tidal_period_s"] = CUR.TIDAL_PERIOD
        return groups, U, cur, {"dof": dof, "residuals": f["residuals"], "trend": trend, "order": order,
                                "ship_scatter": tau}, []
    if rank < p:
        axes = sorted({round(math.degrees(h) % 180.0, 1) for h in heading})
        why = (f"the legs lie on {'one axis' if len(axes) == 1 else 'too few axes'} "
               f"({', '.join(f'{a:g}°/{a + 180.0:g}°' for a in axes)}): the current across it cannot be "
               f"resolved (design rank {rank} < {p} unknowns)")
    else:
        why = (f"{n} legs for {p} unknowns (a speed per group and the current north and east): no "
               f"degree of freedom is left to estimate it and its uncertainty")
    under = [{"quantity": "current", "why": why}]
    U = {}
    for k, g in enumerate(groups):
        sel = gi == k
        hs = heading[sel]
        if sel.sum() == 2 and abs(abs(((hs[1] - hs[0] + math.pi) % (2 * math.pi)) - math.pi) - math.pi) < math.radians(5):
            U[g] = Estimate(float(np.mean(vg[sel])), 0.5 * float(np.hypot(*vg_std[sel])))
        elif sel.sum() == 4:
            try:
                fl = CUR.four_leg_current(*vg[sel], heading0=float(hs[0]), std=list(vg_std[sel]))
                U[g] = fl.u
            except ValueError:
                U[g] = None
        else:
            U[g] = None
        if U[g] is None:
            under.append({"quantity": f"speed through water of group {g}",
                          "why": f"{int(sel.sum())} legs that form neither a reciprocal pair nor a four-leg set, "
                                 f"and the current is not resolved"})
    return groups, U, {"under_determined": why, "trend": False, "t_ref": tm}, \
        {"dof": n - p, "residuals": None, "trend": False}, under


def reduce_record(rec: Record) -> dict:
    """Reduce a trial record by its kind."""
    kind = rec.attrs.get("kind")
    if kind == "standardization":
        return reduce_standardization(rec)
    if kind == "log_calibration":
        return reduce_log_calibration(rec)
    if kind == "maneuvering":
        from vtrials.reduce.maneuvering import reduce_maneuvering
        return reduce_maneuvering(rec)
    if kind == "airwake_survey":
        from vtrials.reduce.airwake_survey import reduce_airwake_survey
        return reduce_airwake_survey(rec)
    if kind == "seakeeping":
        from vtrials.reduce.seakeeping import reduce_seakeeping
        return reduce_seakeeping(rec)
    raise ValueError(f"{rec.path}: no reduction for trial kind {kind!r}")
