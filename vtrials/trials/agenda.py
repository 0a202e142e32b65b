"""Trial agendas: the trials director's run-by-run schedule, read from a scenario's ``[agenda]``.

An agenda names the general rules of the day (base course, the helmsman's rudder limit on a run,
approach and settling times, how steadiness is judged, whether unsteady runs are repeated) and a list
of trials. Each trial expands into numbered runs that the virtual crew (:mod:`vtrials.trials.crew`) executes
one after another on one ship:

``[[agenda.trial]] kind = "standardization"``
    ``[[agenda.trial.spot]]``: one power setting (an engine order, or r/min and pitch), ``runs`` = 2 or
    3 passes alternating between the base course and its reciprocal (seed 002), optionally with a
    shaft ``trailed`` or ``locked`` (trailed- and locked-shaft series).
``[[agenda.trial]] kind = "log_calibration"``
    ``[[agenda.trial.speed]]``: constant r/min legs, ``pattern`` = ``four_leg`` (four headings 90°
    apart, seed 000) or ``pair`` (a reciprocal pair).
``[[agenda.trial]] kind = "airwake_survey"``
    ``[[agenda.trial.condition]]``: a relative wind over deck to hold (``relative_wind_deg`` off the
    bow, ``relative_wind_kn``, or a fixed shaft setting whose speed the wind then gives), and the
    ``positions`` (deck sockets, ``models/<ship>/airwake.toml`` ``[mast]``) the mobile anemometer mast
    is moved among: one recording of ``record_s`` per position (seed 003: 13 positions, 90 s each).
``[[agenda.trial]] kind = "seakeeping"``
    ``[[agenda.trial.leg]]``: the star pattern of a seakeeping trial (seed 004 Table 1): one leg per
    table, its heading named relative to the mean wave direction the team observes (``head``,
    ``bow_starboard`` … ``following``; the course is resolved by the crew at the start of the leg), a
    setting (order or r/min) and the leg's length (default 25 min); ``station_keeping`` marks the
    low-speed head-seas legs at the start and end.

Everything is checked when the scenario is loaded, before anything runs: unknown trial kinds, a spot
with one run, headings that cannot form a four-leg set, settings the machinery cannot give.
Degrees, knots and r/min exist only here, at the edge; :class:`Run` is SI.
"""

from __future__ import annotations

import dataclasses
import math

from vtrials.errors import InputError
from vtrials.schema import (did_you_mean, check_name, choice, flag, integer, num, read_table, table, table_list, text, unknown_key,
                            vector)
from vtrials.units import DEG, KNOT, RPM

ORDERS = ("ahead_1_3", "ahead_2_3", "standard", "full", "flank")
ALL_ORDERS = ORDERS + ("stop", "back_1_3", "back_2_3", "back_full", "back_emergency")
MANEUVERS = ("turn", "speed_change", "direct_spiral", "reverse_spiral", "zigzag", "pull_out", "backing", "steady")
DIEUDONNE = [15.0, 10.0, 7.5, 5.0, 2.0, 0.0, -2.0, -5.0, -7.5, -10.0, -15.0, -10.0, -7.5, -5.0, -2.0, 0.0, 2.0,
             5.0, 7.5, 10.0, 15.0]


@dataclasses.dataclass(frozen=True)
class Steadiness:
    """How the director judges that the ship has settled (seed 002: torque and log speed are the best
    indicators; shaft speed and heading must be steady too). Each test looks at the instruments over
    the last ``window_s``: the linear trend across the window and the scatter about it."""

    window_s: float = num("length of the look-back window", "s", 10.0, 1800.0, default=60.0)
    rpm_pct: float = num("allowed change of shaft speed across the window (trend)",
                         "%", 0.0, 50.0, lo_open=True, default=0.5)
    torque_pct: float = num("allowed change of shaft torque across the window (trend)", "%", 0.0, 50.0,
                            lo_open=True, default=2.0)
    heading_deg: float = num("allowed mean heading error from the ordered course", "deg", 0.0, 45.0,
                             lo_open=True, default=1.5)
    speed_kn: float = num("allowed change of log speed across the window (trend)", "kn", 0.0, 10.0,
                          lo_open=True, default=0.15)


@dataclasses.dataclass(frozen=True)
class AgendaRules:
    base_course_deg: float = num("base course of the trials (from north, clockwise)", "deg", -360.0, 360.0,
                                 default=0.0)
    autopilot_rudder_deg: float = num("rudder limit of the helm holding course on a run (seed 002: about "
                                      "±3°)", "deg", 0.0, 35.0, lo_open=True, default=3.0)
    turn_rudder_deg: float = num("rudder for Williamson turns and course changes", "deg", 0.0, 45.0,
                                 lo_open=True, default=20.0)
    approach_s: float = num("steady approach from COMEX to EXECUTE", "s", 0.0, 3600.0, default=60.0)
    settle_min_s: float = num("time after a course or setting change before the ship can be judged "
                              "steady", "s", 0.0, 7200.0, default=60.0)
    settle_max_s: float = num("longest wait for steadiness; then the run goes ahead and is flagged",
                              "s", 10.0, 36000.0, default=900.0)
    check_every_s: float = num("how often the director looks at the instruments while waiting", "s",
                               1.0, 600.0, default=10.0)
    measured_course: bool = flag("lay reciprocal runs over the same ground, centred on the site's range "
                                 "centre (run out past it, turn, come back), as on a measured course",
                                 default=True)
    runout_s: float = num("time allowed after a Williamson turn for the ship to settle before COMEX "
                          "(sets how far the crew runs out past the range before turning)", "s", 0.0, 7200.0,
                          default=240.0)
    range_radius_m: float = num("maneuvering runs start within this distance of the range centre (the crew "
                                "steams back first when the ship has wandered off)", "m", 100.0, 1e6,
                                default=4000.0)
    repeat_unsteady: int = integer("repeats allowed for a run whose data window fails the steadiness "
                                   "check", 0, 5, default=1)
    balance_shafts: bool = flag("balance power between shafts (CP: match r/min, trim pitch until the "
                                "torques agree)", default=True)
    balance_tolerance_pct: float = num("torque mismatch between shafts the balancing accepts", "%", 0.0,
                                       50.0, lo_open=True, default=1.0)


@dataclasses.dataclass(frozen=True)
class TrialHead:
    name: str = text("name of the trial (its record file is records/<name>.nc)")
    kind: str = text("kind of trial", ("standardization", "log_calibration", "maneuvering", "airwake_survey",
                                       "seakeeping"))
    run_s: float = num("length of each measured run (EXECUTE to FINEX)", "s", 10.0, 7200.0, default=180.0)
    autopilot_rudder_deg: float = num("override of the agenda's helm rudder limit for this trial", "deg",
                                      0.0, 35.0, lo_open=True, default=None)
    displacement_m3: float = num("ship's displacement for this trial (as the team states it)", "m3", 0.0,
                                 1e7, lo_open=True, default=None)
    trim_m: float = num("trim (aft minus forward draught) for this trial", "m", -10.0, 10.0, default=0.0)


@dataclasses.dataclass(frozen=True)
class Setting:
    """A shaft setting: an engine order, or r/min (and pitch ratio for CP propellers)."""

    order: str = text("engine order (telegraph position; maneuvering runs also stop and astern orders)",
                      ALL_ORDERS, default=None)
    rpm: float = num("shaft speed", "r/min", 0.0, 5000.0, lo_open=True, default=None)
    pitch: float = num("pitch ratio P/D (controllable pitch)", "", -2.0, 3.0, default=None)
    trailed: str = text("shaft that trails (declutched, free-wheeling)", default=None)
    locked: str = text("shaft held at zero r/min", default=None)


@dataclasses.dataclass(frozen=True)
class SpotSpec(Setting):
    runs: int = integer("passes: 2 (base, reciprocal) or 3 (base, reciprocal, base)", 1, 6, default=3)


@dataclasses.dataclass(frozen=True)
class SpeedSpec(Setting):
    pattern: str = text("four_leg: four headings 90° apart; pair: a reciprocal pair", ("four_leg", "pair"),
                        default="four_leg")
    headings_deg: list = vector("headings of the legs (default: base course + 0, 90, 180, 270 or + 0, 180)",
                                "deg", -360.0, 360.0, default=None)
    leg_s: float = num("length of each leg (seed 000: at least 5 min)", "s", 10.0, 7200.0, default=None)


@dataclasses.dataclass(frozen=True, kw_only=True)
class ManeuverSpec(Setting):
    """One maneuvering run: the approach setting (order, or rpm and pitch) and the maneuver."""

    type: str = text("maneuver", MANEUVERS)
    course_deg: float = num("approach course (default: the base course)", "deg", -360.0, 360.0, default=None)
    course: str = text("approach course relative to the wind (zig-zags: seed 002)", ("into_wind", "with_wind"),
                       default=None)
    rudder_deg: float = num("rudder angle (+ starboard): turn, zig-zag, pull-out, backing; speed_change "
                            "with hard_over or cycle", "deg", -45.0, 45.0, default=None)
    heading_change_deg: float = num("turn: FINEX after this heading change (seed 002: 540); pull-out: "
                                    "heading change before the rudder is centred", "deg", 10.0, 3600.0,
                                    default=None)
    check_deg: float = num("zig-zag: heading change that shifts the rudder (default |rudder_deg|)", "deg",
                           0.0, 90.0, lo_open=True, default=None)
    executes: int = integer("zig-zag: rudder executes incl. the first (5 = two and a half cycles)", 2, 20,
                            default=5)
    to_order: str = text("speed_change: engine order given at EXECUTE", ALL_ORDERS, default=None)
    to_rpm: float = num("speed_change: shaft speed ordered at EXECUTE", "r/min", -5000.0, 5000.0, default=None)
    to_pitch: float = num("speed_change: pitch ratio ordered at EXECUTE (CP)", "", -2.0, 3.0, default=None)
    rudder_mode: str = text("speed_change: what the helm does", ("hold_course", "hard_over", "cycle"),
                            default="hold_course")
    cycle_s: float = num("speed_change with rudder_mode = cycle: time between rudder shifts", "s", 5.0, 3600.0,
                         default=30.0)
    sequence_deg: list = vector("direct spiral: rudder settings in order (default Dieudonné 15 R … 15 L … "
                                "15 R)", "deg", -45.0, 45.0, default=None)
    rates_deg_s: list = vector("reverse spiral: rates of turn to hold in order", "deg/s", -20.0, 20.0,
                               default=None)
    hold_s: float = num("spirals: data kept at each setting once it is steady (seed 002: ~2 min); pull-out "
                        "and backing: time after the rudder is centred / put over; steady: length of the "
                        "straight run (seed 003: 60-118 s motion records)", "s", 10.0, 7200.0,
                        default=None)
    max_setting_s: float = num("spirals: give a setting up (reported) if not steady after this", "s", 60.0,
                               36000.0, default=1800.0)
    helm_miss_deg: float = num("spirals: standard deviation of the helmsman's miss of each setting "
                               "(seed 002: hold what was reached)", "deg", 0.0, 5.0, default=0.3)
    max_duration_s: float = num("give up (and report it) if FINEX is not reached within this time after "
                                "EXECUTE", "s", 10.0, 1e5, default=None)


@dataclasses.dataclass(frozen=True, kw_only=True)
class AirwakeCondition(Setting):
    """One wind-over-deck condition of an airwake survey (seed 003: the officer of the watch holds a
    nominally constant relative wind while the mobile mast is moved among the deck positions).
    ``positions`` (a list of deck-socket site names) is read separately (the schema has no string lists)."""

    relative_wind_deg: float = num("relative wind to hold: the direction it comes from, off the bow, + to "
                                   "starboard (seed 003: 0-180)", "deg", -180.0, 360.0)
    relative_wind_kn: float = num("relative wind speed to hold (seed 003: 10-30 kn); the crew sets course and "
                                  "speed for it from the reference anemometer. Omit it to keep a given shaft "
                                  "setting (order or rpm) and set the course only", "kn", 0.0, 80.0, lo_open=True,
                                  default=None)
    record_s: float = num("recording at each mast position (seed 003: 90 s; 60 s at full speed)", "s", 10.0, 600.0,
                          default=90.0)
    move_s: float = num("time to unstep the mast and step it in the next socket (data not used)", "s", 0.0, 3600.0,
                        default=60.0)
    wind_tolerance_deg: float = num("relative wind direction the crew accepts as on the ordered one", "deg", 0.0,
                                    45.0, lo_open=True, default=5.0)
    wind_tolerance_kn: float = num("relative wind speed the crew accepts as on the ordered one", "kn", 0.0, 20.0,
                                   lo_open=True, default=1.5)
# angle off the bow [deg] from which the waves come on each named seakeeping leg (+ starboard);
# the ordered course is the observed mean wave direction (from) minus this angle
WAVE_RELATIVE_DEG = {"head": 0.0, "bow_starboard": 45.0, "beam_starboard": 90.0, "quarter_starboard": 135.0,
                     "following": 180.0, "quarter_port": -135.0, "beam_port": -90.0, "bow_port": -45.0}


@dataclasses.dataclass(frozen=True, kw_only=True)
class SeakeepingLeg(Setting):
    """One leg of a seakeeping star pattern (seed 004 Table 1): a heading relative to the waves and a
    setting, held for ``leg_s`` by the course-keeping helm while the motions are recorded."""

    heading: str = text("where the waves come from relative to the bow", tuple(WAVE_RELATIVE_DEG))
    leg_s: float = num("length of the leg, EXECUTE to FINEX (seed 004: about 25 min)", "s", 60.0, 7200.0,
                       default=1500.0)
    station_keeping: bool = flag("a station-keeping leg (low speed, head seas) at the start or end of the "
                                 "pattern", default=False)
    label: str = text("name of the leg in the log (default: heading and setting)", default=None)


@dataclasses.dataclass(frozen=True)
class Run:
    """One numbered run of the agenda (SI)."""

    number: int  # 1.. within the agenda
    trial: str
    kind: str  # "speed" (a measured straight run)
    heading: float  # ordered course [rad]
    rps: float  # ordered shaft speed [rev/s]
    pitch: float | None  # ordered pitch ratio (CP) or None
    modes: tuple  # per shaft "governed" | "trailed" | "locked"
    duration: float  # EXECUTE → FINEX [s]
    helm_limit: float  # rudder limit on the run [rad]
    group: int  # spot (standardization) or speed group (log calibration), 1..
    leg: int  # pass within its group, 1..
    label: str  # e.g. "spot 3 run 2"
    order: str | None = None  # engine order, when the setting is one
    params: dict = dataclasses.field(default_factory=dict)  # the maneuver (SI), for maneuvering runs


@dataclasses.dataclass
class Trial:
    head: TrialHead
    runs: list


@dataclasses.dataclass
class Agenda:
    rules: AgendaRules
    steadiness: Steadiness
    trials: list

    @property
    def runs(self) -> list[Run]:
        return [r for t in self.trials for r in t.runs]


_ITEMS = {"standardization": ("spot", SpotSpec), "log_calibration": ("speed", SpeedSpec),
          "maneuvering": ("run", ManeuverSpec), "airwake_survey": ("condition", AirwakeCondition),
          "seakeeping": ("leg", SeakeepingLeg)}


def _setting(s: Setting, vessel, f: str, sec: str) -> tuple[float, float | None, tuple, str | None]:
    """(rps, pitch, modes, order) of a setting, checked against the vessel."""
    if (s.order is None) == (s.rpm is None):
        raise InputError(f, sec, "give either order or rpm (not both)")
    cp = any(sh.controllable_pitch for sh in vessel.shafts)
    if s.order is not None:
        if s.order not in vessel.telegraph:
            raise InputError(f, f"{sec}.order", f"{vessel.name} has no telegraph position {s.order!r}{did_you_mean(s.order, vessel.telegraph)} (it has "
                                                f"{', '.join(vessel.telegraph)})")
        rps, pitch = vessel.telegraph[s.order]
        if s.pitch is not None:
            raise InputError(f, f"{sec}.pitch", "an engine order sets the pitch; give rpm with pitch instead")
    else:
        rps = s.rpm * RPM
        pitch = s.pitch
        if cp and pitch is None:
            raise InputError(f, f"{sec}.pitch", f"{vessel.name} has controllable-pitch propellers: give the "
                                                f"pitch ratio with rpm")
        if not cp and pitch is not None:
            raise InputError(f, f"{sec}.pitch", f"{vessel.name} has fixed-pitch propellers")
    for sh in vessel.shafts:
        if abs(rps) > sh.max_rps * (1 + 1e-9):
            raise InputError(f, f"{sec}.rpm", f"{rps / RPM:.1f} r/min is above the {sh.max_rps / RPM:.1f} r/min "
                                              f"of shaft {sh.name!r}")
        if pitch is not None and sh.controllable_pitch and not sh.pitch_min <= pitch <= sh.pitch_max:
            raise InputError(f, f"{sec}.pitch", f"P/D {pitch:g} is outside [{sh.pitch_min:g}, {sh.pitch_max:g}] "
                                                f"of shaft {sh.name!r}")
    names = [sh.name for sh in vessel.shafts]
    modes = ["governed"] * len(names)
    for field in ("trailed", "locked"):
        val = getattr(s, field)
        if val is None:
            continue
        if val not in names:
            raise InputError(f, f"{sec}.{field}", f"unknown shaft {val!r}{did_you_mean(val, names)} (shafts of {vessel.name}: "
                                                  f"{', '.join(names)})")
        if modes[names.index(val)] != "governed":
            raise InputError(f, f"{sec}.{field}", "a shaft cannot be trailed and locked at once")
        modes[names.index(val)] = field
    if all(m != "governed" for m in modes):
        raise InputError(f, sec, "no shaft would be left driving")
    return rps, pitch, tuple(modes), s.order


def _four_leg_ok(h: list[float]) -> bool:
    """Four headings forming a four-leg set: consecutive legs 90° apart (either way round)."""
    d = [((h[k + 1] - h[k] + 180.0) % 360.0) - 180.0 for k in range(3)]
    return all(abs(abs(x) - 90.0) < 1.0 for x in d) and (all(x > 0 for x in d) or all(x < 0 for x in d))


def load_agenda(doc: dict, vessel, f: str) -> Agenda:
    """Read and check ``[agenda]`` (``doc`` is that table)."""
    if not isinstance(doc, dict):
        raise InputError(f, "agenda", "expected a table")
    doc = dict(doc)
    trials_tab = doc.pop("trial", None)
    st_tab = table(doc.pop("steadiness", None), f, "agenda.steadiness")
    rules, _ = read_table(AgendaRules, doc, f, "agenda")
    steadiness, _ = read_table(Steadiness, st_tab, f, "agenda.steadiness")
    if not isinstance(trials_tab, list) or not trials_tab:
        raise InputError(f, "agenda.trial", "expected at least one [[agenda.trial]] table")
    table_list(trials_tab, f, "agenda.trial")
    trials = []
    number = 0
    names = set()
    base = rules.base_course_deg
    course_now = 0  # runs alternate between the base course (0) and its reciprocal (1) across the agenda
    max_rudder = math.degrees(vessel.max_rudder)
    for it, tab in enumerate(trials_tab):
        sec = f"agenda.trial[{it}]"
        if not isinstance(tab, dict):
            raise InputError(f, sec, "expected a table")
        kind = choice(tab.get("kind"), _ITEMS, f, f"{sec}.kind", "trial kind")
        if "name" in tab:
            check_name(tab["name"], f, f"{sec}.name")
        item_key, item_cls = _ITEMS[kind]
        tab = dict(tab)
        items = tab.pop(item_key, None)
        head, _ = read_table(TrialHead, tab, f, sec)
        if head.name in names:
            raise InputError(f, f"{sec}.name", f"duplicate trial name {head.name!r}")
        names.add(head.name)
        if head.displacement_m3 is not None:
            d0 = vessel.particulars.displacement
            if abs(head.displacement_m3 / d0 - 1.0) > 0.005:
                raise InputError(f, f"{sec}.displacement_m3", f"{vessel.name} is modelled at one loading "
                                                              f"condition, {d0:.1f} m3; other displacements "
                                                              f"need their own model folder")
        if head.trim_m != 0.0:
            raise InputError(f, f"{sec}.trim_m", f"{vessel.name} is modelled at even keel; only 0 is allowed")
        limit = (head.autopilot_rudder_deg or rules.autopilot_rudder_deg)
        if limit > max_rudder:
            raise InputError(f, f"{sec}.autopilot_rudder_deg", f"{limit:g}° is beyond the maximum rudder angle "
                                                               f"of {vessel.name} ({max_rudder:g}°)")
        if not isinstance(items, list) or not items:
            raise InputError(f, f"{sec}.{item_key}", f"expected at least one [[agenda.trial.{item_key}]] table")
        table_list(items, f, f"{sec}.{item_key}")
        runs = []
        if kind == "airwake_survey":
            for ii, itab in enumerate(items):
                runs += _airwake_runs(itab, number, head.name, ii, base, limit, vessel, f, f"{sec}.{item_key}[{ii}]")
                number = runs[-1].number
            trials.append(Trial(head, runs))
            continue
        for ii, itab in enumerate(items):
            isec = f"{sec}.{item_key}[{ii}]"
            spec, _ = read_table(item_cls, itab, f, isec)
            rps, pitch, modes, order = _setting(spec, vessel, f, isec)
            if kind == "maneuvering":
                runs.append(_maneuver_run(spec, number + 1, head.name, ii, rps, pitch, modes, order, base, limit,
                                          vessel, f, isec))
                number += 1
                continue
            if kind == "seakeeping":
                runs.append(_seakeeping_run(spec, number + 1, head.name, ii, rps, pitch, modes, order, base, limit,
                                            f, isec))
                number += 1
                continue
            if spec.order is not None and spec.order not in ORDERS:
                raise InputError(f, f"{isec}.order", f"a {kind} run needs an ahead order ({', '.join(ORDERS)})")
            if kind == "standardization":
                if spec.runs < 2:
                    raise InputError(f, f"{isec}.runs", f"a spot needs at least 2 runs (base course and its "
                                                        f"reciprocal) to eliminate the current; got {spec.runs}")
                headings = []
                for k in range(spec.runs):
                    headings.append(base + 180.0 * ((course_now + k) % 2))
                course_now = (course_now + spec.runs) % 2
                dur = head.run_s
            else:
                n_legs = 4 if spec.pattern == "four_leg" else 2
                if spec.headings_deg is None:
                    step = 90.0 if n_legs == 4 else 180.0
                    headings = [base + step * k for k in range(n_legs)]
                else:
                    headings = list(spec.headings_deg)
                    if len(headings) != n_legs:
                        raise InputError(f, f"{isec}.headings_deg", f"a {spec.pattern} pattern has {n_legs} legs; "
                                                                    f"got {len(headings)} headings")
                    if n_legs == 4 and not _four_leg_ok(headings):
                        raise InputError(f, f"{isec}.headings_deg",
                                         f"{headings} cannot form a four-leg set: consecutive legs must be "
                                         f"90° apart, turning the same way (e.g. [10, 100, 190, 280])")
                    if n_legs == 2 and abs(abs(((headings[1] - headings[0] + 180) % 360) - 180) - 180) > 1.0:
                        raise InputError(f, f"{isec}.headings_deg", f"{headings} is not a reciprocal pair")
                dur = spec.leg_s or head.run_s
            for k, h in enumerate(headings):
                number += 1
                what = "spot" if kind == "standardization" else "speed"
                runs.append(Run(number, head.name, "speed", h * DEG, rps, pitch, modes, dur, limit * DEG,
                                ii + 1, k + 1, f"{what} {ii + 1} run {k + 1}", order))
        trials.append(Trial(head, runs))
    return Agenda(rules, steadiness, trials)


def _airwake_runs(itab: dict, number: int, trial: str, index: int, base: float, limit: float, vessel, f: str,
                  sec: str) -> list[Run]:
    """One run per mast position of an airwake-survey condition (SI)."""
    from vtrials.instruments.airwake import load_airwake
    if not isinstance(itab, dict):
        raise InputError(f, sec, "expected a table")
    itab = dict(itab)
    positions = itab.pop("positions", None)
    spec, _ = read_table(AirwakeCondition, itab, f, sec)
    aw = load_airwake(vessel.folder, vessel.sites)
    sockets = list(aw.mast_positions) if aw is not None else []
    if not sockets:
        raise InputError(f, f"{sec}.positions", f"{vessel.name} has no mobile-mast positions (models/"
                                                f"{vessel.name}/airwake.toml [mast] positions)")
    if not isinstance(positions, list) or not positions or not all(isinstance(x, str) for x in positions):
        raise InputError(f, f"{sec}.positions", f"expected a non-empty list of deck positions (allowed: "
                                                f"{', '.join(sockets)}), got {positions!r}"[:300])
    for k, x in enumerate(positions):
        if x not in sockets:
            raise InputError(f, f"{sec}.positions[{k}]", f"{x!r} is not a mast position of {vessel.name}"
                                                         f"{did_you_mean(x, sockets)} (allowed: {', '.join(sockets)})")
    if len(set(positions)) != len(positions):
        raise InputError(f, f"{sec}.positions", "a position is listed twice")
    given = spec.order is not None or spec.rpm is not None
    if given == (spec.relative_wind_kn is not None):
        raise InputError(f, f"{sec}.relative_wind_kn", "give either relative_wind_kn (the crew sets the speed) or a "
                                                       "shaft setting (order, or rpm and pitch), not both")
    if given:
        rps, pitch, modes, order = _setting(spec, vessel, f, sec)
        if order is not None and order not in ORDERS:
            raise InputError(f, f"{sec}.order", f"an airwake survey needs an ahead order ({', '.join(ORDERS)})")
    else:  # a starting setting; the crew adjusts the speed for the ordered relative wind
        order = next((o for o in ORDERS if o in vessel.telegraph), None)
        if order is None:
            raise InputError(f, f"{sec}.relative_wind_kn", f"{vessel.name} has no ahead telegraph order to set "
                                                           f"speeds from; give rpm instead")
        rps, pitch = vessel.telegraph[order]
        modes = ("governed",) * len(vessel.shafts)
    gamma = ((spec.relative_wind_deg + 180.0) % 360.0) - 180.0
    params = {"relative_wind": gamma * DEG, "relative_wind_speed": None if spec.relative_wind_kn is None
              else spec.relative_wind_kn * KNOT, "move_s": spec.move_s, "hold_speed": not given,
              "wind_tolerance": spec.wind_tolerance_deg * DEG, "wind_speed_tolerance": spec.wind_tolerance_kn * KNOT}
    runs = []
    for k, pos in enumerate(positions):
        wind = f"{gamma:g}°" + ("" if spec.relative_wind_kn is None else f"/{spec.relative_wind_kn:g} kn")
        runs.append(Run(number + k + 1, trial, "airwake", base * DEG, rps, pitch, tuple(modes), spec.record_s,
                        limit * DEG, index + 1, k + 1, f"wind {wind} at {pos}"[:40], order if given else None,
                        {**params, "position": pos}))
    return runs


def _maneuver_run(m: ManeuverSpec, number: int, trial: str, index: int, rps, pitch, modes, order, base: float,
                  limit: float, vessel, f: str, sec: str) -> Run:
    """Check one maneuvering run and convert it to SI."""
    max_rudder = math.degrees(vessel.max_rudder)
    need = {"turn": ("rudder_deg",), "zigzag": ("rudder_deg",), "pull_out": ("rudder_deg",),
            "backing": ("rudder_deg",), "reverse_spiral": ("rates_deg_s",)}
    for field in need.get(m.type, ()):
        if getattr(m, field) is None:
            raise InputError(f, f"{sec}.{field}", f"a {m.type} run needs {field}")
    if m.rudder_deg is not None and abs(m.rudder_deg) > max_rudder + 1e-9:
        raise InputError(f, f"{sec}.rudder_deg", f"{m.rudder_deg:g}° is beyond the maximum rudder angle of "
                                                 f"{vessel.name} ({max_rudder:g}°)")
    if m.type == "zigzag" and m.rudder_deg == 0:
        raise InputError(f, f"{sec}.rudder_deg", "a zig-zag needs a non-zero rudder (its sign: the first side)")
    if m.course is not None and m.course_deg is not None:
        raise InputError(f, f"{sec}.course", "give course or course_deg, not both")
    p: dict = {"type": m.type}
    if m.type == "speed_change":
        if (m.to_order is None) == (m.to_rpm is None):
            raise InputError(f, f"{sec}.to_order", "a speed_change needs to_order or to_rpm (not both)")
        if m.to_order is not None:
            if m.to_order not in vessel.telegraph:
                raise InputError(f, f"{sec}.to_order", f"{vessel.name} has no telegraph position {m.to_order!r}"
                                                      f"{did_you_mean(m.to_order, vessel.telegraph)}")
            p["to_rps"], p["to_pitch"] = vessel.telegraph[m.to_order]
            p["to_order"] = m.to_order
        else:
            p["to_rps"], p["to_pitch"] = m.to_rpm * RPM, m.to_pitch
            if any(sh.controllable_pitch for sh in vessel.shafts) and m.to_pitch is None:
                raise InputError(f, f"{sec}.to_pitch", f"{vessel.name} has controllable-pitch propellers: give "
                                                       f"to_pitch with to_rpm")
            for sh in vessel.shafts:
                if abs(p["to_rps"]) > sh.max_rps * (1 + 1e-9):
                    raise InputError(f, f"{sec}.to_rpm", f"{m.to_rpm:g} r/min is beyond shaft {sh.name!r}")
        p["rudder_mode"] = m.rudder_mode
        p["cycle_s"] = m.cycle_s
        if m.rudder_mode != "hold_course" and m.rudder_deg is None:
            raise InputError(f, f"{sec}.rudder_deg", f"rudder_mode {m.rudder_mode!r} needs rudder_deg")
    if m.type == "direct_spiral":
        seq = DIEUDONNE if m.sequence_deg is None else list(m.sequence_deg)
        if len(seq) < 3:
            raise InputError(f, f"{sec}.sequence_deg", "a spiral needs at least 3 rudder settings")
        for k, d in enumerate(seq):
            if abs(d) > max_rudder + 1e-9:
                raise InputError(f, f"{sec}.sequence_deg[{k}]", f"{d:g}° is beyond the maximum rudder angle "
                                                                f"({max_rudder:g}°)")
        p["sequence"] = [d * DEG for d in seq]
    if m.type == "reverse_spiral":
        if len(m.rates_deg_s) < 3:
            raise InputError(f, f"{sec}.rates_deg_s", "a reverse spiral needs at least 3 rates of turn")
        p["rates"] = [r * DEG for r in m.rates_deg_s]
    defaults_hold = {"direct_spiral": 120.0, "reverse_spiral": 120.0, "pull_out": 300.0, "backing": 300.0,
                     "steady": 90.0}  # seed 003: the usual airwake-trial record is 90 s
    p["hold_s"] = m.hold_s if m.hold_s is not None else defaults_hold.get(m.type, 0.0)
    p["max_setting_s"] = m.max_setting_s
    p["helm_miss"] = m.helm_miss_deg * DEG
    if m.rudder_deg is not None:
        p["rudder"] = m.rudder_deg * DEG
    if m.type == "turn":
        p["heading_change"] = (m.heading_change_deg or 540.0) * DEG
    if m.type == "pull_out":
        p["heading_change"] = (m.heading_change_deg or 360.0) * DEG
    if m.type == "zigzag":
        p["check"] = (m.check_deg if m.check_deg is not None else abs(m.rudder_deg)) * DEG
        p["executes"] = m.executes
    p["max_duration_s"] = m.max_duration_s
    p["course_rule"] = m.course
    heading = (m.course_deg if m.course_deg is not None else base) * DEG
    what = {"turn": "turn", "speed_change": "speed change", "direct_spiral": "direct spiral",
            "reverse_spiral": "reverse spiral", "zigzag": "zig-zag", "pull_out": "pull-out",
            "backing": "backing", "steady": "steady run"}[m.type]
    extra = "" if m.rudder_deg is None else f" {abs(m.rudder_deg):g}°{'S' if m.rudder_deg > 0 else 'P'}"
    if m.type == "zigzag":
        extra = f" {abs(m.rudder_deg):g}/{p['check'] / DEG:g} {'S' if m.rudder_deg > 0 else 'P'}"
    if m.type == "speed_change":
        extra = f" → {p.get('to_order') or f'{m.to_rpm:g} r/min'}"
    return Run(number, trial, m.type, heading, rps, pitch, modes, m.max_duration_s or 0.0, limit * DEG, index + 1, 1,
               f"{what}{extra}"[:40], order, p)


def _seakeeping_run(leg: SeakeepingLeg, number: int, trial: str, index: int, rps, pitch, modes, order,
                    base: float, limit: float, f: str, sec: str) -> Run:
    """One seakeeping leg in SI: the course is resolved at sea from the observed wave direction
    (``params['wave_relative']``, rad); ``heading`` holds the base course until then."""
    if leg.station_keeping and leg.heading != "head":
        raise InputError(f, f"{sec}.heading", f"a station-keeping leg is held head to the sea; got {leg.heading!r}")
    if order is not None and order not in ORDERS:
        raise InputError(f, f"{sec}.order", f"a seakeeping leg needs an ahead order ({', '.join(ORDERS)}); "
                                            f"got {order!r}")
    setting = order if order is not None else f"{leg.rpm:g} rpm"
    label = leg.label or (f"{'station keeping' if leg.station_keeping else leg.heading.replace('_', ' ')} "
                          f"{setting}")[:40]
    p = {"type": "seakeeping", "wave_relative": WAVE_RELATIVE_DEG[leg.heading] * DEG, "wave_heading": leg.heading,
         "station_keeping": bool(leg.station_keeping)}
    return Run(number, trial, "seakeeping", base * DEG, rps, pitch, modes, leg.leg_s, limit * DEG, index + 1, 1,
               label, order, p)


def agenda_keys() -> list[str]:
    return [f.name for f in dataclasses.fields(AgendaRules)] + ["steadiness", "trial"]


__all__ = ["Agenda", "AgendaRules", "Run", "SeakeepingLeg", "Steadiness", "Trial", "WAVE_RELATIVE_DEG", "load_agenda",
           "unknown_key"]
