"""Re-reduce a standardization campaign's kept records with the current reduction, and rescore its
spot powers, without simulating again.

A campaign run with ``--records`` keeps every replicate's records and its results.json. The
simulation does not depend on the reduction, so after a change of the spot-power reduction that leaves
the spots' speeds unchanged, the re-reduced record is exactly what a rerun would reduce, and the
spot power's reference — the true calm-water curve at the reduced spot speed — is the one stored in
results.json. This script checks that every spot speed (value and interval) is unchanged, replaces the
campaign rows of ``spots[]/power_at_equal_speed`` with the re-reduced ones (error relative to the true
power; covered when the 95 % interval holds it), keeps every other row, and writes the summary with
the campaign's own statistics (:func:`vtrials.score.coverage.verdict`, Wilson interval on the
effective number of trials).

    PYTHONPATH=. python benchmarks/rereduce_standardization_campaign.py /work/runs/ksp200c 200 \\
        --json benchmarks/results/campaign_kvlcc2_speed_power_200.json --note "..."
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

GROUP = "spots[]/power_at_equal_speed"


def rereduce(out_dir: Path, n: int):
    from vtrials.campaign.run import load_rows
    from vtrials.records.netcdf import open_record
    from vtrials.reduce.trials import reduce_standardization
    rows, _ = load_rows(out_dir, n)
    new = {}
    for i in range(n):
        rep = out_dir / "replicates" / f"replicate_{i:05d}"
        res = json.loads((rep / "results.json").read_text())
        for trial in res["trials"]:
            if trial["kind"] != "standardization":
                continue
            red = reduce_standardization(open_record(rep / trial["record"]))
            old = {s["group"]: s for s in trial["reduced"]["spots"]}
            err = {s["group"]: s for s in trial["error"]["spots"]}
            for sp in red["spots"]:
                o = old[sp["group"]]
                if sp["stw"] != o["stw"]:
                    raise SystemExit(f"replicate {i} spot {sp['group']}: the spot speed changed; rerun the campaign")
                e = err[sp["group"]].get("power_at_equal_speed")
                if e is None or e.get("truth") is None:
                    continue
                T, P = e["truth"], sp["power"]
                key = (f"{trial['name']}/spots[group={sp['group']}]/power_at_equal_speed", i)
                new[key] = {"reduced": P["value"], "std": P["std"], "lo95": P["lo95"], "hi95": P["hi95"],
                            "half_width95": (P["hi95"] - P["lo95"]) / 2 / T, "error": P["value"] / T - 1.0,
                            "covered": P["lo95"] <= T <= P["hi95"]}
    out = []
    for r in rows:
        if r["group"].endswith(GROUP):
            nr = new.get((r["quantity"], r["replicate"]))
            if nr is None or not math.isclose(nr["reduced"] / (1 + nr["error"]), r["truth"], rel_tol=1e-9):
                raise SystemExit(f"replicate {r['replicate']}: spot rows do not match the records")
            r = {**r, **nr}
        out.append(r)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("campaign_dir")
    ap.add_argument("replicates", type=int)
    ap.add_argument("--json", required=True)
    ap.add_argument("--note", default="")
    a = ap.parse_args()
    from vtrials.runner.outputs import json_clean
    from vtrials.score.coverage import verdict
    d = Path(a.campaign_dir)
    rows = rereduce(d, a.replicates)
    groups: dict[str, list] = {}
    for r in rows:
        groups.setdefault(r["group"], []).append(r)
    quantities = [{"group": g, **verdict([r["covered"] for r in rs], [r["half_width95"] for r in rs],
                                         [r["error"] for r in rs], clusters=[r["replicate"] for r in rs])}
                  for g, rs in sorted(groups.items())]
    man = json.loads((d / "manifest.json").read_text())
    doc = {"scenario": f"scenarios/{man['scenario']}", "replicates": a.replicates,
           "campaign_seed": man["campaign_seed"], "quantities": quantities, "note": a.note}
    Path(a.json).write_text(json.dumps(json_clean(doc), indent=1) + "\n")
    for q in quantities:
        print(f"{q['group']:<52} n {q['n']:5d} coverage {q['coverage']:.3f} [{q['wilson_lo']:.3f}, "
              f"{q['wilson_hi']:.3f}] sharpness {q['sharpness']:.2f} {q['verdict']}")


if __name__ == "__main__":
    main()
