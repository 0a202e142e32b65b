"""How far the trials team's design-stage RAO model is from the simulator's truth (patrol51; --ship kvlcc2).

Truth: :class:`vtrials.truth.motion_rao.TruthRAO` (the coupled six-DOF model the simulator integrates).
Design: :class:`vtrials.reduce.design_rao.DesignRAO` (models/patrol51/design). Compared per speed and
heading: the RMS heave, roll and pitch at O in a long-crested JONSWAP sea (γ 3.3) of H_s 2 m at T_p
6, 8 and 10 s (the truth's quadratic roll damping linearised at its own roll-rate std), and the peak
|RAO| over 0.25-2.5 rad/s. Writes benchmarks/results/design_rao_vs_truth.json and prints a Markdown table.

    PYTHONPATH=. python benchmarks/design_rao_vs_truth.py [--ship kvlcc2 --speeds 4,7 --tps 8,10,12]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

from vtrials.physics.environment.waves import peak_frequency, spectrum
from vtrials.reduce.design_rao import load_design_rao
from vtrials.truth.motion_rao import TruthRAO

OUT = Path(__file__).resolve().parent / "results" / "design_rao_vs_truth.json"
SPEEDS = (3.0, 6.0)
HEADINGS_DEG = (180.0, 135.0, 90.0, 45.0, 0.0)
TPS = (6.0, 8.0, 10.0)
HS = 2.0
NAMES = ("heave", "roll", "pitch")


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--ship", default="patrol51")
    ap.add_argument("--speeds", default=",".join(str(v) for v in SPEEDS))
    ap.add_argument("--tps", default=",".join(str(v) for v in TPS))
    a = ap.parse_args(argv)
    ship = a.ship
    speeds = [float(v) for v in a.speeds.split(",")]
    tps = [float(v) for v in a.tps.split(",")]
    out_path = OUT if ship == "patrol51" else OUT.with_name(f"design_rao_vs_truth_{ship}.json")
    design = load_design_rao(ship)
    w = np.linspace(0.25, 2.5, 600) if ship == "patrol51" else np.linspace(0.12, 1.4, 600)
    rows = []
    for U in speeds:
        tr = TruthRAO(ship, U)
        for hd in HEADINGS_DEG:
            mu = math.radians(hd)
            D = design.rao(w, mu, tr.U)
            for tp in tps:
                S = spectrum("jonswap", w, HS, peak_frequency("jonswap", 3.3, tp=tp), 3.3)
                sp = tr.roll_rate_std(w, S, mu)
                T = tr.rao(w, mu, sp)
                row = {"U": tr.U, "mu_deg": hd, "tp": tp, "hs": HS, "sigma_p_truth": sp}
                for k, n in enumerate(NAMES):
                    rt = math.sqrt(float(np.trapezoid(np.abs(T[k]) ** 2 * S, w)))
                    rd = math.sqrt(float(np.trapezoid(np.abs(D[k]) ** 2 * S, w)))
                    row[f"{n}_rms_truth"] = rt
                    row[f"{n}_rms_design"] = rd
                    row[f"{n}_rms_diff_pct"] = 100.0 * (rd / rt - 1.0) if rt > 1e-9 else None
                    pt, pd = float(np.max(np.abs(T[k]))), float(np.max(np.abs(D[k])))
                    row[f"{n}_peak_truth"] = pt
                    row[f"{n}_peak_design"] = pd
                rows.append(row)
                print(json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in row.items()}), flush=True)
    out = {"ship": ship, "design_file": str(design.path.relative_to(Path(__file__).resolve().parents[1])),
           "hs": HS, "tps": tps, "rows": rows}
    out_path.write_text(json.dumps(out, indent=1))
    print("\n| U [m/s] | μ [deg] | T_p [s] | heave RMS | roll RMS | pitch RMS |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        f = [("—" if r[f"{n}_rms_diff_pct"] is None or r[f"{n}_rms_truth"] < 1e-4 else f"{r[f'{n}_rms_diff_pct']:+.0f} %")
             for n in NAMES]
        print(f"| {r['U']:.1f} | {r['mu_deg']:.0f} | {r['tp']:.0f} | {f[0]} | {f[1]} | {f[2]} |")
    return out


if __name__ == "__main__":
    main()
