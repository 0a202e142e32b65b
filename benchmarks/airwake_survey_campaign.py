"""Replicates of the shipped airwake survey (scenarios/patrol51_airwake_survey.toml) with other seeds
(sea, gusts, instrument errors): the AWSM residual fraction, the mean change against its uncertainty,
and the coverage and sharpness of the 95 % intervals of the mean airwake components and airwake ratios.

    PYTHONPATH=. python benchmarks/airwake_survey_campaign.py [N]    → results/airwake_survey_campaign.json
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from vtrials.runner.trial_day import simulate_agenda, write_agenda_outputs  # noqa: E402
from vtrials.scenario import load_scenario  # noqa: E402
from vtrials.schema import load_toml  # noqa: E402

SCN = ROOT / "scenarios" / "patrol51_airwake_survey.toml"


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    if n == 0:
        return (math.nan, math.nan)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return c - h, c + h


def main(n: int):
    rows = []
    for k in range(n):
        seed = 3003 + 17 * (k + 1)
        doc = load_toml(SCN)
        doc["scenario"]["seed"] = seed
        doc["scenario"]["truth_every"] = 20
        t0 = time.perf_counter()
        try:
            res = simulate_agenda(load_scenario(SCN, doc))
            with tempfile.TemporaryDirectory() as tmp:
                out = write_agenda_outputs(res, Path(tmp) / "o", plot=False)
        except Exception as exc:  # noqa: BLE001 - a failed replicate is a result
            rows.append({"seed": seed, "error": str(exc)[:300]})
            print(seed, "error", exc, flush=True)
            continue
        tr = out["trials"][0]
        rows.append({"seed": seed, "summary": tr["error"]["summary"], "runs": tr["error"]["runs"],
                     "wall_s": time.perf_counter() - t0})
        print(seed, tr["error"]["summary"], flush=True)
    fr, frs, mean_ok = [], [], []
    groups = {"mean_airwake": ([], [], []), "mean_airwake_with_sampling": ([], [], []),
              "airwake_ratio": ([], [], [])}  # covered, half-width, |error|
    for r in rows:
        for e in r.get("runs", []):
            if "residual_fraction_awsm" not in e:
                continue
            fr.append(e["residual_fraction_awsm"])
            frs.append(e["residual_fraction_awsm_seed_order"])
            mean_ok.append(all(c["within"] for c in e["mean_change"]))
            for key, items in (("mean_airwake", e["mean_airwake"]),
                               ("mean_airwake_with_sampling", e["mean_airwake_with_sampling"]),
                               ("airwake_ratio", [e["airwake_ratio"]])):
                for c in items:
                    groups[key][0].append(bool(c["covered"]))
                    groups[key][1].append(c["half_width95"])
                    groups[key][2].append(abs(c["error"]))
    calib = {}
    for key, (cov, hw, err) in groups.items():
        q95 = float(np.quantile(err, 0.95)) if err else math.nan
        calib[key] = {"n": len(cov), "covered": int(sum(cov)), "coverage": float(np.mean(cov)) if cov else None,
                      "wilson95": wilson(int(sum(cov)), len(cov)),
                      "sharpness": float(np.mean(hw) / q95) if hw and q95 > 0 else None}
    doc = {"replicates": n, "recordings": len(fr),
           "residual_fraction_awsm": {"max": max(fr, default=None), "median": float(np.median(fr)) if fr else None,
                                      "fraction_below_0.10": float(np.mean(np.array(fr) < 0.10)) if fr else None},
           "residual_fraction_seed_order": {"max": max(frs, default=None),
                                            "median": float(np.median(frs)) if frs else None},
           "mean_unchanged_fraction": float(np.mean(mean_ok)) if mean_ok else None,
           "intervals": calib,
           "note": "within one replicate the instrument errors are common to its six recordings, so the "
                   "pooled intervals are not independent",
           "replicates_detail": [{k: v for k, v in r.items() if k != "runs"} for r in rows]}
    path = ROOT / "benchmarks" / "results" / "airwake_survey_campaign.json"
    path.write_text(json.dumps(doc, indent=2, default=float) + "\n")
    print(json.dumps({k: v for k, v in doc.items() if k != "replicates_detail"}, indent=1, default=float))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10)
