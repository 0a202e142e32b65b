"""Simulation-core benchmark (not a test): cost ratios measured in one run on this machine.

Reports
  1. per-step cost of the full 6-DOF ship (force model, helm running a zig-zag, governor, steering
     gear, truth recording every step) against a bare ``mj_step`` loop of the same MJCF;
  2. the real-time factor of one full-scale KVLCC2 at the production time step;
  3. aggregate ship-steps/s at N = 1, 16, 100 ships in one batch;
  4. a time-step study that justifies the production steps (metric change when the step is halved).

Usage: python benchmarks/bench_core.py [--ship kvlcc2] [--quick] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
import time

import mujoco
import numpy as np

from vtrials.physics import steering as H
from vtrials.truth import metrics as TM
from vtrials.physics.simulator import Simulator
from vtrials.truth.columns import ship_columns
from vtrials.units import froude_to_speed, kn_to_mps
from vtrials.physics.vessel import load_vessel

PRODUCTION_DT = {"kvlcc2": 0.05, "kvlcc2_l7": 0.01, "patrol51": 0.02}


def best_of(fn, repeats=5):
    return min(fn() for _ in range(repeats))


def bare_step_cost(vessel, dt, nstep):
    model = vessel.model
    model.opt.timestep = dt
    data = mujoco.MjData(model)
    data.qvel[0] = 5.0
    data.qvel[7] = 7.0

    def once():
        mujoco.mj_resetData(model, data)
        data.qvel[0] = 5.0
        t0 = time.perf_counter()
        for _ in range(nstep):
            mujoco.mj_step(model, data)
        return (time.perf_counter() - t0) / nstep
    return best_of(once)


def _steady(sim, vessel, speed):
    """The approach: a speed (self-propelled) or, for a CP ship, the Full telegraph order."""
    if speed is None:
        rps, pd = vessel.telegraph["full"]
        return sim.steady_at_order(0, (rps,) * sim.ns, (pd,) * sim.ns)
    return sim.self_propulsion(0, speed)


def make_sim(vessel, n, dt, speed, nthread=1, record=True):
    sim = Simulator(vessel, n, dt, nthread=nthread, record_every=1 if record else 0)
    s = _steady(sim, vessel, speed)
    for i in range(n):
        sim.set_state(i, s)
        sim.set_helm(i, [(H.ZIGZAG, math.radians(20), math.radians(20), 0.0, 1.0 if i % 2 == 0 else -1.0)])
    return sim


def full_step_cost(vessel, n, dt, speed, nstep, nthread=1):
    sim = make_sim(vessel, n, dt, speed, nthread)
    sim.step(10)  # compile / warm

    def once():
        sim.clear_truth()
        t0 = time.perf_counter()
        sim.step(nstep)
        return (time.perf_counter() - t0) / nstep
    return best_of(once, 3)


def timestep_study(vessel, speed, dt0, t_turn, t_zz):
    rows = []
    for dt in (2 * dt0, dt0, dt0 / 2):
        sim = Simulator(vessel, 2, dt)
        s = _steady(sim, vessel, speed)
        sim.set_state(1, s)
        sim.set_helm(0, [(H.HOLD, math.radians(35.0))])
        sim.set_helm(1, [(H.ZIGZAG, math.radians(20), math.radians(20), 0.0, 1.0)])
        sim.step(int(round(max(t_turn, t_zz) / dt)))
        rec = sim.truth()
        c = ship_columns(rec, sim.rec_names, 0, sim.dt)
        mt = TM.turning(c["t"], c["x_w"], c["y_w"], c["heading"], c["u_r"], c["v_r"], c["r"])
        c = ship_columns(rec, sim.rec_names, 1, sim.dt)
        mz = TM.zigzag(c["t"], c["heading"], rudder_deg=20, heading_deg=20, first_side=1)
        rows.append((dt, mt["advance_m"], mt["tactical_diameter_m"], mz["first_overshoot_deg"],
                     mz["second_overshoot_deg"]))
    return rows


def bench_ship(name: str, quick: bool) -> dict:
    vessel = load_vessel(name)
    dt = PRODUCTION_DT.get(name, 0.05)
    speed = {"kvlcc2": kn_to_mps(15.5), "kvlcc2_l7": froude_to_speed(0.142, vessel.length)}.get(name)
    nstep = 4000 if quick else 20000
    out = {"ship": name, "dt_s": dt}
    # bare and full measured alternately, best of several rounds: this machine's timing drifts
    bares, fulls = [], []
    for _ in range(3):
        bares.append(bare_step_cost(vessel, dt, nstep))
        fulls.append(full_step_cost(vessel, 1, dt, speed, nstep))
    bare, full1 = min(bares), min(fulls)
    out["bare_mj_step_us"] = bare * 1e6
    out["full_step_us"] = full1 * 1e6
    out["full_over_bare"] = full1 / bare
    out["real_time_factor"] = dt / full1
    print(f"ship {name}, dt {dt} s")
    print(f"  bare mj_step (same MJCF):           {bare * 1e6:8.2f} us/step")
    print(f"  full 6-DOF step (1 ship):           {full1 * 1e6:8.2f} us/step  = {full1 / bare:.2f} x bare  "
          f"(target <= 5x)")
    print(f"  real-time factor at dt = {dt} s:    {dt / full1:8.0f} x    (target >= 1000x)")
    thr = {}
    for n in (1, 16, 100):
        per_call = full_step_cost(vessel, n, dt, speed, max(200, nstep // n), nthread=2)
        thr[n] = n / per_call
        print(f"  N = {n:3d} ships (2 threads):         {thr[n]:10.0f} ship-steps/s")
    out["ship_steps_per_s"] = {str(k): v for k, v in thr.items()}
    out["n100_over_single"] = thr[100] / thr[1]
    # the ceiling: MuJoCo's own batch step of the same model with no force model at all
    from mujoco import batch as mjbatch
    bare_batch = mjbatch.Batch(vessel.model, 100, nthread=2)
    bare_batch.bind("qvel")[:, 0] = 5.0

    def once():
        t0 = time.perf_counter()
        for _ in range(200):
            bare_batch.step()
        return (time.perf_counter() - t0) / 200
    ceiling = 100 / best_of(once)
    out["bare_batch_100_ship_steps_per_s"] = ceiling
    print(f"  bare MuJoCo batch, N = 100 (no force model at all): {ceiling:10.0f} ship-steps/s "
          f"= {ceiling / thr[1]:.1f} x the full single ship (the ceiling of the N = 100 ratio)")
    print(f"  N = 100 over N = 1 throughput:      {thr[100] / thr[1]:8.1f} x    (target >= 10x)")
    print("  time-step study (35 deg turn, 20/20 zig-zag):")
    L = vessel.length
    U = speed if speed is not None else 10.0
    rows = timestep_study(vessel, speed, dt, 12 * L / U, 12 * L / U)
    print("     dt [s]   advance [m]  tactical [m]  1st ovs [deg]  2nd ovs [deg]")
    for r in rows:
        print(f"    {r[0]:7.4f} {r[1]:12.3f} {r[2]:13.3f} {r[3]:14.3f} {r[4]:14.3f}")
    ref, prod = rows[-1], rows[1]
    dev = {"advance_rel": abs(prod[1] / ref[1] - 1), "tactical_rel": abs(prod[2] / ref[2] - 1),
           "overshoot1_deg": abs(prod[3] - ref[3]), "overshoot2_deg": abs(prod[4] - ref[4])}
    out["timestep_study"] = {"rows": rows, "production_vs_half_step": dev}
    print(f"    production step vs half step: advance {dev['advance_rel'] * 100:.3f} %, tactical "
          f"{dev['tactical_rel'] * 100:.3f} %, overshoots {dev['overshoot1_deg']:.3f} / "
          f"{dev['overshoot2_deg']:.3f} deg")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ship", action="append", help="vessel model(s); default kvlcc2 and patrol51")
    ap.add_argument("--quick", action="store_true", help="fewer steps (noisier)")
    ap.add_argument("--json", help="also write the figures to this file")
    args = ap.parse_args()
    results = [bench_ship(name, args.quick) for name in (args.ship or ["kvlcc2", "patrol51"])]
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=2)


if __name__ == "__main__":
    main()
