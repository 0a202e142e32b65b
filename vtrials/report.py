"""The trial report: Markdown with PNG figures, written next to results.json.

Per trial: a summary of the scores, the figures (speed–power reduced vs true; current estimates vs
truth over time; log calibration regression with its band and the true line) and per-run tables.
Every number shown is also in results.json.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .records import atomic_path
from .units import KNOT

KW = 1e-3


def _fig():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, path: Path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", format="png")
    _fig().close(fig)


def _fmt(x, nd=2):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{nd}f}"


def _clock(t: float) -> str:
    s = int(round(t))
    return f"{s // 3600:02d}:{s % 3600 // 60:02d}:{s % 60:02d}"


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
        from .reduce.trials import curve_power
        vv = np.linspace(*red["curve"]["speed_range"], 100)
        a1.plot(vv / KNOT, curve_power(red["curve"], vv) * KW, "C0--", lw=1, label="fitted curve")
    a1.set_xlabel("speed through water [kn]")
    a1.set_ylabel("delivered power [kW]")
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
    _save(fig, out / f)
    files.append(f)
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
    _save(fig, out / f)
    files.append(f)
    return files


def _std_markdown(tr: dict, figs: list[str]) -> list[str]:
    red, err = tr["reduced"], tr["error"]
    sm = err["summary"]
    L = [f"## {tr['name']} (standardization)", "",
         f"Tracking: `{red['tracking']}`. Spots: {sm['spots']}. Largest speed error {_fmt(sm['max_abs_stw_error_kn'], 3)} kn; "
         f"95 % intervals cover the true speed in {_fmt(100 * sm['stw_coverage'] if sm['stw_coverage'] is not None else None, 0)} % "
         f"of spots; fitted curve within {_fmt(100 * sm['max_abs_curve_error'] if sm['max_abs_curve_error'] is not None else None, 2)} % "
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
        _save(fig, out / f)
        files.append(f)
    fig, ax = plt.subplots(figsize=(9, 3.4))
    t = np.array([leg["t_mid"] for leg in red["legs"]]) / 3600
    ax.plot(t, [c["truth"][0] / KNOT for c in err["current"]], "k.-", label="true current north")
    ax.plot(t, [c["truth"][1] / KNOT for c in err["current"]], "k.--", label="true current east")
    ax.plot(t, [c["reduced"][0] / KNOT for c in err["current"]], "C0o", label="reduced north")
    ax.plot(t, [c["reduced"][1] / KNOT for c in err["current"]], "C1s", label="reduced east")
    ax.set_xlabel("time of day [h]")
    ax.set_ylabel("current [kn]")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(alpha=0.3)
    f = f"{tr['name']}_current.png"
    _save(fig, out / f)
    files.append(f)
    return files


def _lc_markdown(tr: dict, figs: list[str]) -> list[str]:
    red, err = tr["reduced"], tr["error"]
    sm = err["summary"]
    L = [f"## {tr['name']} (speed-log calibration)", "",
         f"Tracking: `{red['tracking']}`. Legs: {sm['legs']}. Largest speed-through-water error "
         f"{_fmt(sm['max_abs_stw_error_kn'], 3)} kn; 95 % intervals cover the truth on "
         f"{_fmt(100 * sm['stw_coverage'] if sm['stw_coverage'] is not None else None, 0)} % of legs; current error ≤ "
         f"{_fmt(sm['max_current_error_kn'], 3)} kn.", ""]
    L += [f"![{f}]({f})" for f in figs] + [""]
    for inst, cal in red["calibrations"].items():
        if "error" in cal:
            L += [f"{inst}: {cal['error']}", ""]
            continue
        e = err["calibrations"].get(inst)
        L += [f"**{inst}**: STW = {_fmt(cal['intercept']['value'] / KNOT, 3)} kn (± {_fmt(cal['intercept']['std'] / KNOT, 3)}) + "
              f"{_fmt(cal['slope']['value'], 4)} (± {_fmt(cal['slope']['std'], 4)}) × reading; r² = {cal['r2']:.5f}, "
              f"SEE = {_fmt(cal['see'] / KNOT, 3)} kn, n = {cal['n']}"
              + (f"; true: {_fmt(e['true_line']['intercept_mps'] / KNOT, 3)} kn + {_fmt(e['true_line']['slope'], 4)} × reading "
                 f"(intercept covered: {e['intercept']['covered']}, slope covered: {e['slope']['covered']})" if e else ""), ""]
    L += ["| run | group | course | V_G [kn] | STW [kn] | ± (95 %) | true STW [kn] | err [kn] | covered |",
          "|---|---|---|---|---|---|---|---|---|"]
    for leg, e in zip(red["legs"], err["legs"]):
        L.append(f"| {leg['run']} | {leg['group']} | {math.degrees(leg['course']) % 360:.0f}° | {_fmt(leg['vg']['value'] / KNOT, 3)} | "
                 f"{_fmt(leg['stw']['value'] / KNOT, 3)} | {_fmt((leg['stw']['hi95'] - leg['stw']['value']) / KNOT, 3)} | "
                 f"{_fmt(e['stw']['truth'] / KNOT, 3)} | {_fmt(e['stw_error_kn'], 3)} | {e['stw']['covered']} |")
    return L + [""]


# ----------------------------------------------------------------------------------- the document
def write_report(doc: dict, res, out: Path) -> None:
    """report.md and its figures for an agenda run (``doc`` is results.json's content)."""
    L = [f"# {doc['scenario']}", "",
         f"Ship `{doc['ship']}` · seed {doc['seed']} · time step {doc['timestep_s']} s · trial time "
         f"{doc['agenda']['total_time_s'] / 3600:.2f} h · wall time {doc['wall_time_s']:.1f} s", "",
         "## Agenda", "", "| run | trial | label | course | COMEX | FINEX | run time [min] | steady | accepted |",
         "|---|---|---|---|---|---|---|---|---|"]
    for a in doc["agenda"]["runs"]:
        L.append(f"| {a['run']}{'' if a['attempt'] == 1 else ' (repeat)'} | {a['trial']} | {a['label']} | "
                 f"{a['course_deg']:.0f}° | {_clock(a['t_comex'])} | {_clock(a['t_finex'])} | {a['elapsed_s'] / 60:.1f} | "
                 f"{a['approach_steady'] and a['run_steady']} | {a['accepted']} |")
    L += ["", "Elapsed trial time per trial: " + ", ".join(f"{k} {v / 3600:.2f} h" for k, v in
                                                            doc["agenda"]["trial_time_s"].items()), ""]
    for tr in doc["trials"]:
        if tr["kind"] == "standardization":
            figs = _std_figures(tr, out)
            L += _std_markdown(tr, figs)
        elif tr["kind"] == "log_calibration":
            figs = _lc_figures(tr, out)
            L += _lc_markdown(tr, figs)
    with atomic_path(out / "report.md") as tmp:
        tmp.write_text("\n".join(L) + "\n")
