"""Scenario files: which ship, where and in what condition it starts, the sea, and the maneuvers.

A scenario is TOML with these tables (see ``scenarios/`` for examples, ``vtrials run --help`` for
every field):

``[scenario]``      title, ship (a folder under models/), seed, timestep_s, planar, record_every
``[initial]``       exactly one of froude_number / speed_kn / speed_mps; heading_deg; propulsion
``[environment]``   water_depth_m; ``[environment.current]`` (see :class:`vtrials.physics.environment.current.Current`);
                    ``[environment.waves]`` (:class:`vtrials.physics.environment.waves.Waves`; a seaway realized
                    from the scenario seed, see :func:`wave_field` and :func:`sea_vessel`);
                    ``[environment.wave_loads]`` (:class:`WaveLoads`: the mean wave force's method)
``[[maneuver]]``    one table per maneuver, with ``kind`` and that kind's fields
                    (:mod:`vtrials.trials.programs`), run side by side, one ship each
``[agenda]``        instead of maneuvers: a trial agenda executed run by run on one ship by the virtual
                    crew (:mod:`vtrials.trials.agenda`, :mod:`vtrials.trials.crew`); ``[initial]`` is then optional
                    (default: steady at the first run's setting, on its course)
``[site]``, ``[[instrument]]``  the trial site as surveyed; additions/overrides of the ship's suite

Everything is checked before anything runs or is written; every error names the file and the
field.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from vtrials.errors import InputError
from vtrials.trials.programs import KINDS, ORDER_CHOICES
from vtrials.physics.environment.wind import Wind
from vtrials.schema import (_short, check_name, did_you_mean, choice, flag, integer, load_toml, num, read_table, table, table_list, text,
                            unknown_key)
from vtrials.physics.environment.current import Current
from vtrials.physics.environment.waves import Waves
from vtrials.units import DEG, KNOT, froude_to_speed
from vtrials.physics.vessel import Vessel, load_vessel


@dataclasses.dataclass(frozen=True)
class Head:
    title: str = text("one-line description of the scenario")
    ship: str = text("vessel model: a name under models/ (e.g. kvlcc2_l7) or a model folder path")
    seed: int = integer("seed of every random draw in the run (records are reproducible from it)", 0, 2 ** 63 - 1)
    timestep_s: float = num("simulation time step", "s", 0.0, 1.0, lo_open=True)
    planar: bool = flag("hold heave, roll and pitch at zero (3-DOF validation mode)", default=False)
    record_every: int = integer("record the truth state every this many steps (the instruments sample "
                                "this stream)", 1, 100000, default=1)
    truth_every: int = integer("keep every this many recorded truth rows in truth.nc (agendas of hours may "
                               "thin the file; instruments and scoring still see every row)", 1, 100000,
                               default=1)


@dataclasses.dataclass(frozen=True)
class Initial:
    froude_number: float = num("approach speed as a length Froude number", "", 0.0, 1.0, lo_open=True, default=None)
    speed_kn: float = num("approach speed through the water", "kn", 0.0, 60.0, lo_open=True, default=None)
    speed_mps: float = num("approach speed through the water", "m/s", 0.0, 30.0, lo_open=True, default=None)
    engine_order: str = text("instead of a speed: the steady speed of this engine order (\"stop\": dead in "
                             "the water)", ORDER_CHOICES, default=None)
    heading_deg: float = num("approach heading (from north, clockwise)", "deg", -360.0, 360.0, default=0.0)
    propulsion: str = text("how the shafts are set for a given speed: the r/min that holds it in calm water "
                           "(at the design pitch)", ("self_propelled",), default="self_propelled")


@dataclasses.dataclass(frozen=True)
class Environment:
    water_depth_m: float = num("water depth (the hull models are deep-water models)", "m", 0.0, 12000.0,
                               lo_open=True, default=10000.0)


@dataclasses.dataclass(frozen=True)
class WaveLoads:
    """How the ship's wave loads are modelled (``[environment.wave_loads]``; used only with waves)."""

    mean_force: str = text("mean second-order wave force: 'snnm' (surge: SNNM added resistance at the ship's "
                           "speed and heading, Liu & Papanikolaou 2020; sway, yaw: the database's drift), "
                           "'database' (the BEM database's zero-speed drift in surge, sway and yaw) or 'none'",
                           ("snnm", "database", "none"), default="snnm")


MAX_GRADIENT_CURRENT_KN = 10.0  # the steady current's own bound (Current.speed_kn)
SITE_EXTENT_M = 100000.0  # every surveyed point lies within 100 km of the range's origin (a trial area)


@dataclasses.dataclass(frozen=True)
class Site:
    """The trial site as the trials team surveyed it (positions north, east in the range's frame, m)."""

    latitude_deg: float = num("latitude of the range", "deg", -90.0, 90.0, default=38.0)
    transponder_side: float = num("side of the transponder baseline A→B the ship works on: +1 starboard "
                                  "(right) of A→B, −1 port", "", -1.0, 1.0, default=-1.0)
    hydrophone_side: float = num("side of the hydrophone pair 1→2 the ship works on (±1)", "", -1.0, 1.0,
                                 default=-1.0)
    range_center_north_m: float = num("centre of the measured course (runs are laid over it), north", "m",
                                      -SITE_EXTENT_M, SITE_EXTENT_M, default=0.0)
    range_center_east_m: float = num("centre of the measured course, east", "m", -SITE_EXTENT_M, SITE_EXTENT_M,
                                     default=0.0)


DEFAULT_TRANSPONDERS = [[-10000.0, -6000.0], [-10000.0, 6000.0]]  # 10 km south of the range centre
DEFAULT_HYDROPHONES = [[-600.0, -800.0], [-600.0, 800.0]]


def _points(val, f: str, field: str, n_min: int) -> list:
    """Surveyed points: at least n_min [north, east] pairs, finite, within the trial area, at least
    1 m apart (coincident stations give no fix)."""
    ok = isinstance(val, list) and len(val) >= n_min and all(
        isinstance(p, list) and len(p) == 2 and all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                                    for c in p) for p in val)
    if not ok:
        raise InputError(f, field, f"expected at least {n_min} [north, east] pairs in metres, got {_short(val)}")
    pts = [[float(a), float(b)] for a, b in val]
    for k, (a, b) in enumerate(pts):
        if not (math.isfinite(a) and math.isfinite(b) and abs(a) <= SITE_EXTENT_M and abs(b) <= SITE_EXTENT_M):
            raise InputError(f, f"{field}[{k}]", f"{_short(val[k])} is out of range: expected finite metres within "
                                                 f"±{SITE_EXTENT_M:g} m of the range origin")
        for j in range(k):
            if math.hypot(a - pts[j][0], b - pts[j][1]) < 1.0:
                raise InputError(f, f"{field}[{k}]", f"coincides with {field}[{j}] (stations must be at least "
                                                     f"1 m apart)")
    return pts


@dataclasses.dataclass
class Scenario:
    path: Path
    head: Head
    initial: Initial
    environment: Environment
    current: Current
    wind: Wind
    maneuvers: list
    vessel: Vessel
    site: dict = dataclasses.field(default_factory=dict)
    instrument_items: list = dataclasses.field(default_factory=list)
    agenda: object = None  # vtrials.trials.agenda.Agenda when the scenario is an agenda
    waves: Waves = dataclasses.field(default_factory=Waves)  # calm unless [environment.waves] says so
    wave_loads: WaveLoads = dataclasses.field(default_factory=WaveLoads)

    @property
    def speed(self) -> float:
        """Approach speed through the water [m/s] (None when the approach is an engine order)."""
        i = self.initial
        if i.engine_order is not None:
            return None
        if i.froude_number is not None:
            return froude_to_speed(i.froude_number, self.vessel.length)
        if i.speed_kn is not None:
            return i.speed_kn * KNOT
        return i.speed_mps

    @property
    def heading(self) -> float:
        return self.initial.heading_deg * DEG


_TOP = ("scenario", "initial", "environment", "maneuver", "agenda", "site", "instrument", "campaign")


def load_scenario(path: str | Path, doc: dict | None = None) -> Scenario:
    """Read and check a scenario file (and the vessel it names). ``doc``: the file's tables already
    read (and changed, e.g. by a campaign's draws); ``path`` then names it in messages and anchors
    relative paths. A ``[campaign]`` table is read by :mod:`vtrials.campaign` and ignored here."""
    if not isinstance(path, (str, Path)) or not str(path) or "\x00" in str(path):
        raise InputError("load_scenario()", "path", f"expected the path of a scenario file, got {_short(path)}")
    p = Path(path)
    f = str(path)
    doc = load_toml(p) if doc is None else doc
    for key in doc:
        if key not in _TOP:
            raise unknown_key(f, "", key, list(_TOP))
    if "scenario" not in doc:
        raise InputError(f, "scenario", "missing table [scenario]")
    head, _ = read_table(Head, doc["scenario"], f, "scenario")
    ship = head.ship
    if "/" in ship or "\\" in ship or ship.endswith(".toml"):  # a model folder of the user's, relative to the scenario
        ship = str((p.parent / ship).resolve())
    vessel = load_vessel(ship, file_for_errors=f, field_for_errors="scenario.ship")
    init, _ = read_table(Initial, table(doc.get("initial"), f, "initial"), f, "initial")
    given = [k for k in ("froude_number", "speed_kn", "speed_mps", "engine_order") if getattr(init, k) is not None]
    has_agenda = "agenda" in doc
    if has_agenda and "maneuver" in doc:
        raise InputError(f, "agenda", "a scenario is either an agenda or a list of [[maneuver]] tables, not both")
    if len(given) > 1 or (len(given) == 0 and not has_agenda):
        raise InputError(f, "initial", "give exactly one of froude_number, speed_kn, speed_mps, engine_order"
                         + (f" (got {', '.join(given)})" if given else ""))
    env_tab = table(doc.get("environment"), f, "environment")
    cur_tab = table(env_tab.pop("current", None), f, "environment.current")
    wind_tab = table(env_tab.pop("wind", None), f, "environment.wind")
    waves_tab = table(env_tab.pop("waves", None), f, "environment.waves")
    loads_tab = table(env_tab.pop("wave_loads", None), f, "environment.wave_loads")
    env, _ = read_table(Environment, env_tab, f, "environment")
    if env.water_depth_m <= vessel.particulars.draught:
        raise InputError(f, "environment.water_depth_m", f"{env.water_depth_m} m does not float the ship "
                                                         f"(draught {vessel.particulars.draught} m)")
    current, _ = read_table(Current, cur_tab, f, "environment.current")
    for key in ("reference_north_m", "reference_east_m"):
        val = getattr(current, key)
        if abs(val) > SITE_EXTENT_M:
            raise InputError(f, f"environment.current.{key}", f"{val!r} is out of range: expected a number in "
                                                               f"[{-SITE_EXTENT_M:g}, {SITE_EXTENT_M:g}] m")
    wind, _ = read_table(Wind, wind_tab, f, "environment.wind")
    if wind.speed_kn > 0 and vessel.windage is None:
        raise InputError(f, "environment.wind.speed_kn", f"{vessel.name} has no [windage] data for wind loads")
    waves, _ = read_table(Waves, waves_tab, f, "environment.waves")
    waves.check(f)
    wave_loads, _ = read_table(WaveLoads, loads_tab, f, "environment.wave_loads")
    if (waves.hs_m > 0.0 or waves.swell_hs_m > 0.0) and not hydro_path(vessel).is_file():
        raise InputError(f, "environment.waves", f"{vessel.name} has no hydrodynamic database "
                         f"({hydro_path(vessel)}) for wave loads")
    items = table_list(doc.get("maneuver", []), f, "maneuver")
    if not has_agenda and not items:
        raise InputError(f, "maneuver", "expected at least one [[maneuver]] table (or an [agenda])")
    maneuvers = []
    names = set()
    max_rudder = math.degrees(vessel.max_rudder)
    for i, tab in enumerate(items):
        sec = f"maneuver[{i}]"
        if not isinstance(tab, dict):
            raise InputError(f, sec, "expected a table")
        kind = choice(tab.get("kind"), KINDS, f, f"{sec}.kind", "maneuver kind")
        if "name" in tab:
            check_name(tab["name"], f, f"{sec}.name")
        m, _ = read_table(KINDS[kind], tab, f, sec, extra_keys=("kind",))
        if m.name in names:
            raise InputError(f, f"{sec}.name", f"duplicate maneuver name {m.name!r}")
        names.add(m.name)
        for field, value in m.rudders():
            if abs(value) > max_rudder + 1e-9:
                raise InputError(f, f"{sec}.{field}", f"{value:g}° is beyond the maximum rudder angle of "
                                                      f"{vessel.name} ({max_rudder:g}°)")
        if m.approach_order is not None and m.approach_speed_kn is not None:
            raise InputError(f, f"{sec}.approach_order", "give approach_order or approach_speed_kn, not both")
        shaft_names = [sh.name for sh in vessel.shafts]
        for field in ("trailed_shaft", "locked_shaft"):
            val = getattr(m, field)
            if val is not None and val not in shaft_names:
                raise InputError(f, f"{sec}.{field}", f"unknown shaft {val!r}{did_you_mean(val, shaft_names)} (shafts of {vessel.name}: "
                                                      f"{', '.join(shaft_names)})")
        if m.trailed_shaft is not None and m.trailed_shaft == m.locked_shaft:
            raise InputError(f, f"{sec}.locked_shaft", "a shaft cannot be trailed and locked at once")
        if m.trailed_shaft is not None and m.locked_shaft is not None and len(shaft_names) == 2:
            raise InputError(f, f"{sec}.locked_shaft", "no shaft would be left driving")
        maneuvers.append(m)
    site_tab = table(doc.get("site"), f, "site")
    tr = _points(site_tab.pop("transponders", DEFAULT_TRANSPONDERS), f, "site.transponders", 2)
    hy = _points(site_tab.pop("hydrophones", DEFAULT_HYDROPHONES), f, "site.hydrophones", 2)
    site_obj, _ = read_table(Site, site_tab, f, "site")
    if current.gradient_kn_per_nmi != 0.0:  # the gradient's current at the range must stay a sea current
        d = math.hypot(site_obj.range_center_north_m - current.reference_north_m,
                       site_obj.range_center_east_m - current.reference_east_m)
        at = abs(current.gradient_kn_per_nmi) * d / 1852.0
        if at > MAX_GRADIENT_CURRENT_KN:
            raise InputError(f, "environment.current.reference_north_m",
                             f"the gradient gives {at:.3g} kn at the range centre, {d:.0f} m from the reference "
                             f"point: move the reference within {MAX_GRADIENT_CURRENT_KN * 1852.0 / abs(current.gradient_kn_per_nmi):.0f} m "
                             f"of the range centre (at most {MAX_GRADIENT_CURRENT_KN:g} kn from the gradient there)")
    site = {"transponders": tr, "hydrophones": hy, "transponder_side": site_obj.transponder_side,
            "hydrophone_side": site_obj.hydrophone_side, "latitude_deg": site_obj.latitude_deg,
            "range_center": [site_obj.range_center_north_m, site_obj.range_center_east_m],
            "water_depth_m": env.water_depth_m}
    agenda = None
    if has_agenda:
        from vtrials.trials.agenda import load_agenda
        agenda = load_agenda(table(doc["agenda"], f, "agenda"), vessel, f)
        for k, trial in enumerate(agenda.trials):
            if trial.head.kind == "seakeeping" and not waves.hs_m > 0.0:
                raise InputError(f, f"agenda.trial[{k}].kind", "a seakeeping trial needs a wind sea "
                                                               "([environment.waves] hs_m > 0): its legs are "
                                                               "laid relative to the mean wave direction")
    instruments = table_list(doc.get("instrument", []), f, "instrument")
    scn = Scenario(p, head, init, env, current, wind, maneuvers, vessel, site, instruments, agenda, waves=waves,
                   wave_loads=wave_loads)
    # the instrument suite (and the scenario's additions) are checked now, before anything runs
    instrument_set(scn, scenario_file=f)
    if given and init.engine_order is None and scn.speed > 0.9 * _runaway_speed(vessel):
        raise InputError(f, "initial", f"approach speed {scn.speed:.2f} m/s is beyond this hull model's range")
    return scn


def instrument_set(scn: Scenario, stream: tuple = (), scenario_file: str | None = None):
    """The ship's instruments with the scenario's additions, reading the scenario's sea: anemometers
    scale the truth's wind speed (at the wind's reference height) to their own height with the
    simulated wind's profile (its exponent and reference height, as :func:`environment_block` packs
    them), not with a profile of their own. Instruments that sense the sea itself (wave buoys, wave
    radar, bow relative-motion meter) get the scenario's seaway realization (:func:`wave_field`)."""
    from vtrials.instruments.suite import InstrumentSet
    f = str(scn.path) if scenario_file is None else scenario_file  # the name messages give the file
    iset = InstrumentSet(scn.vessel, scn.head.seed, scn.site, scn.instrument_items, f, stream=stream,
                         wind_profile=(scn.wind.profile_exponent, scn.wind.reference_height_m))
    if any(d.kind == "wave_probe" for d in iset.devices.values()):
        field = wave_field(scn)  # wave probes see the scenario's sea surface
        if field is not None:
            iset.set_seaway(field.components)
    if iset.needs_sea:  # wave buoys, wave radar, relative-motion meter read the seaway itself (opt-in)
        iset.attach_sea(wave_field(scn))
    return iset


def _runaway_speed(vessel: Vessel) -> float:
    from vtrials.units import G
    return 2.0 * math.sqrt(G * vessel.length)


def environment_block(scn: Scenario) -> np.ndarray:
    """The sea (current, wind with its gusts drawn from the scenario seed) as an environment block."""
    from vtrials.physics.environment.current import pack as pack_current
    from vtrials.physics.environment.wind import pack_env as pack_wind
    env = pack_current(scn.current, scn.environment.water_depth_m)
    gust_seed, = np.random.SeedSequence(scn.head.seed).spawn(1)
    return pack_wind(scn.wind, env, np.random.default_rng(gust_seed))


def hydro_path(vessel: Vessel) -> Path:
    """The ship's BEM database: ``models/<ship>/hydro/<ship>_hydro.nc`` (written by
    :mod:`vtrials.physics.seakeeping.build`)."""
    return Path(vessel.folder) / "hydro" / f"{vessel.name}_hydro.nc"


def wave_field(scn: Scenario):
    """The scenario's seaway realization (:class:`vtrials.physics.environment.waves.WaveField`), or
    None in a calm sea. Drawn from the second child of the scenario seed's SeedSequence (the first
    draws the wind gusts, :func:`environment_block`): same seed → same sea, independent of the gusts."""
    w = scn.waves
    if not (w.hs_m > 0.0 or w.swell_hs_m > 0.0):
        return None
    from vtrials.physics.environment.waves import realize
    _, wave_seed = np.random.SeedSequence(scn.head.seed).spawn(2)
    return realize(w, scn.environment.water_depth_m, np.random.default_rng(wave_seed))


def sea_vessel(scn: Scenario, dt: float | None = None, model=None):
    """The scenario's ship with the seakeeping force components for its seaway (the calm-water
    ``scn.vessel`` itself in a calm sea), for a simulator with step ``dt`` (default: the scenario's):
    :func:`vtrials.physics.seakeeping.sea_ship.sea_ship` with ``[environment.wave_loads] mean_force``.

    Components outside the database's frequency range [ω_min/2, ω_max] are left out (their share of
    the sea's variance is returned with the vessel as ``(vessel, dropped_variance_fraction)``).
    Calm-water references (truth) must keep using ``scn.vessel``.
    """
    field = wave_field(scn)
    if field is None:
        return scn.vessel, 0.0
    from vtrials.physics.seakeeping.database import load_database
    from vtrials.physics.seakeeping.sea_ship import sea_ship
    db = load_database(hydro_path(scn.vessel))
    comp = field.components
    keep = (comp[:, 1] >= 0.5 * db.omega[0]) & (comp[:, 1] <= db.omega[-1])
    var = float(np.sum(comp[:, 0] ** 2))
    dropped = float(np.sum(comp[~keep, 0] ** 2)) / var if var > 0.0 else 0.0
    v, _ = sea_ship(scn.vessel, db, comp[keep], scn.head.timestep_s if dt is None else dt, model=model,
                    mean_force=scn.wave_loads.mean_force)
    return v, dropped
