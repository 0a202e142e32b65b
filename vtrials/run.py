"""Running a scenario: simulate every maneuver, compute the truth metrics, write the outputs.

The CLI (``vtrials run``) and the Python API (:func:`run`, :func:`simulate`) are this module.
Outputs in the output directory:

* ``truth.nc``     – the true state history of every maneuver (one netCDF group each);
* ``results.json`` – simulated and wall time, and per maneuver its truth metrics;
* ``trajectory.png`` – the tracks and the heading / rudder histories.

Nothing is written unless the whole run succeeds; each file appears atomically.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from pathlib import Path

import numpy as np

from . import __version__
from . import helm as H
from .errors import InputError
from .maneuvers import Progress
from .records import atomic_path, write_groups
from .scenario import Scenario, load_scenario
from .sea import pack as pack_env
from .simulator import Simulator
from .truth import describe, ship_columns
from .units import DEG, speed_to_froude


@dataclasses.dataclass
class ManeuverRun:
    name: str
    kind: str
    execute_time_s: float
    finex_time_s: float
    completed: bool
    truth: dict  # metrics
    columns: dict  # truth arrays from t = 0 to FINEX


@dataclasses.dataclass
class RunResult:
    scenario: Scenario
    initial: dict
    maneuvers: list
    simulated_time_s: float
    wall_time_s: float
    record_names: list

    def to_json(self) -> dict:
        s = self.scenario
        return {
            "vtrials_version": __version__,
            "scenario": s.head.title,
            "scenario_file": s.path.name,
            "ship": s.vessel.name,
            "ship_length_m": s.vessel.length,
            "seed": s.head.seed,
            "timestep_s": s.head.timestep_s,
            "planar": s.head.planar,
            "initial": self.initial,
            "simulated_time_s": self.simulated_time_s,
            "wall_time_s": self.wall_time_s,
            "maneuvers": [{"name": m.name, "kind": m.kind, "completed": m.completed,
                           "execute_time_s": m.execute_time_s, "finex_time_s": m.finex_time_s,
                           "truth": {**m.truth, "ship_length_m": s.vessel.length}}
                          for m in self.maneuvers],
        }


def _autopilot_args(scn: Scenario) -> tuple:
    ap = scn.vessel.autopilot
    kp = ap.gain
    return (min(ap.rudder_limit_deg * DEG, scn.vessel.max_rudder), kp, kp / ap.integral_time,
            kp * ap.derivative_time)


def simulate(scn: Scenario, nthread: int = 1, progress=None) -> RunResult:
    """Run every maneuver of the scenario side by side (one ship each) and compute truth metrics."""
    t_wall = time.perf_counter()
    vessel = scn.vessel
    N = len(scn.maneuvers)
    dt = scn.head.timestep_s
    env = pack_env(scn.current, scn.environment.water_depth_m)
    sim = Simulator(vessel, N, dt, env, nthread=nthread, record_every=scn.head.record_every,
                    planar=scn.head.planar)
    U = scn.speed
    s0 = sim.self_propulsion(0, U, scn.heading)
    ap = _autopilot_args(scn)
    L_over_U = vessel.length / U
    execute_step = []
    for i, m in enumerate(scn.maneuvers):
        sim.set_state(i, s0)
        sim.set_helm(i, [(H.HEADING, scn.heading, *ap)])
        approach = m.approach_s if m.approach_s is not None else 3.0 * L_over_U
        execute_step.append(int(round(approach / dt)))
    max_dur = [getattr(m, "max_duration_s", None) or 60.0 * L_over_U for m in scn.maneuvers]
    t_exec = [math.nan] * N
    psi_exec = [0.0] * N
    t_finex = [math.nan] * N
    completed = [False] * N
    supervise = max(1, int(round(0.5 / dt)))  # the crew looks every half second
    step = 0
    running = set(range(N))
    while running:
        pending = [execute_step[i] - step for i in running if math.isnan(t_exec[i]) and execute_step[i] >= step]
        n = min([supervise] + [p for p in pending if p > 0])
        if not any(p == 0 for p in pending):
            sim.step(n)
            step += n
        for i in sorted(running):
            if math.isnan(t_exec[i]):
                if step >= execute_step[i]:
                    t_exec[i] = float(sim.time[i])
                    psi_exec[i] = float(sim.nav[i, 0])
                    sim.set_helm(i, scn.maneuvers[i].program(psi_exec[i], ap))
                continue
            elapsed = float(sim.time[i]) - t_exec[i]
            phase = sim.helm_phase(i)
            tstart = sim.hs[i, H.H_TSTART]
            pe = float(sim.time[i]) - tstart if tstart >= 0 else 0.0
            prog = Progress(elapsed, float(sim.nav[i, 0]) - psi_exec[i], phase, pe, 10.0 * L_over_U)
            if scn.maneuvers[i].finished(prog):
                t_finex[i] = float(sim.time[i])
                completed[i] = True
                running.discard(i)
            elif elapsed >= max_dur[i]:
                t_finex[i] = float(sim.time[i])
                running.discard(i)
        if progress:
            progress(float(sim.time[0]), len(running))
    sim.check()
    rec = sim.truth()
    names = sim.rec_names
    runs = []
    for i, m in enumerate(scn.maneuvers):
        cols = ship_columns(rec, names, i)
        keep = cols["t"] <= t_finex[i] + 1e-9
        cols = {k: v[keep] for k, v in cols.items()}
        ex = cols["t"] >= t_exec[i] - 1e-9
        metrics = m.truth({k: v[ex] for k, v in cols.items()}) if np.count_nonzero(ex) > 2 else {}
        if not completed[i]:
            metrics["incomplete"] = f"FINEX condition not reached within {max_dur[i]:.0f} s after EXECUTE"
        runs.append(ManeuverRun(m.name, m.kind, t_exec[i], t_finex[i], completed[i], metrics, cols))
    initial = {"speed_mps": U, "froude_number": speed_to_froude(U, vessel.length),
               "heading_deg": scn.initial.heading_deg, "shaft_rps": list(s0.shaft_rps),
               "shaft_rpm": [60.0 * n for n in s0.shaft_rps], "sinkage_m": s0.z,
               "heel_deg": math.degrees(s0.roll), "trim_deg": math.degrees(s0.pitch)}
    sim_time = float(max(t_finex))
    return RunResult(scn, initial, runs, sim_time, time.perf_counter() - t_wall, names)


def write_truth(result: RunResult, path: Path) -> None:
    s = result.scenario
    groups = {}
    for m in result.maneuvers:
        variables = {}
        for name in result.record_names:
            if name == "t":
                continue
            units, long_name = describe(name)
            variables[name] = (m.columns[name], units, long_name)
        groups[m.name] = {"time": m.columns["t"], "variables": variables,
                          "attrs": {"kind": m.kind, "execute_time_s": m.execute_time_s,
                                    "finex_time_s": m.finex_time_s, "completed": m.completed}}
    attrs = {"Conventions": "CF-1.10", "title": f"vtrials truth: {s.head.title}", "content": "truth",
             "ship": s.vessel.name, "seed": s.head.seed, "timestep_s": s.head.timestep_s,
             "vtrials_version": __version__,
             "frames": "north-east-down world; body x forward, y starboard, z down at midship waterline"}
    write_groups(path, groups, attrs)


def _json_clean(x):
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: _json_clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_clean(v) for v in x]
    if isinstance(x, np.generic):
        return _json_clean(x.item())
    return x


def write_outputs(result: RunResult, out_dir: str | Path, plot: bool = True) -> dict:
    """Write truth.nc, results.json and trajectory.png into out_dir (each atomically)."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(str(out), "--out", "exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    write_truth(result, out / "truth.nc")
    if plot:
        from .plots import trajectory_plot
        with atomic_path(out / "trajectory.png") as tmp:
            trajectory_plot(result, tmp)
    doc = _json_clean(result.to_json())
    with atomic_path(out / "results.json") as tmp:
        tmp.write_text(json.dumps(doc, indent=2) + "\n")
    return doc


def run(scenario_path: str | Path, out_dir: str | Path, nthread: int = 1, plot: bool = True,
        progress=None) -> RunResult:
    """Load, check, simulate and write: the one code path behind ``vtrials run``."""
    scn = load_scenario(scenario_path)
    result = simulate(scn, nthread=nthread, progress=progress)
    write_outputs(result, out_dir, plot=plot)
    return result
