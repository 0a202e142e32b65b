"""Trial agendas: the trials director's run-by-run schedule, read from a scenario's ``[agenda]``.

An agenda names the general rules of the day (base course, the helmsman's rudder limit on a run,
approach and settling times, how steadiness is judged, whether unsteady runs are repeated) and a list
of trials. Each trial expands into numbered runs that the virtual crew (:mod:`vtrials.crew`) executes
one after another on one ship:

``[[agenda.trial]] kind = "standardization"``
    ``[[agenda.trial.spot]]``: one power setting (an engine order, or r/min and pitch), ``runs`` = 2 or
    3 passes alternating between the base course and its reciprocal (seed 002), optionally with a
    shaft ``trailed`` or ``locked`` (trailed- and locked-shaft series).
``[[agenda.trial]] kind = "log_calibration"``
    ``[[agenda.trial.speed]]``: constant r/min legs, ``pattern`` = ``four_leg`` (four headings 90°
    apart, seed 000) or ``pair`` (a reciprocal pair).

Everything is checked when the scenario is loaded, before anything runs: unknown trial kinds, a spot
with one run, headings that cannot form a four-leg set, settings the machinery cannot give.
Degrees, knots and r/min exist only here, at the edge; :class:`Run` is SI.
"""

from __future__ import annotations

import dataclasses
import math

from .errors import InputError
from .schema import flag, integer, num, read_table, text, unknown_key, vector
from .units import DEG, RPM

ORDERS = ("ahead_1_3", "ahead_2_3", "standard", "full", "flank")


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
    repeat_unsteady: int = integer("repeats allowed for a run whose data window fails the steadiness "
                                   "check", 0, 5, default=1)
    balance_shafts: bool = flag("balance power between shafts (CP: match r/min, trim pitch until the "
                                "torques agree)", default=True)
    balance_tolerance_pct: float = num("torque mismatch between shafts the balancing accepts", "%", 0.0,
                                       50.0, lo_open=True, default=1.0)


@dataclasses.dataclass(frozen=True)
class TrialHead:
    name: str = text("name of the trial (its record file is records/<name>.nc)")
    kind: str = text("kind of trial", ("standardization", "log_calibration"))
    run_s: float = num("length of each measured run (EXECUTE to FINEX)", "s", 10.0, 7200.0, default=180.0)
    autopilot_rudder_deg: float = num("override of the agenda's helm rudder limit for this trial", "deg",
                                      0.0, 35.0, lo_open=True, default=None)
    displacement_m3: float = num("ship's displacement for this trial (as the team states it)", "m3", 0.0,
                                 1e7, lo_open=True, default=None)
    trim_m: float = num("trim (aft minus forward draught) for this trial", "m", -10.0, 10.0, default=0.0)


@dataclasses.dataclass(frozen=True)
class Setting:
    """A shaft setting: an engine order, or r/min (and pitch ratio for CP propellers)."""

    order: str = text("engine order (telegraph position)", ORDERS, default=None)
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


_ITEMS = {"standardization": ("spot", SpotSpec), "log_calibration": ("speed", SpeedSpec)}


def _setting(s: Setting, vessel, f: str, sec: str) -> tuple[float, float | None, tuple, str | None]:
    """(rps, pitch, modes, order) of a setting, checked against the vessel."""
    if (s.order is None) == (s.rpm is None):
        raise InputError(f, sec, "give either order or rpm (not both)")
    cp = any(sh.controllable_pitch for sh in vessel.shafts)
    if s.order is not None:
        if s.order not in vessel.telegraph:
            raise InputError(f, f"{sec}.order", f"{vessel.name} has no telegraph position {s.order!r} (it has "
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
        if rps > sh.max_rps * (1 + 1e-9):
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
            raise InputError(f, f"{sec}.{field}", f"unknown shaft {val!r} (shafts of {vessel.name}: "
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
    st_tab = doc.pop("steadiness", {})
    rules, _ = read_table(AgendaRules, doc, f, "agenda")
    steadiness, _ = read_table(Steadiness, st_tab, f, "agenda.steadiness")
    if not isinstance(trials_tab, list) or not trials_tab:
        raise InputError(f, "agenda.trial", "expected at least one [[agenda.trial]] table")
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
        kind = tab.get("kind")
        if kind not in _ITEMS:
            raise InputError(f, f"{sec}.kind", f"unknown trial kind {kind!r} (allowed: {', '.join(_ITEMS)})")
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
        runs = []
        for ii, itab in enumerate(items):
            isec = f"{sec}.{item_key}[{ii}]"
            spec, _ = read_table(item_cls, itab, f, isec)
            rps, pitch, modes, order = _setting(spec, vessel, f, isec)
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


def agenda_keys() -> list[str]:
    return [f.name for f in dataclasses.fields(AgendaRules)] + ["steadiness", "trial"]


__all__ = ["Agenda", "AgendaRules", "Run", "Steadiness", "Trial", "load_agenda", "unknown_key"]
