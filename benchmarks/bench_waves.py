"""Seakeeping benchmark (not a test): one patrol51 at its production step (0.02 s) self-propelled at
7 m/s, calm water against the same ship with the seakeeping components (radiation states and first-
order excitation) in a JONSWAP sea of n components, in one run; several n to show the cost per
component. Issue 10's target: ≥ 1000× real time with 100 components; cost linear in components.

The cost per component is the least-squares slope of the step time over the wave cases (its
linearity: the largest residual of that line). The load average of the machine (1 min) is recorded
before and after.

Usage: python benchmarks/bench_waves.py [--seconds 600] [--repeats 3] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time

import numpy as np

from vtrials.physics.environment.waves import Waves, realize
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.timedomain import seakeeping_vessel
from vtrials.physics.simulator import Simulator
from vtrials.physics.vessel import load_vessel, model_dir

DT = 0.02


def _time(sim, state, seconds, repeats):
    """Wall time of ``seconds`` simulated from ``state``: the shortest of ``repeats`` runs (the machine
    may be shared; the shortest is the least disturbed), and the number of steps."""
    n = int(round(seconds / DT))
    best = math.inf
    for _ in range(repeats):
        sim.set_state(0, state)
        sim.step(50)                         # compile / warm
        sim.clear_truth()
        t0 = time.perf_counter()
        sim.step(n)
        best = min(best, time.perf_counter() - t0)
        sim.clear_truth()
    return best, n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=600.0, help="simulated seconds per case")
    ap.add_argument("--repeats", type=int, default=3, help="runs per case; the shortest counts")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    load_before = os.getloadavg()[0]
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    model = memory_model(db)
    calm = Simulator(ves, 1, DT)
    state = calm.self_propulsion(0, 7.0)
    rows = []
    wall, n = _time(calm, state, a.seconds, a.repeats)
    rows.append({"case": "calm", "components": 0, "radiation_states": 0, "us_per_step": 1e6 * wall / n,
                 "real_time_factor": a.seconds / wall})
    for nc in (25, 50, 100, 200):
        field = realize(Waves(spectrum="jonswap", hs_m=1.0, tp_s=7.0, n_components=nc, direction_deg=0.0),
                        float("inf"), np.random.default_rng(1))
        comp = field.components[(field.components[:, 1] >= db.omega[0] * 0.5) & (field.components[:, 1] <= db.omega[-1])]
        v2, _ = seakeeping_vessel(ves, db, comp, DT, model=model)
        sim = Simulator(v2, 1, DT)
        wall, n = _time(sim, state, a.seconds, a.repeats)
        rows.append({"case": "waves", "components": int(comp.shape[0]), "radiation_states": model.n_states,
                     "us_per_step": 1e6 * wall / n, "real_time_factor": a.seconds / wall})
    for r in rows:
        print(f"{r['case']:6s} components {r['components']:4d}  radiation states {r['radiation_states']:3d}  "
              f"{r['us_per_step']:8.2f} µs/step  {r['real_time_factor']:8.0f}× real time")
    wv = [r for r in rows if r["case"] == "waves"]
    nc = np.array([r["components"] for r in wv], dtype=float)
    us = np.array([r["us_per_step"] for r in wv])
    slope, icpt = np.polyfit(nc, us, 1)
    resid = float(np.max(np.abs(us - (icpt + slope * nc)) / us))
    fit = {"us_per_component_step": float(slope), "us_per_step_at_zero_components": float(icpt),
           "largest_relative_residual": resid, "calm_us_per_step": rows[0]["us_per_step"],
           "load_average_1min": [load_before, os.getloadavg()[0]], "cpus": os.cpu_count(),
           "simulated_seconds": a.seconds, "repeats": a.repeats}
    print(f"cost per component {slope:.4f} µs/step (line through the wave cases: {icpt:.2f} µs at 0 components, "
          f"largest residual {100 * resid:.1f} %); load average {fit['load_average_1min']}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"rows": rows, "fit": fit}, f, indent=1)


if __name__ == "__main__":
    main()
