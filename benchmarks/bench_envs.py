"""Throughput of the gymnasium environments (issue 15 acceptance).

For N = 1, 16, 64, 256 ships: the native vector env (ShipVectorEnv: N ships in one mujoco.batch, one
force-kernel call per time step, vectorised observations), a bare ``mujoco.batch`` loop of the same
MJCF model (no forces, no environment layer) over the same number of time steps, and gymnasium's
SyncVectorEnv of the scalar env (N copies, each its own one-ship batch). Rates are ship time steps
per second (physics steps × ships) and environment steps per second (control periods × ships), and
the simulator alone (Simulator.step of the env's batch, no env layer) to split the cost; the
ratio to the bare batch is the acceptance figure (target ≥ 50 % at N = 256). Rounds of the three
are interleaved and medians reported: the machine may be shared (the 1-minute load average before
and after is written with the results).

    python benchmarks/bench_envs.py [--ship patrol51] [--task CourseKeeping] [--sea wind_current]
                                    [--nthread 2] [--seconds 1] [--rounds 5] [--sync-max 64]
                                    [--cpu-time] [--json out.json]

``--cpu-time`` (with ``--nthread 1``) times by the thread's CPU time instead of the wall clock: on a
loaded machine the ratios then stay those of the code, not of the scheduler.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402


CLOCK = time.perf_counter  # --cpu-time: the thread's CPU time (a shared machine; one thread only)


def _rate(fn, seconds):
    """Calls of fn per second over about ``seconds``."""
    k, t0 = 0, CLOCK()
    while True:
        fn()
        k += 1
        dt = CLOCK() - t0
        if dt >= seconds:
            return k / dt


def bench_size(ship, task, sea, n, nthread, seconds, rounds, sync):
    """Interleaved rounds (vector env, bare batch, SyncVectorEnv), so that the load of a shared machine
    hits all alike; returns the medians over the rounds."""
    import gymnasium as gym
    from mujoco import batch as mjbatch
    from vtrials.envs.ship_env import ShipEnv
    from vtrials.envs.vector import ShipVectorEnv
    venv = ShipVectorEnv(n, task, ship, sea=sea, nthread=nthread)
    venv.reset(seed=0)
    act = np.zeros((n,) + venv.single_action_space.shape, dtype=np.float32)
    venv.step(act)  # warm-up (kernel compiled or loaded from the cache)
    sub = venv.core.substeps
    nth = venv.core.sim.batch.nthread if hasattr(venv.core.sim.batch, "nthread") else (nthread if n >= 8 else 1)
    bare = mjbatch.Batch(venv.core.sim.model, n, nthread=nth)
    sim = venv.core.sim

    def bare_period():
        for _ in range(sub):
            bare.step()

    senv = None
    if sync:
        senv = gym.vector.SyncVectorEnv([lambda: ShipEnv(task, ship, sea=sea) for _ in range(n)])
        senv.reset(seed=0)
        senv.step(act)
    rv, rb, rs, rp = [], [], [], []
    for _ in range(rounds):
        rv.append(_rate(lambda: venv.step(act), seconds) * n)  # env steps/s (ship control periods)
        rb.append(_rate(bare_period, seconds) * n)
        rp.append(_rate(lambda: sim.step(sub), seconds) * n)  # the simulator alone (physics of the env)
        if senv is not None:
            rs.append(_rate(lambda: senv.step(act), seconds) * n)
    med = lambda x: float(np.median(x)) if x else float("nan")  # noqa: E731
    ratio = med([v / b for v, b in zip(rv, rb)])
    return {"N": n, "substeps": sub, "vector_env_steps_per_s": med(rv), "vector_ship_steps_per_s": med(rv) * sub,
            "bare_batch_ship_steps_per_s": med(rb) * sub, "vector_over_bare": ratio,
            "simulator_ship_steps_per_s": med(rp) * sub, "simulator_over_bare": med([p / b for p, b in zip(rp, rb)]),
            "vector_over_simulator": med([v / p for v, p in zip(rv, rp)]),
            "sync_env_steps_per_s": med(rs), "vector_over_sync": med(rv) / med(rs) if rs else float("nan")}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="patrol51")
    ap.add_argument("--task", default="CourseKeeping")
    ap.add_argument("--sea", default="wind_current")
    ap.add_argument("--nthread", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--seconds", type=float, default=1.0, help="length of one timed round")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--sizes", default="1,16,64,256")
    ap.add_argument("--sync-max", type=int, default=64, help="largest N run through SyncVectorEnv")
    ap.add_argument("--cpu-time", action="store_true",
                    help="rates by the thread's CPU time, robust on a loaded machine (needs --nthread 1)")
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    if a.cpu_time:
        if a.nthread != 1:
            ap.error("--cpu-time needs --nthread 1 (other threads' time is not counted)")
        global CLOCK
        CLOCK = time.thread_time
    load_before = os.getloadavg()[0]
    rows = []
    print(f"{a.ship} {a.task} sea={a.sea} nthread={a.nthread}{' (CPU time)' if a.cpu_time else ''}")
    print(f"{'N':>5} {'vec env steps/s':>16} {'vec ship-steps/s':>17} {'bare batch':>12} {'vec/bare':>9} "
          f"{'sim/bare':>9} {'vec/sim':>8} {'sync env steps/s':>17} {'vec/sync':>9}")
    for n in [int(x) for x in a.sizes.split(",")]:
        row = bench_size(a.ship, a.task, a.sea, n, a.nthread, a.seconds, a.rounds, n <= a.sync_max)
        rows.append(row)
        print(f"{n:>5} {row['vector_env_steps_per_s']:>16.0f} {row['vector_ship_steps_per_s']:>17.0f} "
              f"{row['bare_batch_ship_steps_per_s']:>12.0f} {row['vector_over_bare']:>9.2f} "
              f"{row['simulator_over_bare']:>9.2f} {row['vector_over_simulator']:>8.2f} "
              f"{row['sync_env_steps_per_s']:>17.0f} {row['vector_over_sync']:>9.2f}", flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps({"ship": a.ship, "task": a.task, "sea": a.sea, "nthread": a.nthread,
                                            "clock": "thread CPU time" if a.cpu_time else "wall",
                                            "load_average_1min": [load_before, os.getloadavg()[0]],
                                            "cpus": os.cpu_count(), "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
