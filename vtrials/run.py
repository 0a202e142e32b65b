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
from .errors import InputError, SimulationError
from .maneuvers import Progress
from .records import atomic_path, write_groups
from .scenario import Scenario, load_scenario
from .forces import layout as L
from .sea import pack as pack_env
from .instruments.suite import InstrumentSet
from .simulator import ShipState, Simulator
from .trialrecord import write_record
from .wind import pack_env as pack_wind
from .truth import describe, ship_columns
from .units import DEG, KNOT, speed_to_froude


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


def _environment(scn: Scenario) -> np.ndarray:
    """The sea (current, wind with its gusts drawn from the scenario seed) as an environment block."""
    env = pack_env(scn.current, scn.environment.water_depth_m)
    gust_seed, = np.random.SeedSequence(scn.head.seed).spawn(1)
    return pack_wind(scn.wind, env, np.random.default_rng(gust_seed))


def simulate(scn: Scenario, nthread: int = 1, progress=None) -> RunResult:
    """Run every maneuver of the scenario side by side (one ship each) and compute truth metrics."""
    t_wall = time.perf_counter()
    vessel = scn.vessel
    N = len(scn.maneuvers)
    dt = scn.head.timestep_s
    sim = Simulator(vessel, N, dt, _environment(scn), nthread=nthread, record_every=scn.head.record_every,
                    planar=scn.head.planar)
    ap = _autopilot_args(scn)
    starts = [_approach(sim, i, scn, m) for i, m in enumerate(scn.maneuvers)]
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
    t_exec = [math.nan] * N
    psi_exec = [0.0] * N
    t_finex = [math.nan] * N
    completed = [False] * N
    supervise = max(1, int(round(0.5 / dt)))  # the crew looks every half second
    history: list[list[tuple[float, float]]] = [[] for _ in range(N)]
    step = 0
    running = set(range(N))
    while running:
        pending = [execute_step[i] - step for i in running if math.isnan(t_exec[i]) and execute_step[i] >= step]
        n = min([supervise] + [p for p in pending if p > 0])
        if not any(p == 0 for p in pending):
            sim.step(n)
            step += n
        for i in sorted(running):
            t_i = float(sim.time[i])
            if math.isnan(t_exec[i]):
                if step >= execute_step[i]:
                    t_exec[i] = t_i
                    psi_exec[i] = float(sim.nav[i, 0])
                    ex = scn.maneuvers[i].execute(psi_exec[i], ap)
                    sim.set_helm(i, ex.helm)
                    if ex.order is not None:
                        sim.set_order(i, *vessel.telegraph[ex.order])
                continue
            speed = float(np.hypot(sim.ctx[i, L.NU_R], sim.ctx[i, L.NU_R + 1]))
            hist = history[i]
            hist.append((t_i, speed))
            while hist and hist[0][0] < t_i - 20.0:
                hist.pop(0)
            rate = (hist[-1][1] - hist[0][1]) / (hist[-1][0] - hist[0][0]) if hist[-1][0] - hist[0][0] >= 19.0 \
                else math.inf
            phase = sim.helm_phase(i)
            tstart = sim.hs[i, H.H_TSTART]
            pe = t_i - tstart if tstart >= 0 else 0.0
            prog = Progress(t_i - t_exec[i], float(sim.nav[i, 0]) - psi_exec[i], phase, pe, 10.0 * L_over_U[i],
                            surge=float(sim.ctx[i, L.NU_R]), speed_rate=rate)
            if scn.maneuvers[i].finished(prog):
                t_finex[i] = t_i
                completed[i] = True
                running.discard(i)
            elif t_i - t_exec[i] >= max_dur[i]:
                t_finex[i] = t_i
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
        iset = InstrumentSet(vessel, scn.head.seed, scn.site, scn.instrument_items, str(scn.path), stream=(i,))
        iset.reset()
        n = len(cols["t"])
        for a in range(0, n, INSTRUMENT_CHUNK):
            iset.process({k: v[a:a + INSTRUMENT_CHUNK] for k, v in cols.items()})
        events = [(max(0.0, t_exec[i] - 60.0), i + 1, 1), (t_exec[i], i + 1, 2), (t_finex[i], i + 1, 3)]
        order0 = m.approach_order or (scn.initial.engine_order if m.approach_speed_kn is None else None)
        orders = ([(0.0, order0)] if order0 else []) + ([(t_exec[i], m.order)] if getattr(m, "order", None) else [])
        runs.append(ManeuverRun(m.name, m.kind, t_exec[i], t_finex[i], completed[i], metrics, cols, iset, events,
                                orders))
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
    for i, m in enumerate(result.maneuvers):
        if m.instruments is not None:
            write_record(out / "records" / f"{m.name}.nc", m.instruments, m.finex_time_s, m.events, m.orders,
                         f"vtrials trial record: {m.name} ({m.kind}) — {result.scenario.head.title}",
                         {"trial": m.name, "kind": m.kind, "ship": result.scenario.vessel.name,
                          "scenario_file": result.scenario.path.name})
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
    """Load, check, simulate and write: the one code path behind ``vtrials run``. A scenario with an
    ``[agenda]`` goes through :mod:`vtrials.trialrun` (crew, records, reductions, scoring, report)."""
    scn = load_scenario(scenario_path)
    if scn.agenda is not None:
        from .trialrun import simulate_agenda, write_agenda_outputs
        result = simulate_agenda(scn, progress=progress)
        write_agenda_outputs(result, out_dir, plot=plot)
        return result
    result = simulate(scn, nthread=nthread, progress=progress)
    write_outputs(result, out_dir, plot=plot)
    return result
