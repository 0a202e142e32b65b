"""Study: Insel (2008) — the error budget of a speed/power trial, one source at a time.

Published (M. Insel, "Uncertainty in the analysis of speed and powering trials", Ocean Engineering 35
(2008) 1183–1193, abstract): Monte Carlo simulation of the ITTC trial analysis for 12 sister ships;
precision errors were the most influential error source over the whole speed range, more so at low
speeds; the Beaufort number (wind) was the most important elementary error source.

Here (vtrials): the patrol vessel's standardization trial at three spots (low, middle, top), one double run
each, as three campaigns that share their campaign seed (so replicate i has the same scenario seed —
instrument draws, noise, gusts' seed — in all three: common random numbers):

    precision   calm water, no wind, no current (scenarios/studies/patrol51_insel_precision.toml)
    wind        + wind of Beaufort 0–6, speed uniform 0–27 kn, direction uniform (…_insel_wind.toml)
    current     + semidiurnal tidal stream 0–1 kn, axis and phase uniform (…_insel_current.toml)

Every replicate is reduced from its records by the operational reduction (reduce_standardization: spot
speed by the mean of means with the two-run trend correction, wind by the direct power method from the
measured relative wind) and scored by the campaign (vtrials.score.trials: power at equal speed relative
to the true calm-water curve, speed through water against the spot's true mean). The budget:

    precision u_P = RMS error of the precision campaign
    source X    u_X² = mean over replicates of (e_X² − e_P²)   (paired, same replicate index)

per spot, with bootstrap 95 % intervals; wind also per Beaufort band.

    python benchmarks/study_insel2008.py --work /tmp/insel          # runs (resumes) the campaigns, writes the report
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

KN = 1852.0 / 3600.0
CASES = {c: ROOT / "scenarios" / "studies" / f"patrol51_insel_{c}.toml" for c in ("precision", "wind", "current")}
QUANTITIES = {"power_at_equal_speed": ("power at equal speed", "%", 100.0),
              "stw": ("speed through water", "kn", 1.0 / KN),
              "power_uncorrected": ("power at equal speed WITHOUT the wind correction (the spot's measured "
                                    "shaft power before the direct power method)", "%", 100.0)}
# WMO Beaufort upper limits [kn] (Bf 0 < 1 kn, ..., Bf 6 ≤ 27 kn); the study bins them in three bands
BANDS = {"Bf 0–3": (0.0, 10.5), "Bf 4": (10.5, 16.5), "Bf 5–6": (16.5, 27.5)}
OUT = ROOT / "benchmarks" / "results" / "studies"
SPOT_NAMES = {1: "low (300 r/min, P/D 0.65)", 2: "middle (415, 1.07)", 3: "top (530, 1.37)"}


def completed(out: Path, n: int) -> int:
    k = 0
    while k < n and (out / "parts" / f"replicate_{k:05d}.json").exists():
        k += 1
    return k


def run(work: Path, replicates: int | None, workers: int) -> None:
    from vtrials.campaign.run import run_campaign
    from vtrials.campaign.spec import load_campaign
    for case, scen in CASES.items():
        n = replicates or load_campaign(str(scen)).replicates
        ex = cf.ThreadPoolExecutor(1) if workers <= 1 else None
        try:
            run_campaign(str(scen), work / case, replicates=n, executor=ex, workers=workers, resume=True,
                         keep_records=True)
        finally:
            if ex is not None:
                ex.shutdown()


def load_case(out: Path, n: int) -> dict:
    """{replicate: {"drawn": {...}, "err": {(quantity, group): error}}} of the completed replicates."""
    reps = {}
    for i in range(n):
        r = json.loads((out / "parts" / f"replicate_{i:05d}.json").read_text())
        err, runs = {}, {}
        for row in r["rows"]:
            q = row["quantity"]
            if "/runs[run=" in q and row["truth"]:
                k = int(q.split("run=")[1].split("]")[0])
                name = q.rsplit("/", 1)[1]
                runs.setdefault(k, {})[name] = row["error"] / (row["truth"] if name == "power_measured" else 1.0)
                continue
            if "/spots[group=" not in q:
                continue
            g = int(q.split("group=")[1].split("]")[0])
            name = q.rsplit("/", 1)[1]
            if name in QUANTITIES:
                err[(name, g)] = row["error"]
        res = out / "replicates" / f"replicate_{i:05d}" / "results.json"
        if res.exists():  # kept records: the spot power before the wind correction, against the same truth
            trial = next(t for t in json.loads(res.read_text())["trials"] if t["kind"] == "standardization")
            for red, sc in zip(trial["reduced"]["spots"], trial["error"]["spots"]):
                pt = (sc.get("power_at_equal_speed") or {}).get("truth")
                if pt and math.isfinite(pt):
                    err[("power_uncorrected", red["group"])] = red["power_measured"]["value"] / pt - 1.0
        reps[i] = {"drawn": r["drawn"], "err": err, "runs": runs}
    return reps


def _boot(values_fn, idx, n_boot=2000, seed=0):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n_boot):
        out.append(values_fn(rng.choice(idx, size=len(idx))))
    return float(np.quantile(out, 0.025)), float(np.quantile(out, 0.975))


def _signed_sqrt(x):
    return math.copysign(math.sqrt(abs(x)), x)


def budget(cases: dict) -> dict:
    prec = cases["precision"]
    out = {}
    for q, (_, unit, scale) in QUANTITIES.items():
        per_spot = {}
        for g in (1, 2, 3):
            ep = {i: prec[i]["err"].get((q, g)) for i in prec}
            ep = {i: v * scale for i, v in ep.items() if v is not None and math.isfinite(v)}
            idx = np.array(sorted(ep))
            rms = lambda ii: float(np.sqrt(np.mean([ep[i] ** 2 for i in ii])))  # noqa: E731
            lo, hi = _boot(rms, idx)
            ent = {"precision": {"u": rms(idx), "lo95": lo, "hi95": hi, "n": int(idx.size)}}
            sources = {}
            if "wind" in cases:
                w = cases["wind"]
                for band, (a, b) in {"Bf 0–6": (0.0, 27.5), **BANDS}.items():
                    sources[f"wind {band}"] = [i for i in w if a <= w[i]["drawn"]["environment.wind.speed_kn"] < b]
            if "current" in cases:
                sources["current 0–1 kn"] = list(cases["current"])
            for name, members in sources.items():
                case = cases["wind"] if name.startswith("wind") else cases["current"]
                pairs = {i: (case[i]["err"].get((q, g)), ep.get(i)) for i in members if i in ep}
                pairs = {i: (a * scale, b) for i, (a, b) in pairs.items() if a is not None and math.isfinite(a)}
                if not pairs:
                    continue
                ii = np.array(sorted(pairs))
                u2 = lambda jj: float(np.mean([pairs[j][0] ** 2 - pairs[j][1] ** 2 for j in jj]))  # noqa: E731
                lo, hi = _boot(u2, ii, seed=1)
                total = float(np.sqrt(np.mean([pairs[j][0] ** 2 for j in ii])))
                ent[name] = {"u": _signed_sqrt(u2(ii)), "lo95": _signed_sqrt(lo), "hi95": _signed_sqrt(hi),
                             "n": int(ii.size), "rms_total": total}
            per_spot[g] = ent
        out[q] = per_spot
    return out


def run_level(case: dict) -> dict:
    """Run-level measurement errors of a campaign split into the part common to a trial's runs (per
    replicate mean: calibration draws, a bias for the trial) and the run-to-run part (deviations from it:
    precision in the narrow sense): RMS of each, for shaft power (relative) and speed over ground."""
    out = {}
    for name, scale, unit in (("power_measured", 100.0, "%"), ("sog", 1.0 / KN, "kn")):
        common, dev = [], []
        for r in case.values():
            e = np.array([v[name] for v in r["runs"].values() if name in v]) * scale
            if e.size >= 2:
                common.append(float(np.mean(e)))
                dev += list(e - np.mean(e))
        n_run = np.mean([len(r["runs"]) for r in case.values()]) if case else 0
        out[name] = {"unit": unit, "common_rms": float(np.sqrt(np.mean(np.square(common)))) if common else math.nan,
                     "run_to_run_rms": float(np.sqrt(np.sum(np.square(dev)) / max(len(dev) - len(common), 1)))
                     if dev else math.nan, "runs_per_trial": float(n_run)}
    return out


def findings(b: dict) -> list[dict]:
    q = "power_at_equal_speed"
    bs = b[q]
    out = []
    lo_p, hi_p = bs[1]["precision"], bs[3]["precision"]
    f1a = lo_p["lo95"] > hi_p["hi95"]
    elem = [k for k in bs[1] if k in ("wind Bf 0–6", "current 0–1 kn")]
    dom = {g: all(bs[g]["precision"]["u"] > bs[g][k]["u"] for k in elem) for g in bs}
    out.append({"finding": "Precision error is the most influential source, more so at low speed",
                "test": "u_precision(low spot) > u_precision(top spot) (95 % intervals apart), and u_precision > "
                        "every elementary source (wind Bf 0–6, current) at each spot; power at equal speed",
                "ours": {"precision_low_pct": lo_p, "precision_top_pct": hi_p, "precision_dominates_at_spot": dom},
                "reproduced": bool(f1a and dom.get(1, False)),
                "reproduced_whole_range": bool(all(dom.values()))})
    if "wind Bf 0–6" in bs[1] and "current 0–1 kn" in bs[1] and "power_uncorrected" in b:
        raw = b["power_uncorrected"]
        win = {g: bs[g]["wind Bf 0–6"]["u"] > bs[g]["current 0–1 kn"]["u"] for g in bs}
        win_raw = {g: raw[g]["wind Bf 0–6"]["u"] > max(raw[g]["current 0–1 kn"]["u"], 0.0) for g in raw}
        above_p = {g: raw[g]["wind Bf 5–6"]["lo95"] > raw[g]["precision"]["u"] for g in raw if "wind Bf 5–6" in raw[g]}
        out.append({"finding": "Wind (Beaufort number) is the largest elementary error source",
                    "test": "(a) as the sources enter the data (power before the wind correction): u_wind(Bf 0–6) > "
                            "u_current(0–1 kn) at every spot; (b) after the reduction's corrections: the same",
                    "ours": {"a_wind_gt_current_uncorrected": win_raw,
                             "a_u_wind_uncorrected_pct": {g: raw[g]["wind Bf 0–6"]["u"] for g in raw},
                             "a_u_wind_bf56_uncorrected_pct": {g: raw[g].get("wind Bf 5–6", {}).get("u") for g in raw},
                             "a_wind_bf56_above_precision": above_p,
                             "b_wind_gt_current_corrected": win,
                             "u_wind_pct": {g: bs[g]["wind Bf 0–6"]["u"] for g in bs},
                             "u_current_pct": {g: bs[g]["current 0–1 kn"]["u"] for g in bs}},
                    "reproduced": "yes" if all(win_raw.values()) and all(win.values()) else
                                  ("partly (before correction only)" if all(win_raw.values()) else "no")})
    return out


def _f(x, nd=2):
    return "—" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{nd}f}"


def report(b: dict, finds: list[dict], reps: dict, run_lv: dict | None = None) -> str:
    L = ["# Study: Insel (2008) — error budget of a speed/power trial, one source at a time", "",
         "Reproduces the qualitative findings of M. Insel, \"Uncertainty in the analysis of speed and powering "
         "trials\", *Ocean Engineering* 35 (2008) 1183–1193, with vtrials campaigns (`benchmarks/study_insel2008.py`).",
         "", "## Set-up", "",
         "* Ship and trial: patrol51 standardization, three spots — " + "; ".join(f"{g}: {n}" for g, n in SPOT_NAMES.items())
         + " — one double run each (base course 045° and reciprocal, 180 s measured runs, Williamson turns with a "
           "120 s run-out).",
         "* Campaigns sharing one campaign seed (replicate i has the same scenario seed in all: paired "
         f"differences): precision {reps.get('precision', 0)} replicates (calm water, no wind, no current); wind "
         f"{reps.get('wind', 0)} (Beaufort 0–6: 0–27 kn uniform, direction uniform, NPD gusts); current "
         f"{reps.get('current', 0)} (semidiurnal stream 0–1 kn, axis and phase uniform). A source's budget uses the "
         "replicates its campaign shares with the precision campaign (n in the tables).",
         "* Reduction: the operational one from the records (mean of means per spot with the two-run trend "
         "correction; wind by the direct power method from the measured relative wind). Score: the campaign's "
         "(vtrials.score.trials) — power at equal speed relative to the true calm-water curve, speed through "
         "water against the spot's true mean.",
         "* Budget per spot: u_P = RMS error of the precision campaign; u_X = √(mean(e_X² − e_P²)) over paired "
         "replicates (negative sign: the source did not add error beyond the scatter). Bootstrap 95 % intervals.",
         "* Not varied (honestly): sea state (a wave field costs about 9× a calm replicate here: 141 s against 16 s "
         "measured), displacement (the vessel is modelled at one loading; the agenda accepts the stated "
         "displacement only within 0.5 %), water depth and temperature.", "",
         "## Published findings and ours", "",
         "| Published (Insel 2008) | Our test | Ours | Reproduced |", "|---|---|---|---|"]
    for f in finds:
        o = f["ours"]
        if "precision_low_pct" in o:
            ours = (f"u_P low {_f(o['precision_low_pct']['u'])} % [{_f(o['precision_low_pct']['lo95'])}, "
                    f"{_f(o['precision_low_pct']['hi95'])}], top {_f(o['precision_top_pct']['u'])} % "
                    f"[{_f(o['precision_top_pct']['lo95'])}, {_f(o['precision_top_pct']['hi95'])}]; dominant at spots "
                    + ", ".join(f"{g}: {'yes' if v else 'no'}" for g, v in o["precision_dominates_at_spot"].items()))
        else:
            ours = ("(a) " + "; ".join(f"spot {g}: wind {_f(o['a_u_wind_uncorrected_pct'][g])} % (Bf 5–6 "
                                      f"{_f(o['a_u_wind_bf56_uncorrected_pct'][g])} %)" for g in o["a_u_wind_uncorrected_pct"])
                    + "; (b) " + "; ".join(f"spot {g}: wind {_f(o['u_wind_pct'][g])} % vs current "
                                           f"{_f(o['u_current_pct'][g])} %" for g in o["u_wind_pct"]))
        rep = f["reproduced"]
        rep = ("yes" if rep else "NO") if isinstance(rep, bool) else rep
        L.append(f"| {f['finding']} | {f['test']} | {ours} | {rep} |")
    for q, (label, unit, _) in QUANTITIES.items():
        bs = b[q]
        names = ["precision"] + [k for k in bs[1] if k != "precision"]
        L += ["", f"## Budget: {label} [{unit}] (u with 95 % interval; n replicates)", "",
              "| Source | " + " | ".join(f"spot {g}: {SPOT_NAMES[g]}" for g in (1, 2, 3)) + " |",
              "|---|---|---|---|"]
        for k in names:
            cells = []
            for g in (1, 2, 3):
                e = bs[g].get(k)
                cells.append("—" if e is None else f"{_f(e['u'], 3 if unit == 'kn' else 2)} "
                             f"[{_f(e['lo95'], 3 if unit == 'kn' else 2)}, {_f(e['hi95'], 3 if unit == 'kn' else 2)}] "
                             f"(n {e['n']})")
            L.append(f"| {k} | " + " | ".join(cells) + " |")
    bp, raw = b["power_at_equal_speed"], b.get("power_uncorrected")
    L += ["", "## Reading", "",
          f"* Precision (calm water: instrument noise and calibration draws, helm, run-to-run unsteadiness) gives "
          f"{_f(bp[1]['precision']['u'])} % of power at equal speed at the low spot against "
          f"{_f(bp[3]['precision']['u'])} % at the top: the same absolute errors of torque and speed weigh more "
          "against a small power at low speed."]
    if raw and "wind Bf 0–6" in raw[1]:
        L.append(f"* Wind as it enters the data is the largest environmental source (before the correction: "
                 f"{_f(raw[1]['wind Bf 0–6']['u'])} % at the low spot over Bf 0–6, {_f(raw[1].get('wind Bf 5–6', {}).get('u'))} % "
                 f"at Bf 5–6), but the reduction's direct power method — fed by the measured relative wind and the "
                 f"ship's own windage coefficients — removes it to within the scatter (after the correction: "
                 f"{_f(bp[1]['wind Bf 0–6']['u'])} %). A correction resting on a coarser wind estimate (an observed "
                 "Beaufort number) may leave more of the raw contribution: that is where our result and the paper's "
                 "can part.")
    if "current 0–1 kn" in bp[1]:
        L.append(f"* A tidal stream of up to 1 kn, removed by one double run per spot with the reduction's trend "
                 f"correction, adds {_f(bp[1]['current 0–1 kn']['u'])} / {_f(bp[2]['current 0–1 kn']['u'])} / "
                 f"{_f(bp[3]['current 0–1 kn']['u'])} % (low / middle / top spot).")
    L.append("* Negative entries: the source's campaign scattered less than the precision campaign for the same "
             "replicate seeds — within the sampling noise of a difference of two scatters.")
    if run_lv:
        L += ["", "## What the precision case is made of (run-level errors of the precision campaign)", "",
              "| Measurement | common to a trial's runs (calibration draws) RMS | run to run RMS |", "|---|---|---|"]
        for name, label in (("power_measured", "shaft power (relative)"), ("sog", "speed over ground")):
            e = run_lv[name]
            L.append(f"| {label} [{e['unit']}] | {_f(e['common_rms'], 3)} | {_f(e['run_to_run_rms'], 3)} |")
    L.append("")
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", default="/tmp/vtrials_study_insel", help="campaign directories")
    ap.add_argument("--replicates", type=int, default=None, help="per campaign (default: the scenarios' own)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--analyse-only", action="store_true", help="use the replicates completed so far in --work")
    ap.add_argument("--out", default=str(OUT))
    a = ap.parse_args(argv)
    work = Path(a.work)
    if not a.analyse_only:
        run(work, a.replicates, a.workers)
    from vtrials.campaign.spec import load_campaign
    cases, nrep = {}, {}
    for case, scen in CASES.items():
        n = completed(work / case, a.replicates or load_campaign(str(scen)).replicates)
        if n:
            cases[case] = load_case(work / case, n)
            nrep[case] = n
    b = budget(cases)
    finds = findings(b)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    from vtrials.runner.outputs import json_clean
    doc = {"study": "Insel 2008, Ocean Engineering 35:1183-1193",
           "scenarios": {c: str(p.relative_to(ROOT)) for c, p in CASES.items()}, "replicates": nrep,
           "budget": {q: {str(g): v for g, v in d.items()} for q, d in b.items()}, "findings": finds,
           "precision_run_level": run_level(cases["precision"]) if "precision" in cases else None,
           "replicate_errors": {c: {str(i): {"drawn": r["drawn"], "err": {f"{k[0]}[{k[1]}]": v for k, v in r["err"].items()}, "runs": r["runs"]}
                                    for i, r in reps.items()} for c, reps in cases.items()}}
    (out / "insel2008.json").write_text(json.dumps(json_clean(doc), indent=1))
    run_lv = run_level(cases["precision"]) if "precision" in cases else None
    (out / "insel2008.md").write_text(report(b, finds, nrep, run_lv))
    for f in finds:
        print(f"{f['reproduced']}: {f['finding']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
