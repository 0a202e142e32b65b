"""Maneuver kinds a scenario can list: what the helm and the telegraph do, when the run ends, and
which truth to report.

Each maneuver is one ship of the batch. It starts from the scenario's initial condition (or its own
approach order or speed), holds the approach course with the autopilot for ``approach_s``
(default: three ship lengths' travel time), then EXECUTEs. Shafts named in ``trailed_shaft`` /
``locked_shaft`` run that way from the start of the approach.

Kinds: ``turning_circle``, ``zigzag``, ``williamson``, ``course_keeping``, ``rudder_step``,
``crash_stop``, ``speed_change``. Rudder angles are positive to starboard (the ship turns to
starboard).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.physics import steering as H
from vtrials.truth import metrics as TM
from vtrials.schema import integer, num, text
from vtrials.units import DEG

ORDER_CHOICES = ("ahead_1_3", "ahead_2_3", "standard", "full", "flank", "stop",
                 "back_1_3", "back_2_3", "back_full", "back_emergency")


@dataclasses.dataclass(frozen=True)
class Progress:
    """Where a running maneuver stands, as the crew sees it (times after EXECUTE)."""

    elapsed: float  # since EXECUTE [s]
    heading_change: float  # since EXECUTE [rad], signed
    helm_phase: int  # index of the helm phase running
    phase_elapsed: float  # since the running helm phase began [s]
    settle: float  # default settling time of this ship [s]
    surge: float = 0.0  # surge speed through the water [m/s]
    speed_rate: float = math.inf  # recent rate of change of the speed through the water [m/s²]


@dataclasses.dataclass(frozen=True)
class Execute:
    """What happens at EXECUTE: a helm programme and, optionally, a new engine order."""

    helm: list
    order: str | None = None


@dataclasses.dataclass(frozen=True, kw_only=True)
class Maneuver:
    """Fields every maneuver has."""

    name: str = text("name of this maneuver (unique in the scenario)")
    approach_s: float = num("steady approach before EXECUTE (default: 3 L/U)", "s", 0.0, 1e5, default=None)
    max_duration_s: float = num("give up (and report it) if FINEX is not reached within this time after "
                                "EXECUTE (default: 60 L/U)", "s", 1.0, 1e6, default=None)
    approach_order: str = text("approach at the steady speed of this engine order instead of the scenario's "
                               "initial condition", ORDER_CHOICES, default=None)
    approach_speed_kn: float = num("approach at this speed (self-propelled) instead of the scenario's initial "
                                   "condition", "kn", 0.0, 60.0, default=None)
    trailed_shaft: str = text("name of a shaft that trails (declutched, free-wheeling) throughout", default=None)
    locked_shaft: str = text("name of a shaft held at zero r/min throughout", default=None)

    kind = "maneuver"

    def rudders(self) -> list[tuple[str, float]]:
        """(field, angle in degrees) of every rudder angle this maneuver orders (checked on load)."""
        return []

    def execute(self, psi0: float, ap: tuple) -> Execute:
        raise NotImplementedError

    def finished(self, p: Progress) -> bool:
        raise NotImplementedError

    def truth(self, tr: dict) -> dict:
        raise NotImplementedError


def _heel(tr: dict, steady: np.ndarray | None = None) -> dict:
    roll = np.degrees(tr["roll"])
    k = int(np.argmax(np.abs(roll)))
    out = {"max_heel_deg": float(roll[k])}
    if steady is not None and np.any(steady):
        out["steady_heel_deg"] = float(np.mean(roll[steady]))
    return out


@dataclasses.dataclass(frozen=True, kw_only=True)
class TurningCircle(Maneuver):
    """Rudder put over at EXECUTE and held, shafts unchanged; FINEX after ``heading_change_deg`` of turn."""

    rudder_deg: float = num("rudder angle, + starboard / − port", "deg", -90.0, 90.0)
    heading_change_deg: float = num("FINEX after this much heading change", "deg", 90.0, 3600.0, default=720.0)
    kind = "turning_circle"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def execute(self, psi0, ap):
        return Execute([(H.HOLD, self.rudder_deg * DEG)])

    def finished(self, p):
        return abs(p.heading_change) >= self.heading_change_deg * DEG

    def truth(self, tr):
        out = TM.turning(tr["t"], tr["x_w"], tr["y_w"], tr["heading"], tr["u_r"], tr["v_r"], tr["r"])
        dpsi = np.abs(tr["heading"] - tr["heading"][0])
        total = float(dpsi[-1])
        lo, hi = (2 * math.pi, 4 * math.pi) if total >= 4 * math.pi else (total - 2 * math.pi, total)
        out.update(_heel(tr, (dpsi >= lo) & (dpsi <= hi) if lo >= math.pi / 2 else None))
        return out


@dataclasses.dataclass(frozen=True, kw_only=True)
class ZigZag(Maneuver):
    """δ/ψ zig-zag: rudder ±δ shifted whenever the heading deviation reaches ±ψ."""

    rudder_deg: float = num("rudder angle δ of the zig-zag", "deg", 0.0, 90.0, lo_open=True)
    heading_deg: float = num("heading deviation ψ at which the rudder is shifted", "deg", 0.0, 90.0, lo_open=True)
    first_side: str = text("side of the first rudder order", ("starboard", "port"))
    rudder_shifts: int = integer("FINEX at this rudder shift (4: two full cycles)", 3, 40, default=4)
    kind = "zigzag"

    @property
    def side(self) -> int:
        return 1 if self.first_side == "starboard" else -1

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def execute(self, psi0, ap):
        return Execute([(H.ZIGZAG, self.rudder_deg * DEG, self.heading_deg * DEG, psi0, float(self.side),
                         float(self.rudder_shifts)), (H.HOLD, 0.0)])

    def finished(self, p):
        return p.helm_phase >= 1

    def truth(self, tr):
        return TM.zigzag(tr["t"], tr["heading"], rudder_deg=self.rudder_deg, heading_deg=self.heading_deg,
                         first_side=self.side)


@dataclasses.dataclass(frozen=True, kw_only=True)
class Williamson(Maneuver):
    """Williamson turn: rudder to one side until the heading has changed by ``deviation_deg``, then
    the same rudder the other way until within ``window_deg`` of the reciprocal course, then the
    autopilot steadies the ship on the reciprocal for ``settle_s``."""

    rudder_deg: float = num("rudder angle used both ways", "deg", 0.0, 90.0, lo_open=True)
    first_side: str = text("side of the first rudder order", ("starboard", "port"))
    deviation_deg: float = num("heading change at which the rudder is reversed", "deg", 10.0, 120.0, default=60.0)
    window_deg: float = num("hand over to the autopilot this far short of the reciprocal", "deg", 0.0, 90.0,
                            default=20.0)
    settle_s: float = num("time on autopilot after hand-over before FINEX (default: 10 L/U)", "s", 0.0, 1e5,
                          default=None)
    kind = "williamson"

    @property
    def side(self) -> int:
        return 1 if self.first_side == "starboard" else -1

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def execute(self, psi0, ap):
        s = self.side
        d = self.rudder_deg * DEG
        back = -s * (math.pi - self.window_deg * DEG)
        return Execute([(H.TURN_UNTIL, s * d, s * self.deviation_deg * DEG, 0.0, 0.0),
                        (H.TURN_UNTIL, -s * d, back, psi0, 1.0),
                        (H.HEADING, psi0 - s * math.pi, *ap)])

    def finished(self, p):
        settle = p.settle if self.settle_s is None else self.settle_s
        return p.helm_phase >= 2 and p.phase_elapsed >= settle

    def truth(self, tr):
        t, psi = tr["t"], tr["heading"]
        s = self.side
        dpsi = s * (psi - psi[0])
        along, cross = _track_axes(tr)
        out = {"max_heading_change_deg": float(np.degrees(np.max(dpsi))),
               "max_advance_m": float(np.max(along)),
               "max_transfer_m": float(np.max(np.abs(cross)))}
        err = np.degrees(np.abs(np.angle(np.exp(1j * (psi - psi[0] - math.pi)))))
        on = np.flatnonzero(err <= 1.0)
        if on.size:
            k = int(on[0])
            out["time_to_reciprocal_s"] = float(t[k] - t[0])
            out["cross_track_at_reciprocal_m"] = float(cross[k])
            out["along_track_at_reciprocal_m"] = float(along[k])
            out["speed_at_reciprocal_mps"] = float(np.hypot(tr["u_r"][k], tr["v_r"][k]))
        return out


def _track_axes(tr: dict) -> tuple[np.ndarray, np.ndarray]:
    """Water track from EXECUTE along and across (+ starboard) the heading at EXECUTE."""
    psi0 = tr["heading"][0]
    c, sn = math.cos(psi0), math.sin(psi0)
    ex, ey = tr["x_w"] - tr["x_w"][0], tr["y_w"] - tr["y_w"][0]
    return ex * c + ey * sn, -ex * sn + ey * c


def _shaft_power(tr: dict) -> dict:
    out = {}
    k = 0
    while f"shaft_n_{k}" in tr:
        n = tr[f"shaft_n_{k}"]
        out[f"mean_shaft_rps_{k}"] = float(np.mean(n))
        out[f"mean_shaft_power_W_{k}"] = float(np.mean(2 * math.pi * n * tr[f"engine_torque_{k}"]))
        k += 1
    return out


@dataclasses.dataclass(frozen=True, kw_only=True)
class CourseKeeping(Maneuver):
    """Hold the approach heading on autopilot for ``duration_s`` (a straight run)."""

    duration_s: float = num("length of the run after EXECUTE", "s", 0.0, 1e6, lo_open=True)
    kind = "course_keeping"

    def execute(self, psi0, ap):
        return Execute([(H.HEADING, psi0, *ap)])

    def finished(self, p):
        return p.elapsed >= self.duration_s

    def truth(self, tr):
        U = np.hypot(tr["u_r"], tr["v_r"])
        out = {"mean_speed_mps": float(np.mean(U)),
               "heading_rms_deg": float(np.degrees(np.sqrt(np.mean((tr["heading"] - tr["heading"][0]) ** 2)))),
               "rudder_mean_deg": float(np.degrees(np.mean(tr["rudder_0"]))),
               "rudder_rms_deg": float(np.degrees(np.sqrt(np.mean(tr["rudder_0"] ** 2)))),
               "mean_drift_angle_deg": float(np.degrees(np.mean(np.arctan2(-tr["v_r"], tr["u_r"])))),
               "mean_heel_deg": float(np.degrees(np.mean(tr["roll"])))}
        out.update(_shaft_power(tr))
        return out


@dataclasses.dataclass(frozen=True, kw_only=True)
class RudderStep(Maneuver):
    """Rudder put to ``rudder_deg`` at EXECUTE and held for ``duration_s``."""

    rudder_deg: float = num("rudder angle, + starboard / − port", "deg", -90.0, 90.0)
    duration_s: float = num("length of the run after EXECUTE", "s", 0.0, 1e6, lo_open=True)
    kind = "rudder_step"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def execute(self, psi0, ap):
        return Execute([(H.HOLD, self.rudder_deg * DEG)])

    def finished(self, p):
        return p.elapsed >= self.duration_s

    def truth(self, tr):
        out = {"heading_change_deg": float(np.degrees(tr["heading"][-1] - tr["heading"][0])),
               "final_rate_of_turn_dps": float(np.degrees(tr["r"][-1])),
               "final_speed_mps": float(np.hypot(tr["u_r"][-1], tr["v_r"][-1]))}
        out.update(_heel(tr))
        return out


def _steering(steering: str, rudder_deg: float, psi0: float, ap: tuple) -> list:
    if steering == "autopilot":
        return [(H.HEADING, psi0, *ap)]
    if steering == "fixed":
        return [(H.HOLD, rudder_deg * DEG)]
    return [(H.HOLD, 0.0)]


@dataclasses.dataclass(frozen=True, kw_only=True)
class CrashStop(Maneuver):
    """Engine order (default Back Emergency) at EXECUTE; FINEX when the ship is dead in the water (its
    speed through the water along its own axis has fallen to zero). IMO MSC.137(76) full-astern test."""

    order: str = text("engine order at EXECUTE", ORDER_CHOICES, default="back_emergency")
    steering: str = text("rudder during the stop", ("amidships", "autopilot", "fixed"), default="amidships")
    rudder_deg: float = num("rudder angle when steering is 'fixed'", "deg", -90.0, 90.0, default=0.0)
    kind = "crash_stop"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def execute(self, psi0, ap):
        return Execute(_steering(self.steering, self.rudder_deg, psi0, ap), self.order)

    def finished(self, p):
        return p.surge <= 0.0

    def truth(self, tr):
        return TM.stopping(tr["t"], tr["x_w"], tr["y_w"], tr["heading"], tr["u_r"])


@dataclasses.dataclass(frozen=True, kw_only=True)
class SpeedChange(Maneuver):
    """Acceleration or deceleration: engine order at EXECUTE, run until the speed is steady."""

    order: str = text("engine order at EXECUTE", ORDER_CHOICES)
    steering: str = text("rudder during the run", ("autopilot", "amidships", "fixed"), default="autopilot")
    rudder_deg: float = num("rudder angle when steering is 'fixed'", "deg", -90.0, 90.0, default=0.0)
    steady_rate_mps2: float = num("FINEX once the speed changes slower than this (over the last 20 s)", "m/s^2",
                                  0.0, 1.0, lo_open=True, default=2e-4)
    min_duration_s: float = num("shortest run after EXECUTE", "s", 0.0, 1e5, default=30.0)
    kind = "speed_change"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def execute(self, psi0, ap):
        return Execute(_steering(self.steering, self.rudder_deg, psi0, ap), self.order)

    def finished(self, p):
        return p.elapsed >= self.min_duration_s and abs(p.speed_rate) <= self.steady_rate_mps2

    def truth(self, tr):
        return TM.speed_change(tr["t"], tr["x_w"], tr["y_w"], tr["heading"], tr["u_r"], tr["v_r"])


@dataclasses.dataclass(frozen=True, kw_only=True)
class PullOut(Maneuver):
    """Pull-out (ITTC 7.5-04-02-01 §2.3): rudder ``rudder_deg`` until the heading has changed by
    ``heading_change_deg``, then amidships for ``hold_s``; the rate of turn then decays to zero (a
    course-stable ship) or to a residual rate (an unstable one)."""

    rudder_deg: float = num("rudder angle of the turn, + starboard / − port", "deg", -90.0, 90.0)
    heading_change_deg: float = num("heading change at which the rudder is put amidships", "deg", 10.0, 3600.0,
                                    default=90.0)
    hold_s: float = num("time with the rudder amidships before FINEX", "s", 0.0, 1e5, lo_open=True)
    kind = "pull_out"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def execute(self, psi0, ap):
        s = 1.0 if self.rudder_deg >= 0 else -1.0
        return Execute([(H.TURN_UNTIL, self.rudder_deg * DEG, s * self.heading_change_deg * DEG, 0.0, 0.0),
                        (H.HOLD, 0.0)])

    def finished(self, p):
        return p.helm_phase >= 1 and p.phase_elapsed >= self.hold_s

    def truth(self, tr):
        dpsi = np.abs(tr["heading"] - tr["heading"][0])
        k = int(np.searchsorted(dpsi, self.heading_change_deg * DEG)) if np.all(np.diff(dpsi) >= 0) else \
            int(np.argmax(dpsi >= self.heading_change_deg * DEG))
        return {"rate_at_amidships_dps": float(np.degrees(tr["r"][min(k, len(dpsi) - 1)])),
                "residual_rate_dps": float(np.degrees(tr["r"][-1])),
                "heading_change_deg": float(np.degrees(tr["heading"][-1] - tr["heading"][0]))}


@dataclasses.dataclass(frozen=True, kw_only=True)
class Prbs(Maneuver):
    """Pseudo-random binary rudder: ±``rudder_deg`` by a maximum-length sequence of ``stages`` 3 or 4
    (7 or 15 bits of ``bit_s`` each; Godfrey 1993, "Perturbation Signals for System Identification",
    ch. 3), first bit to the side of ``rudder_deg``'s sign, then amidships until FINEX. Runs of equal bits
    are one helm phase each (the helm holds at most eight)."""

    rudder_deg: float = num("rudder amplitude; its sign sets the first bit's side", "deg", -90.0, 90.0)
    bit_s: float = num("duration of one bit", "s", 0.1, 1e4, lo_open=False)
    stages: int = integer("shift-register stages (sequence length 2^stages − 1)", 3, 4, default=4)
    seed: int = integer("initial register state (1 .. 2^stages − 1)", 1, 15, default=1)
    kind = "prbs"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def bits(self) -> np.ndarray:
        """±1 bits: a Fibonacci shift register with taps (3, 2) or (4, 3) (Godfrey 1993, Table 3.1)."""
        taps = {3: (3, 2), 4: (4, 3)}[self.stages]
        state = [(self.seed >> i) & 1 for i in range(self.stages)] if self.seed % (2**self.stages) else [1] * self.stages
        out = []
        for _ in range(2**self.stages - 1):
            out.append(state[-1])
            fb = 0
            for tp in taps:
                fb ^= state[tp - 1]
            state = [fb] + state[:-1]
        b = 2.0 * np.array(out) - 1.0
        return b * b[0] * (1.0 if self.rudder_deg >= 0 else -1.0)

    def execute(self, psi0, ap):
        b = self.bits()
        runs, k = [], 0
        while k < b.size:
            j = k
            while j < b.size and b[j] == b[k]:
                j += 1
            runs.append((b[k], (j - k) * self.bit_s))
            k = j
        phases = [(H.HOLD, v * abs(self.rudder_deg) * DEG, d) for v, d in runs]
        phases[-1] = (H.HOLD, phases[-1][1], 0.0)       # the last run holds on; FINEX ends it
        return Execute(phases)

    def finished(self, p):
        return p.elapsed >= self.bit_s * (2**self.stages - 1)

    def truth(self, tr):
        return {"heading_change_deg": float(np.degrees(tr["heading"][-1] - tr["heading"][0])),
                "max_rate_dps": float(np.degrees(np.max(np.abs(tr["r"])))),
                "final_speed_mps": float(np.hypot(tr["u_r"][-1], tr["v_r"][-1]))}


KINDS = {cls.kind: cls for cls in (TurningCircle, ZigZag, Williamson, CourseKeeping, RudderStep, CrashStop,
                                   SpeedChange, PullOut, Prbs)}


class ProgramSupervisor:
    """The maneuver programmes of a scenario as one controller on the :class:`~vtrials.trials.driver.Driver`.

    Ship i holds its approach until step ``execute_step[i]``, then EXECUTEs its maneuver (helm
    programme and engine order); every half second the supervisor looks at each running ship and
    ends it (FINEX) when its maneuver says it is finished or after ``max_duration[i]`` seconds.
    ``settle[i]`` is the ship's default settling time; ``progress(t, n_running)`` is called after
    every look. Results: ``t_exec``, ``t_finex``, ``completed`` per ship.
    """

    def __init__(self, maneuvers, vessel, autopilot: tuple, execute_step: list[int], max_duration: list[float],
                 settle: list[float], dt: float, progress=None):
        n = len(maneuvers)
        self.maneuvers = maneuvers
        self.vessel = vessel
        self.ap = autopilot
        self.execute_step = list(execute_step)
        self.max_duration = list(max_duration)
        self.settle = list(settle)
        self.progress = progress
        self.t_exec = [math.nan] * n
        self.psi_exec = [0.0] * n
        self.t_finex = [math.nan] * n
        self.completed = [False] * n
        self.look = max(1, int(round(0.5 / dt)))  # the crew looks every half second
        self._history: list[list[tuple[float, float]]] = [[] for _ in range(n)]
        self.running = set(range(n))

    def _pending(self, step: int) -> list[int]:
        return [self.execute_step[i] - step for i in self.running
                if math.isnan(self.t_exec[i]) and self.execute_step[i] >= step]

    def next_step(self, driver) -> int:
        step = driver.step_count
        pending = self._pending(step)
        if any(p == 0 for p in pending):
            return step
        return step + min([self.look] + [p for p in pending if p > 0])

    def done(self, driver) -> bool:
        return not self.running

    def act(self, driver) -> None:
        from vtrials.physics.forces import context as L
        sim = driver.sim
        step = driver.step_count
        for i in sorted(self.running):
            t_i = float(sim.time[i])
            if math.isnan(self.t_exec[i]):
                if step >= self.execute_step[i]:
                    self.t_exec[i] = t_i
                    self.psi_exec[i] = float(sim.nav[i, 0])
                    ex = self.maneuvers[i].execute(self.psi_exec[i], self.ap)
                    sim.set_helm(i, ex.helm)
                    if ex.order is not None:
                        sim.set_engine_order(i, ex.order)
                continue
            speed = float(np.hypot(sim.ctx[i, L.NU_R], sim.ctx[i, L.NU_R + 1]))
            hist = self._history[i]
            hist.append((t_i, speed))
            while hist and hist[0][0] < t_i - 20.0:
                hist.pop(0)
            rate = (hist[-1][1] - hist[0][1]) / (hist[-1][0] - hist[0][0]) if hist[-1][0] - hist[0][0] >= 19.0 \
                else math.inf
            tstart = sim.hs[i, H.H_TSTART]
            pe = t_i - tstart if tstart >= 0 else 0.0
            prog = Progress(t_i - self.t_exec[i], float(sim.nav[i, 0]) - self.psi_exec[i], sim.helm_phase(i), pe,
                            self.settle[i], surge=float(sim.ctx[i, L.NU_R]), speed_rate=rate)
            if self.maneuvers[i].finished(prog):
                self.t_finex[i] = t_i
                self.completed[i] = True
                self.running.discard(i)
            elif t_i - self.t_exec[i] >= self.max_duration[i]:
                self.t_finex[i] = t_i
                self.running.discard(i)
        if self.progress:
            self.progress(float(sim.time[0]), len(self.running))
