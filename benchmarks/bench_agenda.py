"""Agenda benchmark (not a test): a full standardization trial day — crew, instruments, records,
reductions, scoring, report — timed stage by stage on one core.

Default: scenarios/patrol51_standardization.toml (8 spots x 3 runs, ~6 simulated hours). The target
of issue 5 is under 60 s wall time for the whole day. Also reports the real-time factor.

Usage: python benchmarks/bench_agenda.py [SCENARIO] [--out DIR] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time

from vtrials.scenario import load_scenario
from vtrials.runner.trial_day import simulate_agenda, write_agenda_outputs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", nargs="?", default="scenarios/patrol51_standardization.toml")
    ap.add_argument("--out", help="output directory (default: a temporary one)")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    # load once first so the numba kernels are compiled / loaded before timing
    t0 = time.perf_counter()
    scn = load_scenario(a.scenario)
    from vtrials.physics.simulator import Simulator
    Simulator(scn.vessel, 1, scn.head.timestep_s).evaluate()
    t_load = time.perf_counter() - t0
    out = a.out or tempfile.mkdtemp(prefix="vtrials_bench_")
    t0 = time.perf_counter()
    res = simulate_agenda(scn)
    doc = write_agenda_outputs(res, out, plot=True)
    total = time.perf_counter() - t0
    fig = {"scenario": a.scenario, "runs": len(res.attempts), "trial_time_h": res.simulated_time_s / 3600,
           "wall_total_s": total, "real_time_factor": res.simulated_time_s / total, "load_s": t_load,
           **{k: v for k, v in res.timings.items()}}
    sim_only = res.timings["simulate_s"] - res.timings["instruments_s"]
    fig["instrument_share_of_simulation"] = res.timings["instruments_s"] / sim_only
    print(f"{a.scenario}: {fig['runs']} runs, {fig['trial_time_h']:.2f} h of trial time in {total:.1f} s wall "
          f"({fig['real_time_factor']:.0f}x real time; target < 60 s)")
    for k, v in res.timings.items():
        print(f"  {k:<16} {v:6.2f} s")
    print(f"  instruments add {100 * fig['instrument_share_of_simulation']:.1f} % to the simulation and crew cost "
          f"(simulate_s includes them)")
    for tr in doc["trials"]:
        print(f"  {tr['name']}: " + ", ".join(f"{k} {v:.4g}" for k, v in tr["error"]["summary"].items()
                                              if isinstance(v, (int, float))))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(fig, f, indent=2)


if __name__ == "__main__":
    main()
