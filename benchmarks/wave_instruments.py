"""Wave instruments against the true sea (issue 13): a benchmark over seeds and sea states.

* Directional buoy (moored Datawell-like ``directional_waverider``, drifting ``triaxys_drifting_buoy``,
  heave–pitch–roll ``hpr_discus_buoy``): per 30-min report, the mean direction and the circular spread σ₁
  by each method (the coefficients' own bulk values, MLM, IMLM, MEM, EMEP) against the seaway's components
  over the same band (:mod:`vtrials.score.waves`), and H_s against the band truth and against the true
  surface of the same window. Acceptance (issue 13): direction within 10°, spreading within 20 %.
* Wave radar (``wave_radar_recalibrated``, ``wave_radar_trial_calibration``): the 25-min run mean of the
  2-min H_s over the seaway's H_s, over independent installations/trials (seed 004: 1.04 / 0.23 and 1.51).

Writes ``benchmarks/results/wave_instruments.json`` and prints a Markdown table. Nothing is asserted here
(tests/test_wave_buoy.py and tests/test_wave_radar.py assert the physics on a few cases).

    python benchmarks/wave_instruments.py [--seeds 8] [--records 2] [--radar-draws 400]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from vtrials.instruments.suite import load_catalogue  # noqa: E402
from vtrials.instruments.wave_sensors import WaveBuoy, WaveRadar  # noqa: E402
from vtrials.physics.environment.waves import Waves, realize  # noqa: E402
from vtrials.reduce.directional import FourierCoefficients  # noqa: E402
from vtrials.score.waves import METHODS, score_buoy_reports, summarise  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results" / "wave_instruments.json"
SEAS = {  # name: Waves keywords (directions the waves come FROM, degrees)
    "wind sea s=10": dict(hs_m=2.5, tp_s=10.0, direction_deg=30.0, spreading_s=10.0),
    "broad s=4": dict(hs_m=2.0, tp_s=8.0, direction_deg=200.0, spreading_s=4.0),
    "swell-like s=25": dict(hs_m=3.0, tp_s=12.0, direction_deg=300.0, spreading_s=25.0),
    "Mitsuyasu s_max=10": dict(hs_m=3.5, tp_s=9.0, direction_deg=120.0, spreading="mitsuyasu", spreading_s=10.0),
    "sea + swell": dict(hs_m=2.0, tp_s=7.0, direction_deg=60.0, spreading_s=10.0, swell_hs_m=1.5, swell_tp_s=13.0,
                        swell_direction_deg=100.0, swell_spreading_s=25.0),
}
BUOYS = ("directional_waverider", "triaxys_drifting_buoy", "hpr_discus_buoy")


def buoy_rows(entry: str, sea: dict, seed: int, records: int) -> list[dict]:
    field = realize(Waves(**sea), math.inf, np.random.default_rng(seed))
    d = WaveBuoy("buoy", dict(load_catalogue()[entry]), "sea", np.zeros(3), {"site": {"range_center": [0.0, 0.0]}})
    d.attach_sea(field)
    d.reset(np.random.default_rng(10_000 + seed))
    t, ch = d.process({"t": np.arange(0.0, records * d.record + 5.0, 1.0)})
    meta = d.meta()
    om = np.array(meta["omega_rad_s"])
    reps = [FourierCoefficients(om, ch["S"][i], ch["a1"][i], ch["b1"][i], ch["a2"][i], ch["b2"][i], meta["welch_dof"])
            for i in range(t.size)]
    pos = (lambda tt: d.position_at(tt)[0], lambda tt: d.position_at(tt)[1])
    return score_buoy_reports(t, reps, field, d.record, position=pos)


def radar_ratios(entry: str, draws: int, n_spectra: int = 12) -> np.ndarray:
    field = realize(Waves(**SEAS["wind sea s=10"]), math.inf, np.random.default_rng(1))
    hs_sea = 4.0 * math.sqrt(0.5 * float(np.sum(field.components[:, 0] ** 2)))
    out = []
    t = np.arange(0.0, (n_spectra + 2) * 120.0, 1.0)
    for k in range(draws):
        d = WaveRadar("radar", dict(load_catalogue()[entry]), "sea", np.zeros(3), {})
        d.attach_sea(field)
        d.reset(np.random.default_rng(50_000 + k))
        _, ch = d.process({"t": t})
        out.append(float(np.mean(ch["hs"][:n_spectra])) / hs_sea)
    return np.array(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--records", type=int, default=2, help="30-min reports per seed")
    ap.add_argument("--radar-draws", type=int, default=400)
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    res = {"buoys": {}, "radar": {}, "settings": vars(a)}
    for entry in BUOYS:
        per_sea = {}
        allrows = []
        for name, sea in SEAS.items():
            rows = []
            for seed in range(a.seeds):
                rows += buoy_rows(entry, sea, seed, a.records)
            per_sea[name] = summarise(rows)
            allrows += rows
        res["buoys"][entry] = {"all": summarise(allrows), "per_sea": per_sea}
    for entry in ("wave_radar_recalibrated", "wave_radar_trial_calibration"):
        r = radar_ratios(entry, a.radar_draws)
        res["radar"][entry] = {"run_mean_ratio_mean": float(r.mean()), "run_mean_ratio_sd": float(r.std(ddof=1)),
                               "draws": int(r.size)}
    res["wall_s"] = time.perf_counter() - t0
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(res, indent=1) + "\n")
    print("| buoy | method | mean abs dir. error [deg] | max [deg] | spread error mean ± sd | max abs | within 10°/20 % |")
    print("|---|---|---|---|---|---|---|")
    for entry, v in res["buoys"].items():
        for m in METHODS:
            s = v["all"][m]
            print(f"| {entry} | {m} | {s['direction_abs_mean_deg']:.1f} | {s['direction_abs_max_deg']:.1f} | "
                  f"{100 * s['spread_error_mean']:+.1f} ± {100 * s['spread_error_sd']:.1f} % | "
                  f"{100 * s['spread_abs_max']:.0f} % | {100 * s['fraction_within']:.0f} % of {s['n']} |")
        h = v["all"]["hs"]
        hw = v["all"].get("hs_window", {})
        print(f"| {entry} | H_s | vs band truth {100 * h['error_mean']:+.1f} ± {100 * h['error_sd']:.1f} %; "
              f"vs window truth {100 * hw.get('error_mean', math.nan):+.1f} ± {100 * hw.get('error_sd', math.nan):.1f} % |||||")
    for entry, v in res["radar"].items():
        print(f"radar {entry}: run-mean H_s ratio {v['run_mean_ratio_mean']:.3f} ± {v['run_mean_ratio_sd']:.3f} "
              f"({v['draws']} draws)")
    print(f"wall {res['wall_s']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
