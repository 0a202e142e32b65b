"""Seed 004's wave-fusion headline on simulator records: star-pattern seakeeping trials of patrol51 with the
X-band wave radar (recalibrated WaMoS-like, vtrials.instruments.wave_sensors) over H_s 1.5-5 m.

Each case is a seakeeping trial (kind "seakeeping", legs laid relative to the observed wave direction)
of four legs — head, starboard bow, port bow, following — of ``LEG_S`` each (seed 004: 25 min) at the
order ``--order`` (default "standard", about 9 m/s for patrol51) in a
Pierson-Moskowitz sea with cos-2s spreading (s = 10), T_p from H_s by the NATO sea-state table's most
probable modal periods (Lee & Bales 1984 / STANAG 4194: SS3 0.88 m 7.5 s, SS5 3.25 m 9.7 s, SS6 5.0 m
12.4 s; T_p = 6.45 + 1.2 H_s s fits them within 0.4 s). Per leg the reduction reads the record only:
the radar's mean directional spectrum over the leg and its H_s, the measured RMS of heave (IMU, double
integrated), pitch, roll and vertical acceleration, and the team's DESIGN-STAGE RAOs
(models/patrol51/design; never the simulator's) -> r = mean(δ_meas/δ_pred) over the chosen components,
H_s,fused = r H_s,radar (seed 004 eqs. 1-5). Scored against the true sea's H_s (the components').

    PYTHONPATH=. python benchmarks/campaign_wavefusion.py            # the headline (results/campaign_wavefusion.json)
    PYTHONPATH=. python benchmarks/campaign_wavefusion.py --leg-s 600 --out benchmarks/results/campaign_wavefusion_10min.json
    PYTHONPATH=. python benchmarks/campaign_wavefusion.py --ship kvlcc2 --order ahead_2_3 --cases 8 --leg-s 600 \
        --out benchmarks/results/campaign_wavefusion_kvlcc2.json
    (campaign_wavefusion_ahead_1_3.json: an earlier run of this script at --order ahead_1_3 --leg-s 600,
    before the leg acceptance and the ship-buoy columns were added)

Writes the JSON after every case, so a partial campaign is kept. Each leg is also reduced by the ship as
a wave buoy (vtrials.reduce.shipbuoy, same design RAOs, no radar): leg by leg ("buoy") and as one sea
fitted to all the case's legs ("star_buoy", ship_buoy_from_legs: the legs' headings tell the side). Legs whose gyro heading wandered more
than MAX_HEADING_STD_DEG are summarised apart ("accepted_legs") — a records-only test.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vtrials.records.netcdf import open_record, read_groups
from vtrials.reduce.design_rao import load_design_rao
from vtrials.reduce.seamotion import run_windows
from vtrials.reduce.shipbuoy import ship_buoy_from_legs, ship_buoy_from_record
from vtrials.reduce.wavefusion import fuse_run
from vtrials.runner.trial_day import simulate_agenda, write_agenda_outputs
from vtrials.scenario import load_scenario, wave_field
from vtrials.truth.seaway import sea_truth, window_heading

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "campaign_wavefusion.json"
LEG_S = 1500.0
LEGS = ("head", "bow_starboard", "bow_port", "following")
# (H_s [m], seed): one sweep over 1.5-5 m, then a second seed at every metre
CASES = [(hs, 13000 + k) for k, hs in enumerate((1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0))] + \
        [(hs, 13100 + k) for k, hs in enumerate((2.0, 3.0, 4.0, 5.0, 1.5, 2.5, 3.5, 4.5))]
# the team's leg acceptance (records only): the course held within this standard deviation of the gyro heading
# over the leg (a leg that wanders has no single relative wave direction; fusion assumes one)
MAX_HEADING_STD_DEG = 10.0
COMBOS = (("heave",), ("pitch",), ("roll",), ("acc",), ("heave", "pitch"), ("heave", "roll"), ("pitch", "roll"),
          ("heave", "acc"), ("pitch", "acc"), ("heave", "pitch", "roll"), ("heave", "pitch", "acc"))


def tp_of(hs: float) -> float:
    return 6.45 + 1.2 * hs


RADAR_SITE = {"patrol51": "transponder_mast", "kvlcc2": "bridge"}


def scenario_text(hs: float, seed: int, ship: str = "patrol51", order: str = "standard", legs=LEGS,
                  leg_s: float = LEG_S) -> str:
    legs = "".join(f'[[agenda.trial.leg]]\nheading = "{h}"\norder = "{order}"\nleg_s = {leg_s}\n\n' for h in legs)
    return f"""# wave-fusion campaign case (benchmarks/campaign_wavefusion.py)
[scenario]
title = "{ship} seakeeping star, H_s {hs} m, radar + motions"
ship = "{ship}"
seed = {seed}
timestep_s = 0.05
record_every = 1
truth_every = 20

[environment]
water_depth_m = 1000.0

[environment.waves]
spectrum = "pierson_moskowitz"
hs_m = {hs}
tp_s = {tp_of(hs):.3f}
direction_deg = 300.0
spreading = "cos2s"
spreading_s = 10.0
n_components = 200

[environment.wind]
speed_kn = {min(10.0 + 6.0 * hs, 40.0):.1f}
direction_deg = 300.0

[agenda]
base_course_deg = 300.0
autopilot_rudder_deg = 20.0
turn_rudder_deg = 20.0
approach_s = 60.0
settle_min_s = 60.0
settle_max_s = 300.0
repeat_unsteady = 0

[agenda.steadiness]
window_s = 60.0
torque_pct = 5.0
speed_kn = 0.5
heading_deg = 3.0

[[agenda.trial]]
name = "seakeeping"
kind = "seakeeping"

{legs}[[instrument]]
name = "radar"
spec = "wave_radar_recalibrated"
site = "{RADAR_SITE[ship]}"
"""


def reduce_case(out: Path, scn, design, legs=LEGS) -> list[dict]:
    rec = open_record(out / "records" / "seakeeping.nc")
    tr = read_groups(out / "truth.nc")["groups"]["agenda"]["variables"]
    comp = wave_field(scn).components
    rows = []
    for run, t0, t1 in run_windows(rec):
        st = sea_truth(comp, window_heading(tr["time"], tr["heading"], t0, t1))
        f = fuse_run(rec, t0, t1, design, combos=COMBOS)
        k = (tr["time"] >= t0) & (tr["time"] <= t1)
        row = {"seed": scn.head.seed, "run": run, "leg": legs[run - 1] if run <= len(legs) else str(run),
               "hs_true": st["hs"], "from_rel_true_deg": st["from_rel_deg"], "U_log": f.U,
               "hs_radar": f.hs_radar, "radar_ratio": f.hs_radar / st["hs"], "n_spectra": f.n_spectra,
               "measured": f.measured, "predicted": f.predicted,
               "fused_ratio": {k: v.hs / st["hs"] for k, v in f.fused.items()},
               "r": {c: v.r for c, v in f.fused.items()},
               "heading_std_deg": math.degrees(f.heading_std), "accepted": math.degrees(f.heading_std) <= MAX_HEADING_STD_DEG,
               "roll_std_true_deg": math.degrees(float(np.std(tr["roll"][k])))}
        try:   # the ship as a wave buoy on the same leg (the design RAOs, no radar)
            rb = ship_buoy_from_record(rec, t0, t1, design)
            row["buoy"] = scored(rb.fit, rb.from_relative_deg, st) | {"observed": list(rb.observed),
                                                                       "reliable": rb.reliable}
        except Exception as exc:  # reported, not hidden
            row["buoy"] = {"error": f"{type(exc).__name__}: {exc}"[:200]}
        row["_truth"] = st
        rows.append(row)
        print(json.dumps({c: row[c] for c in ("seed", "run", "leg", "hs_true", "radar_ratio", "heading_std_deg")}
                         | {"heave+pitch": round(row["fused_ratio"]["heave+pitch"], 3)}), flush=True)
    try:   # one sea fitted to all the star's legs: the headings tell port from starboard
        sb = ship_buoy_from_legs(rec, [(t0, t1) for _, t0, t1 in run_windows(rec)], design)
        for k, row in enumerate(rows):
            row["star_buoy"] = scored(sb.fit, sb.from_relative_deg(k), row["_truth"]) | {
                "observed": list(sb.observed[k]), "reliable": sb.reliable(k), "side_from": sb.side_from,
                "roll_tuning": list(sb.fit.roll)}
    except Exception as exc:  # reported, not hidden
        for row in rows:
            row["star_buoy"] = {"error": f"{type(exc).__name__}: {exc}"[:200]}
    for row in rows:
        del row["_truth"]
    return rows


def scored(fit, from_rel_deg: float, st: dict) -> dict:
    """A ship-as-buoy estimate against the leg's true sea: H_s error, direction error [deg], side right (a
    sea within 10° of head or following seas has no side)."""
    d = math.degrees(math.remainder(math.radians(from_rel_deg - st["from_rel_deg"]), 2 * math.pi))
    return {"hs_err": fit.hs / st["hs"] - 1.0, "from_rel_deg": from_rel_deg, "dir_err_deg": d,
            "side_right": bool(abs(st["from_rel_deg"]) < 10.0 or abs(st["from_rel_deg"]) > 170.0
                               or np.sign(from_rel_deg) == np.sign(st["from_rel_deg"])),
            "tp": fit.tp, "s": fit.s, "gamma": fit.gamma}


def summary(rows) -> dict:
    acc = [r for r in rows if r.get("accepted", True)]
    out = {"all_legs": _summary(rows), "accepted_legs": _summary(acc) if len(acc) > 1 else None,
           "n_rejected": len(rows) - len(acc)}
    return out


def _summary(rows) -> dict:
    rad = np.array([r["radar_ratio"] for r in rows])
    hs = np.array([r["hs_true"] for r in rows])
    out = {"n_runs": len(rows), "radar_ratio_mean": float(np.mean(rad)), "radar_ratio_std": float(np.std(rad, ddof=1)),
           "radar_within_15pct_above_2.5m": int(np.sum((np.abs(rad - 1) <= 0.15) & (hs > 2.5))),
           "n_above_2.5m": int(np.sum(hs > 2.5)), "combos": {}}
    for c in rows[0]["fused_ratio"]:
        f = np.array([r["fused_ratio"][c] for r in rows])
        sd = float(np.std(f, ddof=1))
        out["combos"][c] = {"mean": float(np.mean(f)), "std": sd, "scatter_reduction": out["radar_ratio_std"] / sd,
                            "within_15pct_above_2.5m": int(np.sum((np.abs(f - 1) <= 0.15) & (hs > 2.5))),
                            "within_15pct_all": int(np.sum(np.abs(f - 1) <= 0.15))}
    for name in ("buoy", "star_buoy"):
        b_all = [r[name] for r in rows if "hs_err" in r.get(name, {})]
        pre = "ship_buoy" if name == "buoy" else "star_buoy"
        for key, b in ((pre, b_all), (pre + "_reliable", [x for x in b_all if x.get("reliable")]),
                       (pre + "_flagged", [x for x in b_all if not x.get("reliable", True)])):
            if b:
                out[key] = _buoy_summary(b)
    return out


def _buoy_summary(b) -> dict:
    """Counts of ship-as-buoy results within 15 % in H_s, within 15° in direction, on the right side."""
    he = np.array([x["hs_err"] for x in b])
    de = np.array([abs(x["dir_err_deg"]) for x in b])
    return {"n": len(b), "hs_within_15pct": int(np.sum(np.abs(he) <= 0.15)),
            "dir_within_15deg": int(np.sum(de <= 15.0)), "side_right": int(sum(x["side_right"] for x in b)),
            "both": int(np.sum((np.abs(he) <= 0.15) & (de <= 15.0))),
            "hs_err_mean": float(np.mean(he)), "hs_abs_err_median": float(np.median(np.abs(he))),
            "dir_abs_err_median_deg": float(np.median(de)), "dir_abs_err_max_deg": float(np.max(de))}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=len(CASES))
    ap.add_argument("--ship", default="patrol51")
    ap.add_argument("--order", default="standard")
    ap.add_argument("--legs", default=",".join(LEGS))
    ap.add_argument("--leg-s", type=float, default=LEG_S)
    ap.add_argument("--out", default=str(OUT))
    a = ap.parse_args(argv)
    legs = tuple(a.legs.split(","))
    out_json = Path(a.out)
    design = load_design_rao(a.ship)
    rows, failed = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for hs, seed in CASES[:a.cases]:
            p = Path(tmp) / f"case_{seed}.toml"
            p.write_text(scenario_text(hs, seed, a.ship, a.order, legs, a.leg_s))
            t = time.perf_counter()
            try:
                scn = load_scenario(p)
                res = simulate_agenda(scn)
                out = Path(tmp) / f"out_{seed}"
                write_agenda_outputs(res, out, plot=False)
                new = reduce_case(out, scn, design, legs)
            except Exception as exc:  # a case the ship or the crew could not complete is reported, not hidden
                failed.append({"hs": hs, "seed": seed, "error": f"{type(exc).__name__}: {exc}"[:300]})
                print(f"case H_s {hs} seed {seed} FAILED: {exc}", flush=True)
                continue
            for r in new:
                r["hs_target"] = hs
                r["tp"] = tp_of(hs)
            rows += new
            print(f"case H_s {hs} seed {seed}: {time.perf_counter() - t:.0f} s", flush=True)
            doc = {"ship": a.ship, "legs": legs, "leg_s": a.leg_s, "order": a.order, "radar": "wave_radar_recalibrated",
                   "max_heading_std_deg": MAX_HEADING_STD_DEG,
                   "design_file": f"models/{a.ship}/design/{a.ship}_design_rao.nc", "rows": rows, "failed": failed,
                   "summary": summary(rows) if len(rows) > 1 else None}
            out_json.write_text(json.dumps(doc, indent=1))
    s = summary(rows)
    print(json.dumps(s, indent=1))
    return s


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
