"""Seakeeping star pattern (issue 13): transfer functions from 25-min legs against the truth.

Runs ``scenarios/patrol51_seakeeping.toml`` (station keeping, six legs at 8 and 13 kn, station keeping;
25 min each; H_s 0.75 m, cos-2s s = 10) through the whole chain (crew, records, reductions from the
records, scoring), and collects per leg and response: the bins the reduction reports as determined
(γ² > 0.8 and ≥ 1 % of the response's spectral peak), their amplitude errors against the true transfer
function of the realised sea (median, max, share within 10 %), the coverage of the 95 % amplitude and
phase intervals with Wilson intervals, and the sharpness (mean half-width / 95 % quantile of
|error|); RMS motions and the probe's H_s against truth; run times.

    python benchmarks/seakeeping_transfer.py --out benchmarks/results/seakeeping_transfer.json
    python benchmarks/seakeeping_transfer.py --timestep 0.05 --out benchmarks/results/seakeeping_transfer_dt005.json
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vtrials.runner import run  # noqa: E402
from vtrials.schema import load_toml  # noqa: E402
from vtrials.score.coverage import wilson  # noqa: E402

RESP = ("heave", "vertical_acc", "roll", "pitch")


def _stats(err, half, cov_a, cov_p) -> dict:
    err, half = np.abs(np.asarray(err, float)), np.asarray(half, float)
    n = int(err.size)
    if n == 0:
        return {"bins": 0}
    ka, kp = int(np.sum(cov_a)), int(np.sum(cov_p))
    q95 = float(np.quantile(err, 0.95))
    return {"bins": n, "median_abs_amp_error": float(np.median(err)), "max_abs_amp_error": float(err.max()),
            "within_10pct": float(np.mean(err <= 0.10)),
            "amp_coverage": ka / n, "amp_coverage_wilson": list(wilson(ka, n)),
            "phase_coverage": kp / n, "phase_coverage_wilson": list(wilson(kp, n)),
            "amp_sharpness": float(np.mean(half) / q95) if q95 > 0 else None}


def summarize(doc: dict) -> dict:
    tr = [t for t in doc["trials"] if t["kind"] == "seakeeping"][0]
    red = {L["run"]: L for L in tr["reduced"]["legs"]}
    legs, pool, expect = [], {n: ([], [], [], []) for n in RESP}, {n: [] for n in RESP}
    for sc in tr["legs"]:
        leg = red[sc["run"]]
        row = {"run": sc["run"], "label": sc["label"], "speed_mps": leg["speed"], "mu_deg": float(np.degrees(leg["mu"])),
               "duration_s": leg["duration_s"], "segment_s": leg["segment_s"],
               "hs_probe": sc["hs_probe"], "rms": sc["rms"], "transfer": {}}
        for n in RESP:
            t = sc["transfer"][n]
            row["transfer"][n] = _stats(t.get("amp_error", []), t.get("amp_half_width", []), t.get("amp_covered", []),
                                        t.get("phase_covered", []))
            row["transfer"][n]["all_coherent"] = t.get("all_coherent")
            row["transfer"][n]["expected_within_10pct"] = t.get("expected_within_10pct")
            for k, key in enumerate(("amp_error", "amp_half_width", "amp_covered", "phase_covered")):
                pool[n][k].extend(t.get(key, []))
            expect[n].extend([t["expected_within_10pct"]] * t["bins"] if t["bins"] else [])
        row["transfer_pool"] = [[x for n in RESP for x in sc["transfer"][n].get(key, [])]
                                for key in ("amp_error", "amp_half_width", "amp_covered", "phase_covered")]
        legs.append(row)
    overall = {n: _stats(*pool[n]) for n in RESP}
    allb = [np.concatenate([np.asarray(pool[n][k], float) for n in RESP]) for k in range(4)]
    overall["all_responses"] = _stats(*allb)
    for n in RESP:
        if expect[n]:
            overall[n]["expected_within_10pct"] = float(np.mean(expect[n]))
    ex = [e for n in RESP for e in expect[n]]
    if ex:
        overall["all_responses"]["expected_within_10pct"] = float(np.mean(ex))
    # the legs where the probe's wave explains the motions (head seas, station keeping, bow seas at speed)
    head = [L for L in legs if L["label"].startswith(("head", "station"))]
    hp = [np.concatenate([np.asarray(L["transfer_pool"][k], float) for L in head]) for k in range(4)] if head else None
    if hp is not None:
        overall["head_and_station_keeping"] = _stats(*hp)
        ex = [L["transfer"][n]["expected_within_10pct"] for L in head for n in RESP
              for _ in range(L["transfer"][n]["bins"]) if L["transfer"][n]["bins"]]
        if ex:
            overall["head_and_station_keeping"]["expected_within_10pct"] = float(np.mean(ex))
    hs = [L["hs_probe"] for L in legs]
    rms = {n: [L["rms"][n]["error"] for L in legs if n in L["rms"]] for n in RESP}
    for L in legs:
        del L["transfer_pool"]
    return {"legs": legs, "overall": overall,
            "hs_probe": {"max_abs_error": float(max(abs(h["error"]) for h in hs)),
                         "coverage": float(np.mean([h["covered"] for h in hs]))},
            "rms_error": {n: {"median_abs": float(np.median(np.abs(v))), "max_abs": float(np.max(np.abs(v)))}
                          for n, v in rms.items() if v}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default=str(ROOT / "scenarios" / "patrol51_seakeeping.toml"))
    ap.add_argument("--timestep", type=float, default=None, help="override the scenario's time step [s]")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "seakeeping_transfer.json"))
    ap.add_argument("--keep", default=None, help="keep the run's outputs (records, report) in this folder")
    ap.add_argument("--from-results", default=None, help="summarise an existing run's output folder instead")
    a = ap.parse_args(argv)
    src = Path(a.scenario)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        path = src
        if a.timestep is not None:
            text = src.read_text()
            doc = load_toml(src)
            old = doc["scenario"]["timestep_s"]
            lines = [ln if not ln.startswith("timestep_s") else f"timestep_s = {a.timestep!r}" for ln in text.splitlines()]
            path = Path(tmp) / src.name
            path.write_text("\n".join(lines) + "\n")
            print(f"time step {old} -> {a.timestep} s")
        out = Path(a.keep) if a.keep else Path(tmp) / "out"
        if a.from_results:
            out = Path(a.from_results)
        else:
            run(path, out, plot=bool(a.keep), progress=print)
        doc = json.loads((out / "results.json").read_text())
    wall = doc["wall_time_s"] if a.from_results else time.perf_counter() - t0
    res = {"scenario": src.name, "timestep_s": doc["timestep_s"], "seed": doc["seed"], "wall_time_s": wall,
           "timings": doc["timings"], "trial_time_h": doc["agenda"]["total_time_s"] / 3600.0, **summarize(doc)}
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(res, indent=1) + "\n")
    o = res["overall"]
    for n in (*RESP, "all_responses", "head_and_station_keeping"):
        s = o.get(n, {"bins": 0})
        if s["bins"]:
            print(f"{n:14s} bins {s['bins']:4d}  median |err| {100 * s['median_abs_amp_error']:5.1f} %  max "
                  f"{100 * s['max_abs_amp_error']:5.1f} %  within 10 % {100 * s['within_10pct']:5.1f} %  amp cov "
                  f"{100 * s['amp_coverage']:5.1f} %  phase cov {100 * s['phase_coverage']:5.1f} %  sharpness "
                  f"{s['amp_sharpness']:.2f}  (random error allows {100 * s.get('expected_within_10pct', float('nan')):.1f} % "
                  f"within 10 %)")
    print(f"wall {wall:.0f} s; written {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
