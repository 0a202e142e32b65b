"""The trial report: Markdown with PNG figures, written next to results.json.

Per trial: a summary of the scores, the figures (speed–power reduced vs true; current estimates vs
truth over time; log calibration regression with its band and the true line) and per-run tables.
Every number shown is also in results.json.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from vtrials.trials.crew import _clock
from vtrials.records.netcdf import atomic_path
from vtrials.units import KNOT

KW = 1e-3


def _fig():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, out: Path, name: str) -> str:
    """Write a figure atomically as out/name and close it; returns the name for the report."""
    with atomic_path(out / name) as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", format="png")
    _fig().close(fig)
    return name


def _pct(x):
    """A fraction as percent (None stays None)."""
    return None if x is None else 100 * x


def _fmt(x, nd=2):
    if isinstance(x, dict):  # an Estimate
        x = x.get("value")
    if x is None or isinstance(x, str) or (isinstance(x, float) and not math.isfinite(x)):
        return "–" if x is None or not isinstance(x, str) else x
    return f"{x:.{nd}f}"


# ----------------------------------------------------------------------------------- standardization
def _std_figures(tr: dict, out: Path) -> list[str]:
    plt = _fig()
    red, err = tr["reduced"], tr["error"]
    name = tr["name"]
    files = []
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    calm = sorted(err["curve"]["true_points"] if err.get("curve") else [], key=lambda p: p["stw"])
    if calm:
        a1.plot([p["stw"] / KNOT for p in calm], [p["power"] * KW for p in calm], "k-", lw=1.2,
                label="true calm-water curve")
    V = np.array([s["stw"]["value"] for s in red["spots"]])
    P = np.array([s["power"]["value"] for s in red["spots"]])
    Pe = np.array([s["power"]["std"] for s in red["spots"]])
    Ve = np.array([s["stw"]["std"] for s in red["spots"]])
    Pm = np.array([s["power_measured"]["value"] for s in red["spots"]])
    a1.errorbar(V / KNOT, P * KW, xerr=1.96 * Ve / KNOT, yerr=1.96 * Pe * KW, fmt="o", ms=4, color="C0",
                label="reduced spots (wind-corrected, 95 %)")
    a1.plot(V / KNOT, Pm * KW, "x", color="C3", label="measured power (uncorrected)")
    if red.get("curve"):
        from vtrials.reduce.trials import curve_power
        vv = np.linspace(*red["curve"]["speed_range"], 100)
        a1.plot(vv / KNOT, curve_power(red["curve"], vv) * KW, "C0--", lw=1, label="fitted curve")
    a1.set_xlabel("speed through water [kn]")
    a1.set_ylabel("shaft power at the torsionmeters [kW]")
    a1.set_title(f"{name}: speed–power")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    if err.get("curve"):
        a2.plot(np.array(err["curve"]["speed"]) / KNOT, 100 * np.array(err["curve"]["rel_error"]), "C0-",
                label="fitted curve")
    sp = [s for s in err["spots"] if s.get("power_at_equal_speed") and s["power_at_equal_speed"]["error"] is not None]
    a2.plot([s["stw"]["reduced"] / KNOT for s in sp], [100 * s["power_at_equal_speed"]["error"] for s in sp], "o",
            color="C1", label="spots")
    a2.axhspan(-1, 1, color="0.9", zorder=0, label="±1 %")
    a2.set_xlabel("speed through water [kn]")
    a2.set_ylabel("power error at equal speed [%]")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3)
    f = f"{name}_speed_power.png"
    files.append(_save(fig, out, f))
    # current along the base course: reduced (per run, from the elimination) vs truth, over time
    fig, ax = plt.subplots(figsize=(9, 3.4))
    runs = {r["run"]: r for r in red["runs"]}
    for s, e in zip(red["spots"], err["spots"]):
        tt = [runs[k]["t_mid"] / 3600 for k in s["runs"]]
        ax.plot(tt, np.array(e["current_along_base"]["truth"]) / KNOT, "k.-", lw=0.8)
        ax.plot(tt, np.array(e["current_along_base"]["reduced"]) / KNOT, "C0o", ms=4)
    ax.plot([], [], "k.-", label="true current along the spot's first course")
    ax.plot([], [], "C0o", label="implied by the current elimination")
    ax.set_xlabel("time of day [h]")
    ax.set_ylabel("current [kn]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    f = f"{name}_current.png"
    files.append(_save(fig, out, f))
    return files


def _std_markdown(tr: dict, figs: list[str]) -> list[str]:
    red, err = tr["reduced"], tr["error"]
    sm = err["summary"]
    L = [f"## {tr['name']} (standardization)", "",
         f"Tracking: `{red['tracking']}`. Spots: {sm['spots']}. Largest speed error {_fmt(sm['max_abs_stw_error_kn'], 3)} kn; "
         f"95 % intervals cover the true speed in {_fmt(_pct(sm['stw_coverage']), 0)} % "
         f"of spots; fitted curve within {_fmt(_pct(sm['max_abs_curve_error']), 2)} % "
         f"of the true calm-water power at equal speed.", ""]
    L += [f"![speed-power]({figs[0]})", "", f"![current]({figs[1]})", ""]
    L += ["| spot | runs | method | V_S [kn] | ± (95 %) | true [kn] | err [kn] | covered | P_corr [kW] | P_meas [kW] | "
          "power err at equal V [%] |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for s, e in zip(red["spots"], err["spots"]):
        pe = e.get("power_at_equal_speed", {}).get("error")
        L.append(f"| {s['group']} | {','.join(map(str, s['runs']))} | {s['method']} | {_fmt(s['stw']['value'] / KNOT, 3)} | "
                 f"{_fmt(1.96 * s['stw']['std'] / KNOT, 3)} | {_fmt(e['stw']['truth'] / KNOT, 3)} | {_fmt(e['stw_error_kn'], 3)} | "
                 f"{e['stw']['covered']} | {_fmt(s['power']['value'] * KW, 1)} | {_fmt(s['power_measured']['value'] * KW, 1)} | "
                 f"{_fmt(None if pe is None else 100 * pe, 2)} |")
    L += ["", "Per run (window EXECUTE–FINEX):", "",
          "| run | label | course | SOG [kn] | true SOG [kn] | power [kW] | true power [kW] | r/min | rel. wind [kn] | steady |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for r, e in zip(red["runs"], err["runs"]):
        rpm = [s["rps"]["mean"] * 60 for s in r["shafts"].values() if s.get("rps")]
        L.append(f"| {r['run']} | {r['label']} | {math.degrees(r['course']) % 360:.0f}° | {_fmt(r['vg']['value'] / KNOT, 3)} | "
                 f"{_fmt(e['sog']['truth'] / KNOT, 3)} | {_fmt(r['power']['value'] * KW if r['power'] else None, 1)} | "
                 f"{_fmt(e['power_measured']['truth'] * KW, 1)} | {' / '.join(f'{x:.1f}' for x in rpm)} | "
                 f"{_fmt(r['wind']['speed'] / KNOT if r.get('wind') else None, 1)} | {r['steady']} |")
    return L + [""]


# ----------------------------------------------------------------------------------- log calibration
def _lc_figures(tr: dict, out: Path) -> list[str]:
    plt = _fig()
    red, err = tr["reduced"], tr["error"]
    files = []
    for inst, cal in red["calibrations"].items():
        if "error" in cal:
            continue
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        x = np.array(cal["x"])
        y = np.array(cal["y"])
        ax.errorbar(x / KNOT, y / KNOT, yerr=1.96 * np.array(cal["y_std"]) / KNOT, fmt="o", label="reduced STW per speed")
        bx = np.array(cal["band_x"])
        line = cal["intercept"]["value"] + cal["slope"]["value"] * bx
        ax.plot(bx / KNOT, line / KNOT, "C0-", label="regression")
        if cal.get("band_lo") is not None:
            ax.fill_between(bx / KNOT, np.array(cal["band_lo"]) / KNOT, np.array(cal["band_hi"]) / KNOT, color="C0",
                            alpha=0.2, label="95 % confidence band")
        tl = err["calibrations"].get(inst, {}).get("true_line")
        if tl:
            ax.plot(bx / KNOT, (tl["intercept_mps"] + tl["slope"] * bx) / KNOT, "k--", label="true calibration")
        ax.plot(bx / KNOT, bx / KNOT, ":", color="0.5", label="log = STW")
        ax.set_xlabel(f"{inst} reading [kn]")
        ax.set_ylabel("speed through water [kn]")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        f = f"{tr['name']}_{inst}_calibration.png"
        files.append(_save(fig, out, f))
    fig, ax = plt.subplots(figsize=(9, 3.4))
    t = np.array([leg["t_mid"] for leg in red["legs"]]) / 3600
    if not err["current"]:  # the current was under-determined: the truth alone
        ax.plot(t, [leg["true_current"][0] / KNOT for leg in err["legs"]], "k.-", label="true current north")
        ax.plot(t, [leg["true_current"][1] / KNOT for leg in err["legs"]], "k.--", label="true current east")
        t = t[:0]
    ax.plot(t, [c["truth"][0] / KNOT for c in err["current"]], "k.-", label="true current north")
    ax.plot(t, [c["truth"][1] / KNOT for c in err["current"]], "k.--", label="true current east")
    ax.plot(t, [c["reduced"][0] / KNOT for c in err["current"]], "C0o", label="reduced north")
    ax.plot(t, [c["reduced"][1] / KNOT for c in err["current"]], "C1s", label="reduced east")
    ax.set_xlabel("time of day [h]")
    ax.set_ylabel("current [kn]")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(alpha=0.3)
    f = f"{tr['name']}_current.png"
    files.append(_save(fig, out, f))
    return files


def _lc_markdown(tr: dict, figs: list[str]) -> list[str]:
    red, err = tr["reduced"], tr["error"]
    sm = err["summary"]
    L = [f"## {tr['name']} (speed-log calibration)", "",
         f"Tracking: `{red['tracking']}`. Legs: {sm['legs']}. Largest speed-through-water error "
         f"{_fmt(sm['max_abs_stw_error_kn'], 3)} kn; 95 % intervals cover the truth on "
         f"{_fmt(_pct(sm['stw_coverage']), 0)} % of legs; current error ≤ "
         f"{_fmt(sm['max_current_error_kn'], 3)} kn."
         + (f" Drift angle of the water track: {red['drift_angle']['source']}." if "drift_angle" in red else ""), ""]
    for u in red.get("under_determined", []):
        L += [f"**Not reduced — {u['quantity']} is under-determined**: {u['why']}.", ""]
    L += [f"![{f}]({f})" for f in figs] + [""]
    for inst, cal in red["calibrations"].items():
        if "error" in cal:
            L += [f"{inst}: {cal['error']}", ""]
            continue
        e = err["calibrations"].get(inst)
        L += [f"**{inst}**: STW = {_fmt(cal['intercept']['value'] / KNOT, 3)} kn (± {_fmt(cal['intercept']['std'] / KNOT, 3)}) + "
              f"{_fmt(cal['slope']['value'], 4)} (± {_fmt(cal['slope']['std'], 4)}) × reading; r² = {_fmt(cal['r2'], 5)}, "
              + (f"SEE = {_fmt(cal['see'] / KNOT, 3)} kn (legs' ground-speed residuals of the joint fit), scatter "
                 f"beyond the tracking σ τ = {_fmt(cal['scatter_tau'] / KNOT, 3)} kn, {cal['n']} legs with readings, "
                 f"dof {cal['dof']}" if "scatter_tau" in cal else
                 f"SEE = {_fmt(cal['see'] / KNOT, 3)} kn (residual RMS), reduced χ² = {_fmt(cal.get('chi2_red'), 2)}, "
                 f"n = {cal['n']}")
              + (f"; true: {_fmt(e['true_line']['intercept_mps'] / KNOT, 3)} kn + {_fmt(e['true_line']['slope'], 4)} × reading "
                 f"(intercept covered: {e['intercept']['covered']}, slope covered: {e['slope']['covered']})" if e else ""), ""]
    L += ["| run | group | course | V_G [kn] | STW [kn] | ± (95 %) | true STW [kn] | err [kn] | covered |",
          "|---|---|---|---|---|---|---|---|---|"]
    for leg, e in zip(red["legs"], err["legs"]):
        L.append(f"| {leg['run']} | {leg['group']} | {math.degrees(leg['course']) % 360:.0f}° | {_fmt(leg['vg']['value'] / KNOT, 3)} | "
                 f"{_fmt(leg['stw']['value'] / KNOT, 3)} | {_fmt((leg['stw']['hi95'] - leg['stw']['value']) / KNOT, 3)} | "
                 f"{_fmt(e['stw']['truth'] / KNOT, 3)} | {_fmt(e['stw_error_kn'], 3)} | {e['stw']['covered']} |")
    return L + [""]


# ----------------------------------------------------------------------------------- maneuvering
def _truth_cols(res):
    crew = res.crew
    rows = np.concatenate(crew.truth_rows, axis=0)
    return crew.columns(rows)


def _mv_figures(tr: dict, res, out: Path) -> list[str]:
    plt = _fig()
    red, err = tr["reduced"], tr["error"]
    name = tr["name"]
    files = []
    cols = _truth_cols(res)
    tt = cols["t"]
    runs = red["runs"]
    turns = [r for r in runs if r["type"] == "turn" and r.get("advance")]
    ch = None
    if turns or any(r["type"] == "zigzag" and "error" not in r for r in runs):
        from vtrials.records.netcdf import open_record
        from vtrials.reduce.maneuvering import Channels
        ch = Channels(open_record(out / tr["record"]))  # read once for the turn and zig-zag pages
    if turns:
        n = len(turns)
        nc = min(6, n)
        nr = int(math.ceil(n / nc))
        fig, axes = plt.subplots(nr, nc, figsize=(2.6 * nc, 2.6 * nr), squeeze=False)
        for ax, r in zip(axes.ravel(), turns):
            te = r["t_execute"]
            w = ch.window(te, r["t_finex"])
            dn = r["drift"]["north"]["value"] if r.get("drift") else 0.0
            de = r["drift"]["east"]["value"] if r.get("drift") else 0.0
            psi0 = r["approach_course"]["value"]
            c, s_ = math.cos(psi0), math.sin(psi0)
            n0 = np.interp(te, w["t"], w["north"]) if w["t"].size else 0.0
            e0 = np.interp(te, w["t"], w["east"]) if w["t"].size else 0.0
            nn = w["north"] - dn * (w["t"] - te) - n0
            ee = w["east"] - de * (w["t"] - te) - e0
            ax.plot(-nn * s_ + ee * c, nn * c + ee * s_, "C0-", lw=1, label="reduced (drift-corrected)")
            m = (tt >= te) & (tt <= r["t_finex"])
            xw, yw = cols["x_w"][m] - np.interp(te, tt, cols["x_w"]), cols["y_w"][m] - np.interp(te, tt, cols["y_w"])
            ax.plot(-xw * s_ + yw * c, xw * c + yw * s_, "k--", lw=0.8, label="true track through the water")
            side = 1 if r["turn_side"] > 0 else -1
            ax.plot([side * r["transfer"]["value"]], [r["advance"]["value"]], "C1o", ms=4)
            if r.get("tactical_diameter"):
                ax.axvline(side * r["tactical_diameter"]["value"], color="C1", lw=0.6, ls=":")
            ax.set_aspect("equal")
            ax.set_title(r["label"], fontsize=8)
            ax.tick_params(labelsize=6)
        for ax in axes.ravel()[n:]:
            ax.axis("off")
        axes[0, 0].legend(fontsize=6)
        fig.suptitle(f"{name}: drift-corrected turning tracks (across / along the approach course, m); "
                     f"dot: advance & transfer, dotted: tactical diameter", fontsize=9)
        f = f"{name}_turns.png"
        files.append(_save(fig, out, f))
        # rate of turn against rudder, reduced vs true
        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        truth = {x["run"]: x for x in tr["truth"]["runs"] if x}
        for k, r in enumerate(turns):
            rd = r["rudder_steady"]["value"] if r.get("rudder_steady") else r["rudder_ordered"]
            rt = r["steady_rate"]
            ax.errorbar(math.degrees(rd), math.degrees(rt["value"]), yerr=1.96 * math.degrees(rt["std"]), fmt="o",
                        color="C0", ms=4, label="reduced" if k == 0 else None)
            t_ = truth.get(r["run"], {})
            if t_.get("steady_rate_of_turn_dps") is not None:
                ax.plot(t_.get("rudder_deg", math.degrees(rd)), math.copysign(t_["steady_rate_of_turn_dps"], rd), "kx",
                        label="true" if k == 0 else None)
        ax.set_xlabel("rudder [deg]")
        ax.set_ylabel("steady rate of turn [deg/s]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        f = f"{name}_rate_vs_rudder.png"
        files.append(_save(fig, out, f))
    sc = [r for r in runs if r["type"] == "speed_change" and r.get("curve")]
    if sc:
        fig, axes = plt.subplots(1, len(sc), figsize=(4.2 * len(sc), 3.4), squeeze=False)
        for ax, r in zip(axes[0], sc):
            cv = r["curve"]
            te = r["t_execute"]
            ax.plot(np.array(cv["t"]) - te, np.array(cv["speed"]) / KNOT, "C0-", label="reduced (fit)")
            m = (tt >= te - 60) & (tt <= r["t_finex"])
            ax.plot(tt[m] - te, np.sign(cols["u_r"][m]) * np.hypot(cols["u_r"][m], cols["v_r"][m]) / KNOT, "k--", lw=0.8,
                    label="true speed through water")
            if r.get("time_to_dead_in_water"):
                ax.axvline(r["time_to_dead_in_water"]["value"], color="C1", lw=0.8, label="reduced time to DIW")
            ax.axhline(0, color="0.6", lw=0.5)
            ax.set_title(r["label"], fontsize=8)
            ax.set_xlabel("time after EXECUTE [s]")
            ax.set_ylabel("speed [kn]")
            ax.grid(alpha=0.3)
        axes[0, 0].legend(fontsize=7)
        f = f"{name}_reach.png"
        files.append(_save(fig, out, f))
    zz = [r for r in runs if r["type"] == "zigzag" and "error" not in r]
    if zz:
        fig, axes = plt.subplots(len(zz), 1, figsize=(9, 2.6 * len(zz)), squeeze=False)
        for ax, r in zip(axes[:, 0], zz):
            te = r["t_execute"]
            w = ch.window(te - 30, r["t_finex"])
            psi0 = r["approach_heading"]["value"] if isinstance(r.get("approach_heading"), dict) else w["heading"][0]
            ax.plot(w["t_heading"] - te, np.degrees(w["heading"] - psi0), "C0-", lw=1, label="gyro heading − approach")
            ax.plot(w["t_rudder"] - te, np.degrees(w["rudder"]), "C1-", lw=0.8, label="rudder synchro")
            m = (tt >= te - 30) & (tt <= r["t_finex"])
            ax.plot(tt[m] - te, np.degrees(cols["heading"][m] - np.interp(te, tt, cols["heading"])), "k--", lw=0.7,
                    label="true heading change")
            ax.set_title(r["label"], fontsize=8)
            ax.grid(alpha=0.3)
            ax.set_ylabel("deg")
        axes[-1, 0].set_xlabel("time after EXECUTE [s]")
        axes[0, 0].legend(fontsize=7, ncol=3)
        f = f"{name}_zigzag.png"
        files.append(_save(fig, out, f))
    sp = [r for r in runs if r["type"] in ("direct_spiral", "reverse_spiral") and r.get("points")]
    if sp:
        fig, axes = plt.subplots(1, len(sp), figsize=(5.5 * len(sp), 4.2), squeeze=False)
        for ax, r in zip(axes[0], sp):
            st = res.calm_water.get(f"spiral_run_{r['run']}")
            if st:
                ax.plot(np.degrees(st["curve"]["delta"]), np.degrees(st["curve"]["r"]), "k-", lw=1,
                        label="true steady turns (model equations)")
            for q in r["points"]:
                ok = q.get("steady", True)
                ax.errorbar(math.degrees(q["rudder"]["value"]), math.degrees(q["rate"]["value"]),
                            xerr=1.96 * math.degrees(q["rudder"]["std"]), yerr=1.96 * math.degrees(q["rate"]["std"]),
                            fmt="o" if ok else "x", color="C0" if ok else "C3", ms=4)
            ax.axhline(0, color="0.7", lw=0.5)
            ax.axvline(0, color="0.7", lw=0.5)
            dd = [math.degrees(q["rudder"]["value"]) for q in r["points"]]
            rr = [math.degrees(q["rate"]["value"]) for q in r["points"]]
            pad = 0.15 * (max(dd) - min(dd)) + 0.2
            ax.set_xlim(min(dd) - pad, max(dd) + pad)  # the data's range: a narrow loop stays visible
            ax.set_ylim(min(rr) - 0.1 * abs(min(rr)) - 0.01, max(rr) + 0.1 * abs(max(rr)) + 0.01)
            ax.set_xlabel("rudder [deg]")
            ax.set_ylabel("rate of turn [deg/s]")
            ax.set_title(f"{r['label']} (x: never steady)", fontsize=8)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        f = f"{name}_spiral.png"
        files.append(_save(fig, out, f))
    return files


def _mv_markdown(tr: dict, figs: list[str]) -> list[str]:
    red, err = tr["reduced"], tr["error"]
    sm = err["summary"]
    L = [f"## {tr['name']} (maneuvering)", "",
         f"Tracking: `{red['tracking']}`. Runs: {sm['runs']}. Advance / tactical diameter: largest error "
         f"{_fmt(100 * sm['max_rel_error_advance_tactical'], 2)} %, intervals cover "
         f"{_fmt(_pct(sm['advance_tactical_coverage']), 0)} %; "
         f"stopping time / reach: largest error {_fmt(100 * sm['max_rel_error_stop_time_reach'], 2)} %; "
         f"overshoots: largest error {_fmt(sm['max_abs_overshoot_error_deg'], 3)}°.", ""]
    L += [f"![{f}]({f})" for f in figs] + [""]
    rows = ["| run | maneuver | quantity | reduced | ± (95 %) | true | error | covered |", "|---|---|---|---|---|---|---|---|"]
    unit = {"advance": ("m", 1), "transfer": ("m", 1), "tactical_diameter": ("m", 1), "steady_diameter": ("m", 1),
            "steady_speed": ("kn", 1 / KNOT), "steady_rate": ("°/s", 180 / math.pi), "heel_max": ("°", 180 / math.pi),
            "approach_speed": ("kn", 1 / KNOT), "time_to_dead_in_water": ("s", 1), "track_reach": ("m", 1),
            "head_reach": ("m", 1), "lateral_deviation": ("m", 1), "terminal_speed": ("kn", 1 / KNOT),
            "time_to_terminal_speed": ("s", 1), "time_to_90_percent": ("s", 1), "first_overshoot": ("°", 180 / math.pi),
            "second_overshoot": ("°", 180 / math.pi), "initial_turning_time": ("s", 1), "time_to_check_yaw": ("s", 1),
            "period": ("s", 1), "period_heading": ("s", 1)}
    for r in err["runs"]:
        for k, c in r.items():
            if not isinstance(c, dict) or "truth" not in c or k not in unit or c.get("reduced") is None:
                continue
            u, f = unit[k]
            rows.append(f"| {r['run']} | {r['label']} | {k} [{u}] | {_fmt(c['reduced'] * f, 2)} | "
                        f"{_fmt(1.96 * c['std'] * f if c.get('std') is not None else None, 2)} | {_fmt(c['truth'] * f, 2)} | "
                        f"{_fmt(c['error'] * f, 2)} | {c['covered']} |")
        if "loop" in r:
            lp = r["loop"]
            rw = lp.get("reduced_width")
            rwv = rw.get("value") if isinstance(rw, dict) else None
            tw = lp.get("true_width")
            rows.append(f"| {r['run']} | {r['label']} | loop width [°] | "
                        f"{_fmt(math.degrees(rwv) if rwv is not None else None, 2)} | | "
                        f"{_fmt(math.degrees(tw) if tw is not None else None, 2)} | | "
                        f"{lp.get('width', {}).get('covered')} |")
    L += rows + [""]
    imo = red.get("imo") or {}
    if imo.get("verdicts"):
        L += [f"IMO MSC.137(76) (L = {imo['length_m']:.1f} m, V = {imo['speed_mps'] / KNOT:.2f} kn):", "",
              "| criterion | value | limit | passed | margin | true value | true verdict |", "|---|---|---|---|---|---|---|"]
        L += imo_rows(imo["verdicts"], tr["truth"].get("imo") or {})
        L.append("")
    return L


def _pc(x) -> str:
    return "n/a" if x is None else f"{100 * x:.1f} %"


def _aw_markdown(tr: dict) -> list[str]:
    """Airwake survey: per recording the relative wind, the airwake ratio (mast / reference) against
    truth, the true motion-induced velocity and what AWSM left of it, and the mean change."""
    s = tr["error"]["summary"]
    L = [f"## {tr['name']} (airwake survey)", "",
         f"Motion-induced velocity left after AWSM (max over recordings): {_pc(s['max_residual_fraction_awsm'])} "
         f"(the seed's order, body-axis mean removed then rotated: "
         f"{_pc(s['max_residual_fraction_awsm_seed_order'])}); acceptance < 10 %: {s['residual_accepted']}. "
         f"Mean airwake unchanged by the correction within its 95 % interval: {s['mean_unchanged_all']} "
         f"(largest change {s['max_abs_mean_change']:.3f} m/s; indistinguishable from zero by its own interval in "
         f"{_pc(s['mean_change_indistinguishable_from_zero'])} of the components). "
         f"Coverage of the 95 % intervals (mean components, ratios): {_pc(s['coverage'])}.", "",
         "| run | position | wind ordered | ratio K (95 %) | true K | motion-induced RMS [m/s] | left by AWSM | "
         "mean change u, v, w [m/s] |", "|---|---|---|---|---|---|---|---|"]
    red = {r["run"]: r for r in tr["reduced"]["runs"]}
    for e in tr["error"]["runs"]:
        r = red.get(e["run"], {})
        if "reduction_error" in e or "airwake_ratio" not in e:
            L.append(f"| {e['run']} | {e['position']} | | {e.get('reduction_error', '')} | | | | |")
            continue
        k = r["airwake_ratio"]["speed_ratio"]
        w = r["relative_wind_speed_ordered"]
        wind = f"{math.degrees(r['relative_wind_ordered']):.0f}°" + ("" if w is None else f" {w / KNOT:.0f} kn")
        ch = ", ".join(f"{c['change']:+.3f}" for c in e["mean_change"])
        L.append(f"| {e['run']} | {e['position']} | {wind} | {k['value']:.3f} ({k['lo95']:.3f}–{k['hi95']:.3f}) | "
                 f"{e['airwake_ratio']['truth']:.3f} | {e['true_motion_induced_rms']:.2f} | "
                 f"{_pc(e['residual_fraction_awsm'])} | {ch} |")
    return L + [""]


def imo_rows(verdicts: dict, truth: dict) -> list[str]:
    """Markdown rows of the IMO verdict table; angles (kept in rad inside) are printed in degrees,
    the unit the MSC.137(76) criteria are written in, and every value carries its unit."""
    rows = []
    for k, v in verdicts.items():
        if not isinstance(v, dict) or "limit" not in v:
            continue
        tv = truth.get(k, {}) if isinstance(truth, dict) else {}
        f, unit = (180.0 / math.pi, "°") if v.get("unit") == "rad" else (1.0, f" {v.get('unit')}" if v.get("unit") else "")

        def num(x):
            x = x.get("value") if isinstance(x, dict) else x
            return None if x is None else x * f

        def show(x):
            x = num(x)
            return "–" if x is None else f"{_fmt(x, 2)}{unit}"
        rows.append(f"| {v['criterion']} | {show(v['value'])} | {show(v['limit'])} | {v['passed']} | "
                    f"{show(v.get('margin'))} | {show(tv.get('value'))} | {tv.get('passed')} |")
    return rows


def unsteady_reasons(attempt: dict) -> str:
    """Why the director found an attempt unsteady (empty when steady): the approach's and the run's
    reasons from the log sheet, each once, so the reader sees why each repeat happened."""
    if attempt.get("approach_steady") and attempt.get("run_steady"):
        return ""
    parts = []
    for key, where in (("approach_notes", "approach"), ("run_notes", "run")):
        for n in dict.fromkeys(attempt.get(key) or []):
            parts.append(f"{where}: {n}")
    return "; ".join(parts).replace("|", "/") or "unsteady"


# ----------------------------------------------------------------------------------- the document
def write_report(doc: dict, res, out: Path) -> None:
    """report.md and its figures for an agenda run (``doc`` is results.json's content)."""
    L = [f"# {doc['scenario']}", "",
         f"Ship `{doc['ship']}` · seed {doc['seed']} · time step {doc['timestep_s']} s · trial time "
         f"{doc['agenda']['total_time_s'] / 3600:.2f} h · wall time {doc['wall_time_s']:.1f} s", "",
         "## Agenda", "", "| run | trial | label | course | COMEX | FINEX | run time [min] | steady | accepted | "
         "why unsteady (the director's judgement) |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    for a in doc["agenda"]["runs"]:
        L.append(f"| {a['run']}{'' if a['attempt'] == 1 else ' (repeat)'} | {a['trial']} | {a['label']} | "
                 f"{a['course_deg']:.0f}° | {_clock(a['t_comex'])} | {_clock(a['t_finex'])} | {a['elapsed_s'] / 60:.1f} | "
                 f"{a['approach_steady'] and a['run_steady']} | {a['accepted']} | {unsteady_reasons(a)} |")
    L += ["", "Elapsed trial time per trial: " + ", ".join(f"{k} {v / 3600:.2f} h" for k, v in
                                                            doc["agenda"]["trial_time_s"].items()), ""]
    for tr in doc["trials"]:
        if tr["kind"] == "standardization":
            figs = _std_figures(tr, out)
            L += _std_markdown(tr, figs)
        elif tr["kind"] == "log_calibration":
            figs = _lc_figures(tr, out)
            L += _lc_markdown(tr, figs)
        elif tr["kind"] == "maneuvering":
            figs = _mv_figures(tr, res, out)
            L += _mv_markdown(tr, figs)
        elif tr["kind"] == "seakeeping":
            from vtrials.report import seakeeping_report as SKR
            L += SKR.markdown(tr, SKR.figures(tr, out))
        elif tr["kind"] == "airwake_survey":
            L += _aw_markdown(tr)
    with atomic_path(out / "report.md") as tmp:
        tmp.write_text("\n".join(L) + "\n")
