"""Ship as a wave buoy on SIMULATOR records (issue 13 part C): patrol51 at forward speed in short-crested seas.

Each case is the State 3 standardization day (scenarios/patrol51_standardization_sea3.toml) cut to two
speed spots of two reciprocal 600 s runs (course 045 and 225), with the sea (Pierson-Moskowitz, cos-2s
s = 10) and the wind from ``direction``: from 010 the sea meets the 045 leg 35 deg off the port bow and
the 225 leg on the starboard quarter; from 080 the mirror images. Per run the reduction reads the record
only (IMU specific forces and vertical-gyro roll/pitch -> heave at the IMU, roll, pitch; cross-spectra;
fit with the team's DESIGN-STAGE RAOs, models/patrol51/design) and is scored against the true sea
(vtrials.truth.seaway: the components' H_s, their energy-weighted mean direction relative to the
ship's true mean heading over the run). Three fit settings are reported: roll stiffness and damping
fitted with the sea (the default), roll RAO trusted as the design model has it, and roll with a free gain;
and ("day_fit") one sea fitted to the day's four runs together (reduce.shipbuoy.ship_buoy_from_legs): on
reciprocal courses the headings cannot tell port from starboard, so there roll still does.

    PYTHONPATH=. python benchmarks/shipbuoy_sim.py [--quick]

Writes benchmarks/results/shipbuoy_sim.json.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vtrials.records.netcdf import open_record, read_groups
from vtrials.reduce.design_rao import load_design_rao
from vtrials.reduce.seamotion import run_windows
from vtrials.reduce.shipbuoy import ship_buoy_from_legs, ship_buoy_from_record
from vtrials.runner.trial_day import simulate_agenda, write_agenda_outputs
from vtrials.scenario import load_scenario, wave_field
from vtrials.truth.seaway import sea_truth, window_heading

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "scenarios" / "patrol51_standardization_sea3.toml"
OUT = ROOT / "benchmarks" / "results" / "shipbuoy_sim.json"
SPOTS = ((340.0, 0.79), (415.0, 1.07))
CASES = ((2002, 10.0, 1.2), (2003, 80.0, 1.2), (2004, 10.0, 1.5), (2005, 80.0, 1.5))
SETTINGS = {"roll_tuned": dict(tune_roll=True), "roll_trusted": dict(tune_roll=False),
            "roll_free_gain": dict(free_gain=("roll",), tune_roll=False)}


def scenario_text(seed: int, direction: float, hs: float, run_s: float = 600.0, spots=SPOTS) -> str:
    t = BASE.read_text()
    head = t.split("[[agenda.trial.spot]]", 1)[0]
    head = head.replace("seed = 2002", f"seed = {seed}").replace("run_s = 180.0", f"run_s = {run_s}")
    head = head.replace("hs_m = 0.88", f"hs_m = {hs}")
    head = re.sub(r"direction_deg = 10\.0", f"direction_deg = {direction}", head)
    for rpm, p in spots:
        head += f"[[agenda.trial.spot]]\nrpm = {rpm}\npitch = {p}\nruns = 2\n\n"
    return head


def score_case(out: Path, scn, design, settings=SETTINGS) -> list[dict]:
    rec = open_record(out / "records" / "standardization.nc")
    tr = read_groups(out / "truth.nc")["groups"]["agenda"]["variables"]
    comp = wave_field(scn).components
    rows = []
    for run, t0, t1 in run_windows(rec):
        st = sea_truth(comp, window_heading(tr["time"], tr["heading"], t0, t1))
        k = (tr["time"] >= t0) & (tr["time"] <= t1)
        row = {"seed": scn.head.seed, "run": run, "hs_true": st["hs"], "from_rel_true_deg": st["from_rel_deg"],
               "u_true": float(np.mean(tr["u"][k])), "roll_std_true_deg": math.degrees(float(np.std(tr["roll"][k])))}
        for name, kw in settings.items():
            t = time.perf_counter()
            rb = ship_buoy_from_record(rec, t0, t1, design, **kw)
            d = math.remainder(math.radians(rb.from_relative_deg - st["from_rel_deg"]), 2 * math.pi)
            row[name] = {"hs": rb.fit.hs, "hs_err": rb.fit.hs / st["hs"] - 1.0, "from_rel_deg": rb.from_relative_deg,
                         "dir_err_deg": math.degrees(d), "tp": rb.fit.tp, "s": rb.fit.s, "gamma": rb.fit.gamma,
                         "gains": list(rb.fit.gains), "U_log": rb.U,
                         "observed": list(rb.observed), "reliable": rb.reliable,
                         "side_right": bool(np.sign(rb.from_relative_deg) == np.sign(st["from_rel_deg"])),
                         "seconds": time.perf_counter() - t}
        row["_truth"] = st
        rows.append(row)
    # one sea fitted to the day's four runs: reciprocal courses, so roll (not the headings) tells the side
    t = time.perf_counter()
    sb = ship_buoy_from_legs(rec, [(t0, t1) for _, t0, t1 in run_windows(rec)], design)
    for k, row in enumerate(rows):
        st = row.pop("_truth")
        d = math.remainder(math.radians(sb.from_relative_deg(k) - st["from_rel_deg"]), 2 * math.pi)
        row["day_fit"] = {"hs": sb.fit.hs, "hs_err": sb.fit.hs / st["hs"] - 1.0, "from_rel_deg": sb.from_relative_deg(k),
                          "dir_err_deg": math.degrees(d), "tp": sb.fit.tp, "s": sb.fit.s, "gamma": sb.fit.gamma,
                          "roll_tuning": list(sb.fit.roll), "side_from": sb.side_from,
                          "observed": list(sb.observed[k]), "reliable": sb.reliable(k),
                          "side_right": bool(np.sign(sb.from_relative_deg(k)) == np.sign(st["from_rel_deg"])),
                          "seconds": time.perf_counter() - t}
        print(json.dumps(row), flush=True)
    return rows


def summary(rows, settings=SETTINGS) -> dict:
    out = {}
    for name in tuple(settings) + ("day_fit",):
        for tag, sel in (("", rows), ("_reliable", [r for r in rows if r[name].get("reliable")]),
                         ("_flagged", [r for r in rows if not r[name].get("reliable", True)])):
            if not sel:
                continue
            he = np.array([abs(r[name]["hs_err"]) for r in sel])
            de = np.array([abs(r[name]["dir_err_deg"]) for r in sel])
            side = np.array([r[name]["side_right"] for r in sel])
            out[name + tag] = {"n": len(sel), "hs_within_15pct": int(np.sum(he <= 0.15)),
                               "dir_within_15deg": int(np.sum(de <= 15.0)),
                               "both": int(np.sum((he <= 0.15) & (de <= 15.0))), "side_right": int(np.sum(side)),
                               "hs_abs_err_median": float(np.median(he)),
                               "hs_err_mean": float(np.mean([r[name]["hs_err"] for r in sel])),
                               "dir_abs_err_median_deg": float(np.median(de)), "dir_abs_err_max_deg": float(np.max(de))}
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="first case only")
    a = ap.parse_args(argv)
    design = load_design_rao("patrol51")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed, direction, hs in (CASES[:1] if a.quick else CASES):
            p = Path(tmp) / f"case_{seed}.toml"
            p.write_text(scenario_text(seed, direction, hs))
            scn = load_scenario(p)
            t = time.perf_counter()
            res = simulate_agenda(scn)
            out = Path(tmp) / f"out_{seed}"
            write_agenda_outputs(res, out, plot=False)
            print(f"case seed {seed} from {direction} H_s {hs}: simulated in {time.perf_counter() - t:.0f} s", flush=True)
            for r in score_case(out, scn, design):
                r.update({"direction_deg": direction, "hs_target": hs})
                rows.append(r)
    res = {"design_file": "models/patrol51/design/patrol51_design_rao.nc", "cases": CASES, "spots": SPOTS,
           "run_s": 600.0, "rows": rows, "summary": summary(rows)}
    print(json.dumps(res["summary"], indent=1))
    if not a.quick:
        OUT.write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
