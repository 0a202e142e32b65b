"""Instrument benchmark (not a test): the cost of sampling a ship's full instrument suite at 20 Hz,
as a ratio to the simulation cost of the same stretch, measured in the same run.

The patrol vessel (21 instruments: range radar, DGPS, LORAN, knotmeter, EM and Doppler logs, gyro,
vertical gyro, IMU, two anemometers, torque/r/min/thrust/pitch per shaft, two rudder synchros) runs
with gusty wind at dt = 0.05 s, truth recorded every step (20 Hz, the stream the instruments sample).
The instruments then process that truth in 600-s chunks (how the crew streams the instruments it is
not watching) and, for comparison, 60-s and 10-s chunks (each call has a fixed cost of ~0.4 ms per
instrument). benchmarks/bench_agenda.py reports the share inside a whole trial day, where the
director's displays are also flushed at every look.

Usage: python benchmarks/bench_instruments.py [--seconds 1800] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from vtrials.instruments.suite import InstrumentSet
from vtrials.scenario import environment_block as _environment
from vtrials.scenario import load_scenario
from vtrials.physics.simulator import Simulator
from vtrials.truth.columns import ship_columns

SCENARIO = "scenarios/patrol51_standardization.toml"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=1800.0, help="simulated seconds (default 1800)")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    scn = load_scenario(SCENARIO)
    dt = 0.05
    n = int(a.seconds / dt)
    sim = Simulator(scn.vessel, 1, dt, _environment(scn), record_every=1)
    sim.steady_at_order(0, (450 / 60,) * 2, (1.22,) * 2, heading=0.8)
    sim.step(200)  # warm-up (and JIT load)
    sim.clear_truth()
    t0 = time.perf_counter()
    sim.step(n)
    t_sim = time.perf_counter() - t0
    cols = {k: np.ascontiguousarray(v) for k, v in ship_columns(sim.truth(), sim.rec_names, 0, sim.dt).items()}
    rows = cols["t"].size
    out = {"simulated_s": a.seconds, "truth_rate_hz": 1 / dt, "rows": rows, "instruments": None,
           "simulation_wall_s": t_sim, "chunks": {}}
    for chunk_s in (600.0, 60.0, 10.0):
        iset = InstrumentSet(scn.vessel, 1, scn.site, scn.instrument_items, SCENARIO)
        iset.reset()
        out["instruments"] = len(iset.devices)
        k = int(chunk_s / dt)
        t0 = time.perf_counter()
        for i in range(0, rows, k):
            iset.process({c: v[i:i + k] for c, v in cols.items()})
        t_ins = time.perf_counter() - t0
        out["chunks"][f"{chunk_s:g}s"] = {"wall_s": t_ins, "ratio_to_simulation": t_ins / t_sim}
    print(f"{out['instruments']} instruments, {a.seconds:.0f} s at {1 / dt:.0f} Hz: simulation {t_sim:.2f} s wall")
    for k, v in out["chunks"].items():
        print(f"  instruments, {k:>33} chunks: {v['wall_s']:.2f} s = {100 * v['ratio_to_simulation']:.1f} % of the "
              f"simulation cost")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=2)


if __name__ == "__main__":
    main()
