"""End-to-end accuracy of the shipped trial scenarios, from fresh runs: the figures the README quotes.

Runs every shipped scenario that has an agenda (a trial day run by the crew), reads each trial's
scored ``error.summary`` from ``results.json`` and, for standardization trials, the per-spot power
error against the true calm-water curve. Writes ``benchmarks/results/accuracy.json`` and prints a
Markdown table. Nothing here is asserted; the tests check the physics and the reductions, this
reports what the shipped days give today.

    python benchmarks/accuracy_summary.py [--workers 2] [--out out/accuracy] [SCENARIO ...]
"""

from __future__ import annotations

import argparse
import json
import sys
import tomllib
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results" / "accuracy.json"
if str(ROOT) not in sys.path:  # tests.calibration (scoring-side helper) from any working directory
    sys.path.insert(0, str(ROOT))


def agenda_scenarios() -> list[Path]:
    """Shipped scenarios run by the crew (those with an ``[agenda]``)."""
    return [p for p in sorted((ROOT / "scenarios").glob("*.toml"))
            if "agenda" in tomllib.loads(p.read_text())]


def _run(scenario: str, out: str) -> dict:
    import vtrials
    vtrials.run(scenario, out, plot=False)
    res = json.loads((Path(out) / "results.json").read_text())
    trials = []
    for t in res["trials"]:
        err = t.get("error") or {}
        row = {"trial": t["name"], "kind": t["kind"], "summary": err.get("summary")}
        spots = err.get("spots")
        if spots:
            row["spot_power_error"] = [s.get("curve_error") for s in spots]
            # the same with the meters' drawn calibration errors taken out (the reduction's own share)
            from tests.calibration import drawn_meter_errors, net_of_calibration
            meters = drawn_meter_errors(Path(out) / "truth.nc")
            row["spot_power_error_net_of_meters"] = [
                None if s.get("power_at_equal_speed", {}).get("error") is None or not meters else
                net_of_calibration(s["power_at_equal_speed"]["error"], meters, r["torque"], r["rps"])
                for s, r in zip(spots, t["reduced"]["spots"])]
        trials.append(row)
    return {"scenario": Path(scenario).name, "ship": res["ship"], "simulated_h": res["simulated_time_s"] / 3600,
            "wall_s": res["wall_time_s"], "trials": trials}


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*", help="scenario files (default: every shipped agenda scenario)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=str(ROOT / "out" / "accuracy"))
    a = ap.parse_args(argv)
    scen = [Path(s) for s in a.scenarios] or agenda_scenarios()
    with ProcessPoolExecutor(a.workers) as ex:
        futs = [ex.submit(_run, str(s), str(Path(a.out) / s.stem)) for s in scen]
        rows = [f.result() for f in futs]
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(rows, indent=1) + "\n")
    print("| scenario | trial | kind | summary |\n|---|---|---|---|")
    for r in rows:
        for t in r["trials"]:
            s = t["summary"] or {}
            text = ", ".join(f"{k} = {_fmt(v)}" for k, v in s.items())
            if t.get("spot_power_error"):
                pe = [e for e in t["spot_power_error"] if e is not None]
                text += f"; spot power error {min(pe):+.2%} … {max(pe):+.2%}" if pe else ""
                pn = [e for e in t.get("spot_power_error_net_of_meters") or [] if e is not None]
                text += f" (net of the meters' calibration {min(pn):+.2%} … {max(pn):+.2%})" if pn else ""
            print(f"| {r['scenario']} | {t['trial']} | {t['kind']} | {text} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
