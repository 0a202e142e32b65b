"""Study: seed 004 (Stredulinsky & Thornhill, DRDC Atlantic TM 2009) — wave radar and ship-motion fusion.

Published (../shared/seeds/004_wave_radar_ship_motion_fusion.txt: executive summary, sections 4.1 and 4.5;
the report's tables are not in the seed copy): on CFAV QUEST (trial Q293, star patterns, H_s 1.3–5 m) the
WaMoS II radar's H_s scattered about the buoys' with a standard deviation of 0.23 even after recalibration;
fusing the radar spectrum with measured ship motions through the ShipMo7 strip-theory RAOs (H_s scaled
by the mean ratio of measured to predicted motion RMS, eqs. 1–5) put H_s within ±15 % of the buoys for
most runs above 2.5 m and cut the scatter by a factor of three or more; heave displacement with pitch
was the best combination; roll (and the bow's relative motion) compared poorly with prediction and was
not used. On HMCS KINGSTON a commercial ship-as-a-wave-buoy algorithm performed very poorly.

Ours: the campaigns of benchmarks/campaign_wavefusion.py (patrol51 25-min and 10-min legs, KVLCC2 10-min
legs), read from benchmarks/results/ — no new simulation. The scatter reduction is given with a
bootstrap 95 % interval over the campaign's cases (each case is one star pattern in one sea; its legs
are not independent).

    python benchmarks/study_seed004.py      # writes benchmarks/results/studies/seed004.md and .json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
CAMPAIGNS = (("patrol51, 25-min legs", "campaign_wavefusion.json"),
             ("patrol51, 10-min legs", "campaign_wavefusion_10min.json"),
             ("KVLCC2, 10-min legs", "campaign_wavefusion_kvlcc2.json"))
N_BOOT = 2000


def _reduction(rows, combo: str) -> float:
    rad = np.array([r["radar_ratio"] for r in rows])
    fus = np.array([r["fused_ratio"][combo] for r in rows])
    return float(np.std(rad, ddof=1) / np.std(fus, ddof=1))


def scatter_reduction(rows, combo: str, rng) -> tuple[float, float, float]:
    """std(radar/true) / std(fused/true) over the legs, and its bootstrap 95 % interval over cases (seeds)."""
    seeds = sorted({r["seed"] for r in rows})
    by = {s: [r for r in rows if r["seed"] == s] for s in seeds}
    boot = []
    for _ in range(N_BOOT):
        pick = rng.integers(0, len(seeds), len(seeds))
        boot.append(_reduction([r for k in pick for r in by[seeds[k]]], combo))
    lo, hi = np.quantile(boot, [0.025, 0.975])
    return _reduction(rows, combo), float(lo), float(hi)


def analyse(rows, rng) -> dict:
    combos = list(rows[0]["fused_ratio"])
    hs = np.array([r["hs_true"] for r in rows])
    rad = np.array([r["radar_ratio"] for r in rows])
    out = {"legs": len(rows), "cases": len({r["seed"] for r in rows}), "above_2.5m": int(np.sum(hs > 2.5)),
           "radar": {"mean": float(rad.mean()), "std": float(np.std(rad, ddof=1)),
                     "within_15pct_above_2.5m": int(np.sum((np.abs(rad - 1) <= 0.15) & (hs > 2.5)))},
           "combos": {}}
    for c in combos:
        f = np.array([r["fused_ratio"][c] for r in rows])
        red, lo, hi = scatter_reduction(rows, c, rng)
        out["combos"][c] = {"mean": float(f.mean()), "std": float(np.std(f, ddof=1)), "reduction": red,
                            "reduction_ci95": [lo, hi],
                            "within_15pct_above_2.5m": int(np.sum((np.abs(f - 1) <= 0.15) & (hs > 2.5)))}
    for key in ("buoy", "star_buoy"):
        b = [r[key] for r in rows if "hs_err" in r.get(key, {})]
        if b:
            he = np.array([x["hs_err"] for x in b])
            de = np.array([abs(x["dir_err_deg"]) for x in b])
            out[key] = {"legs": len(b), "hs_within_15pct": int(np.sum(np.abs(he) <= 0.15)),
                        "dir_within_15deg": int(np.sum(de <= 15.0)), "side_right": int(sum(x["side_right"] for x in b)),
                        "hs_err_mean": float(he.mean()), "dir_abs_err_median_deg": float(np.median(de))}
    return out


def _fmt_red(c: dict) -> str:
    return f"{c['reduction']:.1f}× [{c['reduction_ci95'][0]:.1f}, {c['reduction_ci95'][1]:.1f}]"


def report(res: dict) -> str:
    p25, p10, kv = (res[name] for name, _ in CAMPAIGNS)
    hp = p25["combos"]["heave+pitch"]
    ranked = sorted(p25["combos"].items(), key=lambda kv_: -kv_[1]["reduction"])
    best_pair = max(((k, v) for k, v in p25["combos"].items() if "+" in k), key=lambda kv_: kv_[1]["reduction"])
    roll = p25["combos"]["roll"]
    L = ["# Study: seed 004 — wave radar and ship-motion fusion (Stredulinsky & Thornhill, DRDC Atlantic)", "",
         "Reproduces the findings of seed 004 with the star-pattern campaigns of `benchmarks/campaign_wavefusion.py` "
         "(`benchmarks/study_seed004.py` reads their results; scatter reductions with bootstrap 95 % intervals over "
         "the campaign's cases).", "",
         "## Set-up", "",
         "* Star patterns of four legs (head, starboard bow, port bow, following) in Pierson–Moskowitz cos-2s seas "
         "(s = 10) of H_s 1.5–5 m, T_p from the NATO sea-state table; patrol51 at \"standard\" (≈ 9 m/s), 16 cases of "
         "25-min and of 10-min legs; KVLCC2 at ahead 2/3, 8 cases of 10-min legs.",
         "* The X-band radar recalibrated as seed 004's reprocessed data (H_s scatter sd 0.23 about the truth: an input "
         "of the instrument model, not a finding); heave (strapdown), pitch, roll and vertical acceleration from "
         "the motion package; the team's design-stage RAOs (Capytaine on the coarsest mesh, models/<ship>/design), "
         "not the simulator's; scored against the true sea's H_s (no buoy in between: seed 004's reference "
         "buoys themselves scattered by about half its fused scatter).", "",
         "## Published findings and ours", "",
         "| Published (seed 004, QUEST) | Ours | Reproduced |", "|---|---|---|",
         f"| Radar H_s scatter, sd 0.23 of radar/buoy after recalibration | radar/true sd {p25['radar']['std']:.3f} "
         f"(the instrument model's input) | — |",
         f"| Fusion cuts the radar's scatter by a factor of three or more | heave + pitch: patrol51 25-min "
         f"{_fmt_red(hp)}; 10-min {_fmt_red(p10['combos']['heave+pitch'])}; KVLCC2 10-min "
         f"{_fmt_red(kv['combos']['heave+pitch'])} | patrol51 yes; KVLCC2 no (2–3×) |",
         f"| Fused H_s within ±15 % for most runs above 2.5 m | patrol51 25-min {hp['within_15pct_above_2.5m']}/"
         f"{p25['above_2.5m']} (radar alone {p25['radar']['within_15pct_above_2.5m']}); 10-min "
         f"{p10['combos']['heave+pitch']['within_15pct_above_2.5m']}/{p10['above_2.5m']}; KVLCC2 "
         f"{kv['combos']['heave+pitch']['within_15pct_above_2.5m']}/{kv['above_2.5m']} | yes |",
         f"| Heave displacement with pitch is the best combination | best pair here {best_pair[0]} "
         f"({_fmt_red(best_pair[1])}); best of all {ranked[0][0]} ({_fmt_red(ranked[0][1])}); heave + pitch "
         f"{_fmt_red(hp)} | partly: heave + pitch is the best pair, pitch alone is as good here |",
         f"| Roll compares poorly with prediction and is not used | roll alone {_fmt_red(roll)} (mean "
         f"{roll['mean']:.2f}): it adds scatter | yes |",
         f"| Fused mean about 1.00 (0.97 with the other buoy's spectra) | heave + pitch mean {hp['mean']:.3f} "
         f"(the design model's heave and pitch are high by +5…+19 % and +1…+14 %) | no: a design-model bias |",
         f"| A ship-as-a-wave-buoy algorithm performed very poorly (KINGSTON) | patrol51 leg by leg (one leg at a time, "
         f"roll telling the side): direction within 15° on {_ship_leg(p25)}; one sea fitted to each star's legs "
         f"(the headings telling the side): {_star(p25)}; KVLCC2 star: {_star(kv)} | (context) |", "",
         "## Per component and pair (std of fused/true over the legs; scatter reduction = radar std / fused std)", ""]
    for name, _ in CAMPAIGNS:
        r = res[name]
        L += [f"### {name} ({r['legs']} legs, {r['cases']} cases, {r['above_2.5m']} above 2.5 m)", "",
              "| input | mean | std | scatter reduction [95 %] | within ±15 % above 2.5 m |", "|---|---|---|---|---|",
              f"| radar alone | {r['radar']['mean']:.3f} | {r['radar']['std']:.3f} | 1 | "
              f"{r['radar']['within_15pct_above_2.5m']} |"]
        for c, v in r["combos"].items():
            L.append(f"| {c} | {v['mean']:.3f} | {v['std']:.3f} | {_fmt_red(v)} | {v['within_15pct_above_2.5m']} |")
        L.append("")
    L += ["## Notes", "",
          "* Seed 004 scored against buoys whose own H_s scattered (its Figure 4); here the truth is the simulated "
          "sea's, so our fused scatter is the method's and the design model's alone.",
          "* KVLCC2 (320 m) in these seas barely heaves and pitches to the short waves, and its design model's "
          "errors weigh more: the reduction falls to 2–3×.", ""]
    return "\n".join(L)


def _ship_leg(r: dict) -> str:
    b = r.get("buoy")
    return f"{b['dir_within_15deg']}/{b['legs']} legs, H_s within 15 % on {b['hs_within_15pct']}" if b else "n/a"


def _star(r: dict) -> str:
    b = r.get("star_buoy")
    return (f"H_s within 15 % on {b['hs_within_15pct']}/{b['legs']} legs, direction within 15° on "
            f"{b['dir_within_15deg']}/{b['legs']}" if b else "n/a")


def main(argv=None) -> int:
    rng = np.random.default_rng(4004)
    res = {}
    for name, f in CAMPAIGNS:
        rows = json.loads((RESULTS / f).read_text())["rows"]
        res[name] = analyse(rows, rng)
    out = RESULTS / "studies"
    out.mkdir(exist_ok=True)
    (out / "seed004.json").write_text(json.dumps(res, indent=1))
    (out / "seed004.md").write_text(report(res))
    print(report(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
