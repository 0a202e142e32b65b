"""Running an agenda: crew → records → reductions → scoring → report.

The flow of one trial day (architecture.md):

1. :func:`simulate_agenda` — one ship, the virtual crew executes every run; instruments stream the
   truth; per-run truth references are taken at each FINEX; the calm-water truth at every setting the
   crew used is computed by :mod:`vtrials.truth.calmwater`.
2. :func:`write_agenda_outputs` — ``truth.nc`` (state history, drawn instrument errors, per-run truth
   references), ``records/<trial>.nc`` (what the team has), then the reductions — which read the
   record FILES just written, through :mod:`vtrials.records.netcdf`, never the in-memory truth — then the
   scoring against truth, ``results.json`` (a ``trials`` list with ``reduced``, ``truth`` and
   ``error`` per trial) and ``report.md`` with PNG figures.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from pathlib import Path

import numpy as np

from vtrials import __version__
from vtrials.trials.crew import Crew
from vtrials.errors import InputError, SimulationError
from vtrials.instruments.sea_observation import observe_sea
from vtrials.records.netcdf import atomic_path, open_record, record_in_memory, write_groups
from vtrials.scenario import Scenario, environment_block, hydro_path, instrument_set, sea_vessel, wave_field
from vtrials.runner.outputs import json_clean
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.records.trial import record_contents
from vtrials.truth.calmwater import load_variation
from vtrials.truth.columns import describe
from vtrials.units import DEG, RPM


@dataclasses.dataclass
class AgendaResult:
    scenario: Scenario
    crew: Crew
    simulated_time_s: float
    wall_time_s: float
    calm_water: dict  # trial name → list of calm-water truth points per accepted group
    timings: dict = dataclasses.field(default_factory=dict)
    seaway: np.ndarray | None = None  # the sea's wave components (n, 6), truth for the seakeeping scoring
    hydro_path: Path | None = None  # the ship's hydrodynamic database (seakeeping truth RAOs)

    @property
    def attempts(self):
        return self.crew.attempts


def _initial_state(sim: Simulator, scn: Scenario) -> ShipState:
    """Steady at the first run's setting on its course, or the scenario's [initial] if it has one,
    found on ship 0 of ``sim`` (a one-ship simulator of the calm-water ship for the search)."""
    v = scn.vessel
    first = scn.agenda.runs[0]
    f = str(scn.path)
    init = scn.initial
    heading = first.heading
    try:
        if init.engine_order is not None:
            rps, pitch = v.telegraph[init.engine_order]
            s = sim.steady_at_order(0, (rps,) * sim.ns, (pitch,) * sim.ns if pitch is not None else (),
                                    heading=init.heading_deg * DEG)
        elif any(getattr(init, k) is not None for k in ("froude_number", "speed_kn", "speed_mps")):
            s = sim.self_propulsion(0, scn.speed, init.heading_deg * DEG)
        else:
            gov = [k for k, m in enumerate(first.modes) if m == "governed"]
            s = sim.steady_at_order(0, (first.rps,) * sim.ns,
                                    (first.pitch,) * sim.ns if first.pitch is not None else (), heading=heading)
            if len(gov) < sim.ns:
                s = dataclasses.replace(s, shaft_modes=tuple(first.modes))
    except SimulationError as exc:
        raise InputError(f, "initial", f"the machinery cannot give the starting condition: {exc}") from None
    rules = scn.agenda.rules
    if rules.measured_course and abs(s.heading - heading) < 1e-9:
        # start on the first run's line, far enough before the range centre to settle and approach
        back = abs(s.u) * (2.0 * rules.runout_s + rules.approach_s + 0.5 * first.duration)
        c = scn.site.get("range_center", [0.0, 0.0])
        s = dataclasses.replace(s, x=c[0] - back * math.cos(heading), y=c[1] - back * math.sin(heading))
    return s


def simulate_agenda(scn: Scenario, progress=None) -> AgendaResult:
    """One trial day: the crew executes the agenda on the scenario's ship (see the module docstring)."""
    return simulate_agendas([scn], progress=progress)[0]


def _same_ship(a, b) -> bool:
    """Whether vessels ``a`` and ``b`` can be ships of one :class:`Simulator` — the same model, masses,
    steering, machinery and autopilot, and force components of the same kinds and sizes (their
    parameter values may differ: each ship gets its own, e.g. its own wave realization)."""
    if a is b:
        return True
    if (a.name, str(a.mjcf_path)) != (b.name, str(b.mjcf_path)) or a.added_mass.coriolis != b.added_mass.coriolis \
            or a.autopilot != b.autopilot or a.mass != b.mass:
        return False
    if not all(np.array_equal(x, y) for x, y in ((a.r_G, b.r_G), (a.M_RB, b.M_RB), (a.M_A, b.M_A),
                                                  (a.steering, b.steering), (a.shaft_params, b.shaft_params))):
        return False
    ca, cb = a.components, b.components
    return len(ca) == len(cb) and all(p.name == q.name and p.type == q.type and p.params.shape == q.params.shape
                                      and np.array_equal(p.states, q.states) for p, q in zip(ca, cb))


def _day_setup(scn: Scenario):
    """The ship (with its seaway's components), its environment block and its starting condition."""
    ship, _dropped = sea_vessel(scn)
    env = environment_block(scn)
    dt = scn.head.timestep_s
    # the steady search runs in a simulator of its own: in a seaway on the calm-water ship (it would
    # otherwise balance one instant's wave excitation; the ship then starts in the sea from the
    # calm-water steady condition and settles within the approach)
    search = Simulator(scn.vessel if ship is not scn.vessel else ship, 1, dt, env, record_every=0)
    return ship, env, _initial_state(search, scn)


class CannotShare(ValueError):
    """Trial days that cannot be ships of one simulator (:func:`_can_share`)."""


def _can_share(scns: list[Scenario], setups: list) -> bool:
    """Whether the days of ``scns`` can be stepped together in one simulator (:func:`simulate_agendas`):
    the same time step and truth rate, environment blocks of one size and ships that :func:`_same_ship`."""
    s0, (v0, e0, _) = scns[0], setups[0]
    return all(s.head.timestep_s == s0.head.timestep_s and s.head.record_every == s0.head.record_every
               and e.shape == e0.shape and _same_ship(v0, v) for s, (v, e, _) in zip(scns, setups))


def simulate_agendas(scns: list[Scenario], progress=None) -> list[AgendaResult]:
    """The trial days of ``scns``, stepped together as the ships of one simulator, each with its own
    crew, instruments, environment and seaway (:mod:`vtrials.trials.fleet`); a campaign's way to
    amortize the per-step cost (issue 11). Each day's records are bit-identical to its day simulated
    alone. ``progress`` is given to the first day's crew. Raises :class:`CannotShare` when the days cannot share
    a simulator (:func:`_can_share`)."""
    t_wall = time.perf_counter()
    setups, t_setup = [], []
    for scn in scns:
        t0 = time.perf_counter()
        setups.append(_day_setup(scn))
        t_setup.append(time.perf_counter() - t0)
    if not _can_share(scns, setups):
        raise CannotShare("these trial days cannot share one simulator (time step, truth rate, environment "
                         "block size or ship differ); simulate them one by one")
    n = len(scns)
    s0 = scns[0]
    ship0 = setups[0][0]
    sim = Simulator(ship0, n, s0.head.timestep_s, np.stack([e for _, e, _ in setups]),
                    record_every=s0.head.record_every)
    fleet = None
    if n > 1:
        from vtrials.trials.fleet import Fleet
        fleet = Fleet(sim)
    crews = []
    for i, (scn, (ship, _env, start)) in enumerate(zip(scns, setups)):
        for c0, c in zip(ship0.components, ship.components):
            if c.params is not c0.params and not np.array_equal(c.params, c0.params):
                sim.set_component_params(i, c.name, c.params)
        sim.set_state(i, start, alone=True)
        iset = instrument_set(scn)
        sea = observe_sea(scn.waves, scn.head.seed)
        if sea:  # the wave buoy's (or hindcast's) sea state, for the analysis's wave correction
            iset.team["sea_observed"] = sea
        iset.reset()
        crews.append(Crew(sim, scn.agenda, iset, truth_every=scn.head.truth_every,
                          progress=progress if i == 0 else None, ship=i,
                          driver=None if fleet is None else fleet.driver(i)))
    t_sim = time.perf_counter()
    try:
        if fleet is None:
            crews[0].run_agenda()
        else:
            fleet.run([(i, c.run_agenda) for i, c in enumerate(crews)])
    except KeyboardInterrupt as exc:  # the CLI names the trial time it stopped at
        exc.trial_time_s = float(crews[0].t)
        raise
    sim_s = (time.perf_counter() - t_sim) / n  # a shared simulator's time, shared evenly
    out = []
    for scn, crew, ts in zip(scns, crews, t_setup):
        timings = {"sea_setup_s": ts}
        t_ins = time.perf_counter()
        crew.iset.flush()
        crew.instrument_wall_s += time.perf_counter() - t_ins
        timings["simulate_s"] = sim_s + time.perf_counter() - t_ins
        timings["instruments_s"] = crew.instrument_wall_s
        t1 = time.perf_counter()
        calm = calm_water_truth(scn, crew)
        calm.update(spiral_truth(scn, crew))
        timings["calm_water_s"] = time.perf_counter() - t1
        field = wave_field(scn)
        out.append(AgendaResult(scn, crew, crew.t, ts + sim_s + time.perf_counter() - t_ins, calm, timings,
                                seaway=None if field is None else field.components,
                                hydro_path=hydro_path(scn.vessel) if field is not None else None))
    return out


def _accepted(crew: Crew, trial: str) -> list:
    return [a for a in crew.attempts if a.accepted and a.run.trial == trial]


def calm_water_truth(scn: Scenario, crew: Crew) -> dict:
    """Per standardization trial: calm-water twins at the settings the crew actually used for each
    spot (the last accepted run's per-shaft orders), plus midpoints between consecutive spots of the
    same shaft modes so the true curve is densely known between spots."""
    from vtrials.truth.calmwater import twin_points
    out = {}
    for trial in scn.agenda.trials:
        if trial.head.kind != "standardization":
            continue
        acc = _accepted(crew, trial.head.name)
        groups = sorted({a.run.group for a in acc})
        settings = []
        for g in groups:
            a = [x for x in acc if x.run.group == g][-1]
            settings.append({"group": g, "rps": [r * RPM for r in a.rpm_ordered],
                             "pitch": a.pitch_ordered if a.pitch_ordered[0] is not None else None,
                             "modes": list(a.modes)})
        extra = []
        # the two ends, a little beyond the measured range (the reduced speeds scatter about the spots)
        for st, f in ((settings[0], 0.96), (settings[-1], 1.03)):
            gov = [k for k, m in enumerate(st["modes"]) if m == "governed"]
            rps = [r * f if k in gov else r for k, r in enumerate(st["rps"])]
            if all(r <= sh.max_rps for r, sh in zip(rps, scn.vessel.shafts)):
                extra.append({**st, "group": None, "rps": rps})
        for s0, s1 in zip(settings, settings[1:]):
            if s0["modes"] == s1["modes"]:
                mid = {"group": None, "modes": s0["modes"],
                       "rps": [0.5 * (a + b) for a, b in zip(s0["rps"], s1["rps"])],
                       "pitch": None if s0["pitch"] is None else [0.5 * (a + b) for a, b in zip(s0["pitch"], s1["pitch"])]}
                extra.append(mid)
        pts = twin_points(scn.vessel, settings + extra, scn.head.timestep_s)
        for s, p in zip(settings + extra, pts):
            p.update({"group": s["group"], "modes": s["modes"], "rps_order": s["rps"], "pitch_order": s["pitch"]})
        out[trial.head.name] = pts
    return out


def spiral_truth(scn: Scenario, crew: Crew) -> dict:
    """For every spiral run: the steady-turning curve δ(r) of the model's own equations at the run's
    shaft settings (calm deep water) and its hysteresis loop (:mod:`vtrials.truth.steadyturn`)."""
    from vtrials.truth.steadyturn import hysteresis, steady_turning_curve
    out = {}
    cache = {}
    for a in crew.attempts:
        if not a.accepted or a.run.kind not in ("direct_spiral", "reverse_spiral"):
            continue
        rps = tuple(r * RPM for r in a.rpm_ordered)
        pitch = tuple(p for p in a.pitch_ordered) if a.pitch_ordered and a.pitch_ordered[0] is not None else ()
        key = (rps, pitch)
        if key not in cache:
            curve = steady_turning_curve(scn.vessel, rps, pitch, dt=scn.head.timestep_s)
            loop = hysteresis(curve)
            cache[key] = {"curve": {k: (np.asarray(v).tolist() if isinstance(v, np.ndarray) else v)
                                    for k, v in curve.items()},
                          "hysteresis": {k: (np.asarray(v).tolist() if isinstance(v, np.ndarray) else v)
                                         for k, v in loop.items()}}
        out[f"spiral_run_{a.run.number}"] = cache[key]
    return out


# ----------------------------------------------------------------------------------- writing
def write_agenda_truth(res: AgendaResult, path: Path) -> None:
    crew = res.crew
    s = res.scenario
    rows = np.concatenate(crew.truth_rows, axis=0) if crew.truth_rows else np.zeros((0, len(crew.names)))
    variables = {}
    for j, name in enumerate(crew.names):
        if name == "t":
            continue
        units, long_name = describe(name)
        variables[name] = (rows[:, j], units, long_name)
    attrs = {"kind": "agenda", "instrument_errors": json.dumps(crew.iset.drawn(), sort_keys=True),
             "run_truth": json.dumps(crew.truth_refs), "calm_water": json.dumps(res.calm_water),
             "truth_every": s.head.truth_every}
    groups = {"agenda": {"time": rows[:, 0], "variables": variables, "attrs": attrs}}
    write_groups(path, groups, {"Conventions": "CF-1.10", "title": f"vtrials truth: {s.head.title}",
                                "content": "truth", "ship": s.vessel.name, "seed": s.head.seed,
                                "timestep_s": s.head.timestep_s, "vtrials_version": __version__,
                                "frames": "north-east-down world; body x forward, y starboard, z down at "
                                          "midship waterline"})


def trial_record_contents(res: AgendaResult) -> dict:
    """Per trial: (groups, attributes) of its record — the instruments over the trial's span, its events,
    orders and log sheet (:func:`vtrials.records.trial.record_contents`)."""
    crew = res.crew
    s = res.scenario
    out = {}
    for trial in s.agenda.trials:
        name = trial.head.name
        atts = [a for a in crew.attempts if a.run.trial == name]
        t0, t1 = atts[0].t_start, atts[-1].t_finex
        numbers = {a.run.number for a in atts}
        events = [e for e in crew.events if e[1] in numbers]
        orders = [o for o in crew.orders if t0 <= o[0] <= t1]
        prior = [o for o in crew.orders if o[0] < t0]
        if prior:
            orders = [(t0, prior[-1][1])] + orders
        settings = [st for st in crew.settings if t0 <= st[0] <= t1]
        # the state of every shaft at the start of the trial (the engine-room log carries it over)
        for k in range(crew.sim.ns):
            before = [st for st in crew.settings if st[0] < t0 and st[1] == k]
            if before:
                settings.insert(0, (t0, *before[-1][1:]))
        head = trial.head
        out[name] = record_contents(
            crew.iset, t1, events, orders, f"vtrials trial record: {name} ({head.kind}) — {s.head.title}",
            {"trial": name, "kind": head.kind, "ship": s.vessel.name, "scenario_file": s.path.name,
             "run_log": [a.log() for a in atts],
             "condition": {"displacement_m3": head.displacement_m3 or s.vessel.particulars.displacement,
                           "trim_m": head.trim_m},
             "tank_prediction": tank_prediction(s.vessel)},
            t_start=t0, settings=sorted(settings))
    return out


def write_trial_records(res: AgendaResult, out: Path) -> dict:
    """One record file per trial (:func:`trial_record_contents`) under out/records; {trial: path}."""
    paths = {}
    for name, (groups, attrs) in trial_record_contents(res).items():
        path = out / "records" / f"{name}.nc"
        write_groups(path, groups, attrs)
        paths[name] = path
    return paths


def trial_records_in_memory(res: AgendaResult) -> dict:
    """{trial: Record} equal to what :func:`write_trial_records` then :func:`open_record` give — the
    same arrays and attributes (:func:`vtrials.records.netcdf.record_in_memory`) — with no file written:
    a campaign replicate reduces these."""
    return {name: record_in_memory(Path("records") / f"{name}.nc", groups, attrs)
            for name, (groups, attrs) in trial_record_contents(res).items()}


def tank_prediction(vessel) -> dict:
    """What the towing tank told the trials team: calm-water resistance, delivered power and
    propulsive efficiency η_D = R_T V / P_D at a few speeds (computed from the model's own equations,
    i.e. a perfect tank test of this hull; the reductions use η_D only inside the resistance
    corrections, as ITTC 7.5-04-01-01.1 does), and the overload factor ξ_P of a load-variation test at
    each speed (:func:`vtrials.truth.calmwater.load_variation`)."""
    key = str(vessel.folder)
    if key in _TANK_CACHE:
        return _TANK_CACHE[key]
    sim = Simulator(vessel, 1, 0.05, record_every=0)
    vmax = max_speed(vessel, sim)
    out = {"speed_mps": [], "resistance_N": [], "power_W": [], "eta_D": []}
    hull = [i for i, n in enumerate(sim.comp_names) if n.startswith("hull")]
    for f in np.linspace(0.25, 1.0, 7):
        V = f * vmax
        sim.self_propulsion(0, V)
        P = float(sum(sim.shaft_power(0)))
        R = -float(sum(sim.comp_w[0, i, 0] for i in hull))
        out["speed_mps"].append(V)
        out["resistance_N"].append(R)
        out["power_W"].append(P)
        out["eta_D"].append(R * V / P)
    # the load-variation test at the same speeds: the overload factor ξ_P the Direct Power Method needs
    lv = load_variation(vessel, out["speed_mps"], sim=sim)
    out["xi_P"] = lv["xi_P"]
    out["load_variation"] = lv["points"]
    _TANK_CACHE[key] = out
    return out


_TANK_CACHE: dict = {}


def max_speed(vessel, sim: Simulator) -> float:
    """Calm-water speed at the highest ahead telegraph order (the tank table's range)."""
    best = None
    for order in ("flank", "full"):
        if order in vessel.telegraph:
            rps, pitch = vessel.telegraph[order]
            s = sim.steady_at_order(0, (rps,) * sim.ns, (pitch,) * sim.ns if pitch is not None else ())
            best = s.u
            break
    return best if best else 0.5 * math.sqrt(9.81 * vessel.length) * 0.3


def write_agenda_outputs(res: AgendaResult, out_dir: str | Path, plot: bool = True) -> dict:
    """Write truth, records, results.json and the report into out_dir: into a staging directory beside
    it that replaces out_dir only when everything is written (:mod:`vtrials.runner.staging`)."""
    from vtrials.runner.staging import staged_output
    with staged_output(out_dir) as out:
        return _write_agenda_outputs(res, out, plot)


def _score_sea_sensors(res: AgendaResult, records: dict) -> dict:
    """Wave buoys and wave radars of each trial's record against the true sea (:mod:`vtrials.score.waves`);
    {} when no instrument senses the sea (every shipped scenario: their results are unchanged).
    ``records``: {trial: Record}."""
    kinds = {d.kind for d in res.crew.iset.devices.values()} if hasattr(res.crew, "iset") else set()
    if not kinds & {"wave_buoy", "wave_radar"}:
        return {}
    from vtrials.scenario import wave_field
    from vtrials.score.waves import score_wave_record
    field = wave_field(res.scenario)
    out = {}
    for name, rec in records.items():
        sc = score_wave_record(rec, field)
        if sc:
            out[name] = sc
    return out


def reduce_and_score(res: AgendaResult, records: dict) -> tuple[list, dict]:
    """Reduce every trial's record (the reduction sees the Record only) and score it against the
    truth: (trials list of results.json, wave-instrument scores). ``records``: {trial: Record}, read
    from the files (:func:`write_agenda_outputs`) or built in memory (:func:`score_agenda`)."""
    from vtrials.reduce.trials import reduce_record
    from vtrials.score.trials import score_trial
    trials = []
    for trial in res.scenario.agenda.trials:
        name = trial.head.name
        reduced = reduce_record(records[name])
        scored = score_trial(trial.head.kind, reduced, res, name)
        trials.append({"name": name, "kind": trial.head.kind, "record": f"records/{name}.nc", **scored})
    return trials, _score_sea_sensors(res, records)


def score_agenda(res: AgendaResult) -> dict:
    """The campaign replicate's fast path: reduce and score from in-memory records
    (:func:`trial_records_in_memory`), writing nothing — no truth.nc, records, results.json or report.
    Returns ``{"trials": ..., "simulated_time_s": ...}`` with the trials list exactly as
    :func:`write_agenda_outputs` puts it in results.json (same reduction code, same numbers)."""
    t1 = time.perf_counter()
    trials, waves = reduce_and_score(res, trial_records_in_memory(res))
    res.timings.update({"reduce_score_s": time.perf_counter() - t1})
    doc = {"simulated_time_s": res.simulated_time_s, "timings": res.timings, "trials": trials}
    if waves:
        doc["wave_instruments"] = waves
    return json_clean(doc)


def _write_agenda_outputs(res: AgendaResult, out: Path, plot: bool) -> dict:
    from vtrials.report.trial_report import write_report
    t0 = time.perf_counter()
    write_agenda_truth(res, out / "truth.nc")
    paths = write_trial_records(res, out)
    t1 = time.perf_counter()
    # the reduction sees the record files only
    trials, waves = reduce_and_score(res, {name: open_record(p) for name, p in paths.items()})
    t2 = time.perf_counter()
    res.timings.update({"write_s": t1 - t0, "reduce_score_s": t2 - t1})
    crew = res.crew
    s = res.scenario
    doc = {"vtrials_version": __version__, "scenario": s.head.title, "scenario_file": s.path.name,
           "ship": s.vessel.name, "ship_length_m": s.vessel.length, "seed": s.head.seed,
           "timestep_s": s.head.timestep_s, "simulated_time_s": res.simulated_time_s,
           "wall_time_s": res.wall_time_s, "timings": res.timings,
           "agenda": {"runs": [a.log() for a in crew.attempts],
                      "trial_time_s": {t.head.name: sum(a.t_finex - a.t_start for a in crew.attempts
                                                        if a.run.trial == t.head.name)
                                       for t in s.agenda.trials},
                      "total_time_s": crew.t},
           "trials": trials}
    if waves:  # only when the scenario lists sea sensors (wave buoys, wave radar)
        doc["wave_instruments"] = waves
    doc = json_clean(doc)
    if plot:
        write_report(doc, res, out)
    with atomic_path(out / "results.json") as tmp:
        tmp.write_text(json.dumps(doc, indent=2) + "\n")
    return doc
