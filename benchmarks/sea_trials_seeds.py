"""The short State 3 standardization day of tests/test_sea_trials.py over wave seeds: how much of its
result is the realization.

tests/data/patrol51_standardization_sea3_short.toml is run through ``vtrials.run`` with its scenario
seed replaced by each of ``--seeds``; per seed the true speed through the water and shaft power of
every accepted run (scorer's truth), the attempt that was accepted, and per spot the reduced power at
equal speed against the calm-water truth, uncorrected (``raw``) and with the team's STAWAVE-2
correction (``cor``), both net of the meters' drawn calibration errors — the quantities
test_stawave_corrected_reduction_recovers_the_calm_water_curve asserts on (|cor| < |raw| at the slow
spot; |cor| ≤ 2.5 % at both).

Run: ``python benchmarks/sea_trials_seeds.py --seeds 2002-2020 [--run-s 180] [--out FILE]``.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SHORT = ROOT / "tests" / "data" / "patrol51_standardization_sea3_short.toml"


def extract(out: Path, seed: int) -> dict:
    """The row of one simulated day whose outputs are in ``out`` (results.json, truth.nc)."""
    sys.path.insert(0, str(ROOT))
    from tests.calibration import calibration_power_error, drawn_meter_errors
    from vtrials.score.trials import true_curve
    doc = json.loads((out / "results.json").read_text())
    meters = drawn_meter_errors(out / "truth.nc")
    t = doc["trials"][0]
    P_true, _ = true_curve(t["truth"]["calm_water"])
    row = {"seed": seed, "runs": [], "spots": []}
    for r in t["truth"]["runs"]:
        row["runs"].append({"run": r["run"], "attempt": r.get("attempt"), "t0": r["t0"], "stw": r["stw"],
                            "power_excess": r["power"] / float(P_true(r["stw"])) - 1.0})
    for s in t["reduced"]["spots"]:
        Pt = float(P_true(s["stw"]["value"]))
        cal = calibration_power_error(meters, s["torque"], s["rps"])
        row["spots"].append({"group": s["group"], "V": s["stw"]["value"],
                             "raw": (s["power_measured"]["value"] / Pt) / (1.0 + cal) - 1.0,
                             "cor": (s["power"]["value"] / Pt) / (1.0 + cal) - 1.0})
    return row


def one_day(seed: int, run_s: float | None = None) -> dict:
    import vtrials
    src = re.sub(r"(?m)^seed = \d+", f"seed = {seed}", SHORT.read_text())
    if run_s is not None:
        src = re.sub(r"(?m)^run_s = [0-9.]+", f"run_s = {float(run_s)}", src)
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "s.toml"
        f.write_text(src)
        vtrials.run(f, Path(d) / "o", plot=False)
        return extract(Path(d) / "o", seed)


def summary(rows: list[dict]) -> dict:
    sr = np.array([r["spots"][0]["raw"] for r in rows])
    sc = np.array([r["spots"][0]["cor"] for r in rows])
    fc = np.array([r["spots"][1]["cor"] for r in rows])
    fr = np.array([r["spots"][1]["raw"] for r in rows])
    stw = np.array([[x["stw"] for x in r["runs"]] for r in rows])
    slow_ok = np.abs(sc) < np.abs(sr)
    worst_ok = np.maximum(np.abs(sc), np.abs(fc)) <= 0.025
    return {"n": len(rows), "slow_raw_mean": float(sr.mean()), "slow_raw_sd": float(sr.std()),
            "slow_cor_mean": float(sc.mean()), "slow_cor_sd": float(sc.std()),
            "fast_raw_mean": float(fr.mean()), "fast_raw_sd": float(fr.std()),
            "fast_cor_mean": float(fc.mean()), "fast_cor_sd": float(fc.std()),
            "slow_cor_nearer_than_raw": int(slow_ok.sum()), "worst_cor_within_2.5pct": int(worst_ok.sum()),
            "test_criteria_met": int((slow_ok & worst_ok).sum()),
            "run_stw_mean": stw.mean(axis=0).tolist(), "run_stw_sd": stw.std(axis=0).tolist()}


def _seeds(text: str) -> list[int]:
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(x) for x in text.split(",")]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="2002-2011")
    ap.add_argument("--run-s", type=float, default=None, help="override the runs' length [s] (the file's run_s by default)")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "sea_trials_seeds.json"))
    a = ap.parse_args(argv)
    rows = []
    for s in _seeds(a.seeds):
        rows.append(one_day(s, a.run_s))
        sp = rows[-1]["spots"]
        print(f"seed {s}: slow raw {sp[0]['raw']:+.4f} cor {sp[0]['cor']:+.4f}, fast raw {sp[1]['raw']:+.4f} "
              f"cor {sp[1]['cor']:+.4f}", flush=True)
    file_run_s = float(re.search(r"(?m)^run_s = ([0-9.]+)", SHORT.read_text()).group(1))
    out = {"scenario": str(SHORT.relative_to(ROOT)), "run_s": a.run_s or file_run_s, "rows": rows, "summary": summary(rows)}
    Path(a.out).write_text(json.dumps(out, indent=1))
    print(json.dumps(out["summary"], indent=1))


if __name__ == "__main__":
    main()
