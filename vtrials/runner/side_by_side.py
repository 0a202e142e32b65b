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

from vtrials import __version__
from vtrials.physics import steering as H
from vtrials.errors import InputError, SimulationError
from vtrials.trials.driver import Driver
from vtrials.trials.programs import ProgramSupervisor
from vtrials.records.netcdf import atomic_path, write_groups
from vtrials.runner.outputs import json_clean
from vtrials.scenario import Scenario, environment_block, instrument_set, sea_vessel
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.records.trial import write_record
from vtrials.truth.columns import describe, ship_columns
from vtrials.units import DEG, KNOT, speed_to_froude


@dataclasses.dataclass
class ManeuverRun:
    name: str
    kind: str
    execute_time_s: float
    finex_time_s: float
    completed: bool
    truth: dict  # metrics
    columns: dict  # truth arrays from t = 0 to FINEX
    instruments: object = None  # the InstrumentSet that recorded this run
    events: list = dataclasses.field(default_factory=list)  # (time, run, code)
    orders: list = dataclasses.field(default_factory=list)  # (time, engine order)
    ordered: dict = dataclasses.field(default_factory=dict)  # the maneuver as ordered (the director's sheet)


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


INSTRUMENT_CHUNK = 2500  # truth rows per instrument call (streaming, as in the loop of a trial)


def _approach_field(scn: Scenario, i: int, m) -> str:
    """The scenario field that set ship i's approach (for error messages)."""
    if m.approach_order is not None:
        return f"maneuver[{i}].approach_order"
    if m.approach_speed_kn is not None:
        return f"maneuver[{i}].approach_speed_kn"
    init = scn.initial
    return "initial." + next(k for k in ("engine_order", "froude_number", "speed_kn", "speed_mps")
                             if getattr(init, k) is not None)


def _approach(sim: Simulator, i: int, scn: Scenario, m) -> ShipState:
    """The steady condition ship i starts its approach in (also placed on it). An approach the
    machinery cannot deliver (r/min or power beyond the engine's limits) is an input error."""
    v = scn.vessel
    f = str(scn.path)
    order = m.approach_order or (scn.initial.engine_order if m.approach_speed_kn is None else None)
    try:
        if order is not None:
            rps, pitch = v.telegraph[order]
            pitches = (pitch,) * sim.ns if pitch is not None else ()
            s = sim.steady_at_order(i, (rps,) * sim.ns, pitches, heading=scn.heading)
        else:
            U = m.approach_speed_kn * KNOT if m.approach_speed_kn is not None else scn.speed
            s = sim.self_propulsion(i, U, scn.heading)
    except SimulationError as exc:
        raise InputError(f, _approach_field(scn, i, m), f"the machinery cannot give this approach: {exc}") from None
    for k, (power, sh) in enumerate(zip(sim.shaft_power(i), v.shafts)):
        if abs(power) > sh.max_power * (1 + 1e-9):
            raise InputError(f, _approach_field(scn, i, m),
                             f"needs {power / 1e6:.2f} MW on shaft {sh.name!r}, above its limit of "
                             f"{sh.max_power / 1e6:.2f} MW")
    modes = ["governed"] * sim.ns
    names = [sh.name for sh in v.shafts]
    if m.trailed_shaft is not None:
        modes[names.index(m.trailed_shaft)] = "trailed"
    if m.locked_shaft is not None:
        modes[names.index(m.locked_shaft)] = "locked"
    if any(mm != "governed" for mm in modes):
        s = dataclasses.replace(s, shaft_modes=tuple(modes))
        sim.set_state(i, s)
    return s


def simulate(scn: Scenario, nthread: int = 1, progress=None) -> RunResult:
    """Run every maneuver of the scenario side by side (one ship each) and compute truth metrics."""
    t_wall = time.perf_counter()
    vessel = scn.vessel
    N = len(scn.maneuvers)
    dt = scn.head.timestep_s
    env = environment_block(scn)
    # in a seaway the ships carry the wave components (vtrials.scenario.sea_vessel); the approaches are
    # the calm-water steady conditions (found on the calm-water ship: a steady search in the sea would
    # balance one instant's wave excitation), from which the ships settle during the approach
    ship, _dropped = sea_vessel(scn, dt)
    sim = Simulator(ship, N, dt, env, nthread=nthread, record_every=scn.head.record_every,
                    planar=scn.head.planar)
    calm = sim if ship is vessel else Simulator(vessel, N, dt, env, record_every=0, planar=scn.head.planar)
    ap = _autopilot_args(scn)
    starts = [_approach(calm, i, scn, m) for i, m in enumerate(scn.maneuvers)]
    for i in range(N):  # every ship placed last, so no steady-state search disturbs another
        sim.set_state(i, starts[i])
        sim.set_helm(i, [(H.HEADING, scn.heading, *ap)])
    # each ship's time scale L/U from its own approach speed (at least Fn 0.1)
    L_over_U = [vessel.length / max(abs(s.u), 0.1 * math.sqrt(9.80665 * vessel.length)) for s in starts]
    execute_step = []
    for i, m in enumerate(scn.maneuvers):
        approach = m.approach_s if m.approach_s is not None else 3.0 * L_over_U[i]
        execute_step.append(int(round(approach / dt)))
    max_dur = [m.max_duration_s or (60.0 * L_over_U[i] + getattr(m, "duration_s", 0.0))
               for i, m in enumerate(scn.maneuvers)]
    sup = ProgramSupervisor(scn.maneuvers, vessel, ap, execute_step, max_dur, [10.0 * lu for lu in L_over_U],
                            dt, progress)
    try:
        Driver(sim).run([sup])
    except KeyboardInterrupt as exc:  # the CLI names the trial time it stopped at
        exc.trial_time_s = float(np.max(sim.time))
        raise
    t_exec, t_finex, completed = sup.t_exec, sup.t_finex, sup.completed
    sim.check()
    rec = sim.truth()
    names = sim.rec_names
    runs = []
    for i, m in enumerate(scn.maneuvers):
        cols = ship_columns(rec, names, i, sim.dt)
        keep = cols["t"] <= t_finex[i] + 1e-9
        cols = {k: v[keep] for k, v in cols.items()}
        ex = cols["t"] >= t_exec[i] - 1e-9
        metrics = m.truth({k: v[ex] for k, v in cols.items()}) if np.count_nonzero(ex) > 2 else {}
        if not completed[i]:
            metrics["incomplete"] = f"FINEX condition not reached within {max_dur[i]:.0f} s after EXECUTE"
        iset = instrument_set(scn, stream=(i,))
        iset.reset()
        n = len(cols["t"])
        for a in range(0, n, INSTRUMENT_CHUNK):
            iset.process({k: v[a:a + INSTRUMENT_CHUNK] for k, v in cols.items()})
        events = [(max(0.0, t_exec[i] - 60.0), i + 1, 1), (t_exec[i], i + 1, 2), (t_finex[i], i + 1, 3)]
        order0 = m.approach_order or (scn.initial.engine_order if m.approach_speed_kn is None else None)
        orders = ([(0.0, order0)] if order0 else []) + ([(t_exec[i], m.order)] if getattr(m, "order", None) else [])
        ordered = {"kind": m.kind, **{k: v for k, v in dataclasses.asdict(m).items() if v is not None}}
        runs.append(ManeuverRun(m.name, m.kind, t_exec[i], t_finex[i], completed[i], metrics, cols, iset, events,
                                orders, ordered))
    s0 = starts[0]
    U0 = abs(s0.u)
    initial = {"speed_mps": U0, "froude_number": speed_to_froude(U0, vessel.length),
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
        attrs = {"kind": m.kind, "execute_time_s": m.execute_time_s, "finex_time_s": m.finex_time_s,
                 "completed": m.completed}
        if m.instruments is not None:
            attrs["instrument_errors"] = json.dumps(m.instruments.drawn(), sort_keys=True)
        groups[m.name] = {"time": m.columns["t"], "variables": variables, "attrs": attrs}
    attrs = {"Conventions": "CF-1.10", "title": f"vtrials truth: {s.head.title}", "content": "truth",
             "ship": s.vessel.name, "seed": s.head.seed, "timestep_s": s.head.timestep_s,
             "vtrials_version": __version__,
             "frames": "north-east-down world; body x forward, y starboard, z down at midship waterline"}
    write_groups(path, groups, attrs)


def write_outputs(result: RunResult, out_dir: str | Path, plot: bool = True) -> dict:
    """Write truth.nc, results.json and trajectory.png into out_dir: into a staging directory beside it
    that replaces out_dir only when everything is written (:mod:`vtrials.runner.staging`)."""
    from vtrials.runner.staging import staged_output
    with staged_output(out_dir) as out:
        return _write_outputs(result, out, plot)


def _write_outputs(result: RunResult, out: Path, plot: bool) -> dict:
    write_truth(result, out / "truth.nc")
    for i, m in enumerate(result.maneuvers):
        if m.instruments is not None:
            write_record(out / "records" / f"{m.name}.nc", m.instruments, m.finex_time_s, m.events, m.orders,
                         f"vtrials trial record: {m.name} ({m.kind}) — {result.scenario.head.title}",
                         {"trial": m.name, "kind": m.kind, "ship": result.scenario.vessel.name,
                          "scenario_file": result.scenario.path.name, "maneuver": m.ordered})
    if plot:
        from vtrials.report.plots import trajectory_plot
        with atomic_path(out / "trajectory.png") as tmp:
            trajectory_plot(result, tmp)
    doc = json_clean(result.to_json())
    with atomic_path(out / "results.json") as tmp:
        tmp.write_text(json.dumps(doc, indent=2) + "\n")
    return doc
