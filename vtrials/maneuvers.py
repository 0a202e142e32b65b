"""Maneuver kinds a scenario can list: what the helm does, when the run ends, what truth to report.

Each maneuver starts from the scenario's initial condition, holds the approach course with the
autopilot for ``approach_s`` (default: three ship lengths' travel time), then EXECUTEs. All the
maneuvers of a scenario run side by side as ships of one batch.

Kinds: ``turning_circle``, ``zigzag``, ``williamson``, ``course_keeping``, ``rudder_step``.
Rudder angles are positive to starboard (the ship turns to starboard).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from . import helm as H
from . import truth_metrics as TM
from .schema import integer, num, text
from .units import DEG


@dataclasses.dataclass(frozen=True)
class Progress:
    """Where a running maneuver stands, as the crew sees it (times after EXECUTE)."""

    elapsed: float  # since EXECUTE [s]
    heading_change: float  # since EXECUTE [rad], signed
    helm_phase: int  # index of the helm phase running
    phase_elapsed: float  # since the running helm phase began [s]
    settle: float  # default settling time of this ship [s]


@dataclasses.dataclass(frozen=True)
class TurningCircle:
    """Rudder put over at EXECUTE and held; FINEX after ``heading_change_deg`` of turn."""

    name: str = text("name of this maneuver (unique in the scenario)")
    rudder_deg: float = num("rudder angle, + starboard / − port", "deg", -90.0, 90.0)
    heading_change_deg: float = num("FINEX after this much heading change", "deg", 90.0, 3600.0, default=720.0)
    approach_s: float = num("steady approach before EXECUTE (default: 3 L/U)", "s", 0.0, 1e5, default=None)
    max_duration_s: float = num("give up (and report) if FINEX is not reached within this time after EXECUTE",
                                "s", 1.0, 1e6, default=None)
    kind: str = "turning_circle"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def program(self, psi0: float, ap: tuple) -> list[tuple]:
        return [(H.HOLD, self.rudder_deg * DEG)]

    def finished(self, p: Progress) -> bool:
        return abs(p.heading_change) >= self.heading_change_deg * DEG

    def truth(self, tr: dict) -> dict:
        return TM.turning(tr["t"], tr["x_w"], tr["y_w"], tr["heading"], tr["u_r"], tr["v_r"], tr["r"])


@dataclasses.dataclass(frozen=True)
class ZigZag:
    """δ/ψ zig-zag: rudder ±δ shifted whenever the heading deviation reaches ±ψ."""

    name: str = text("name of this maneuver (unique in the scenario)")
    rudder_deg: float = num("rudder angle δ of the zig-zag", "deg", 0.0, 90.0, lo_open=True)
    heading_deg: float = num("heading deviation ψ at which the rudder is shifted", "deg", 0.0, 90.0, lo_open=True)
    first_side: str = text("side of the first rudder order", ("starboard", "port"))
    rudder_shifts: int = integer("FINEX at this rudder shift (4: two full cycles)", 3, 40, default=4)
    approach_s: float = num("steady approach before EXECUTE (default: 3 L/U)", "s", 0.0, 1e5, default=None)
    max_duration_s: float = num("give up if FINEX is not reached within this time after EXECUTE", "s", 1.0, 1e6,
                                default=None)
    kind: str = "zigzag"

    @property
    def side(self) -> int:
        return 1 if self.first_side == "starboard" else -1

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def program(self, psi0: float, ap: tuple) -> list[tuple]:
        return [(H.ZIGZAG, self.rudder_deg * DEG, self.heading_deg * DEG, psi0, float(self.side),
                 float(self.rudder_shifts)), (H.HOLD, 0.0)]

    def finished(self, p: Progress) -> bool:
        return p.helm_phase >= 1

    def truth(self, tr: dict) -> dict:
        return TM.zigzag(tr["t"], tr["heading"], rudder_deg=self.rudder_deg, heading_deg=self.heading_deg,
                         first_side=self.side)


@dataclasses.dataclass(frozen=True)
class Williamson:
    """Williamson turn: rudder to one side until the heading has changed by ``deviation_deg``, then
    the same rudder the other way until within ``window_deg`` of the reciprocal course, then the
    autopilot steadies the ship on the reciprocal for ``settle_s``."""

    name: str = text("name of this maneuver (unique in the scenario)")
    rudder_deg: float = num("rudder angle used both ways", "deg", 0.0, 90.0, lo_open=True)
    first_side: str = text("side of the first rudder order", ("starboard", "port"))
    deviation_deg: float = num("heading change at which the rudder is reversed", "deg", 10.0, 120.0, default=60.0)
    window_deg: float = num("hand over to the autopilot this far short of the reciprocal", "deg", 0.0, 90.0,
                            default=20.0)
    settle_s: float = num("time on autopilot after hand-over before FINEX (default: 10 L/U)", "s", 0.0, 1e5,
                          default=None)
    approach_s: float = num("steady approach before EXECUTE (default: 3 L/U)", "s", 0.0, 1e5, default=None)
    max_duration_s: float = num("give up if FINEX is not reached within this time after EXECUTE", "s", 1.0, 1e6,
                                default=None)
    kind: str = "williamson"

    @property
    def side(self) -> int:
        return 1 if self.first_side == "starboard" else -1

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def program(self, psi0: float, ap: tuple) -> list[tuple]:
        s = self.side
        d = self.rudder_deg * DEG
        back = -s * (math.pi - self.window_deg * DEG)
        return [(H.TURN_UNTIL, s * d, s * self.deviation_deg * DEG, 0.0, 0.0),
                (H.TURN_UNTIL, -s * d, back, psi0, 1.0),
                (H.HEADING, psi0 - s * math.pi, *ap)]

    def finished(self, p: Progress) -> bool:
        settle = p.settle if self.settle_s is None else self.settle_s
        return p.helm_phase >= 2 and p.phase_elapsed >= settle

    def truth(self, tr: dict) -> dict:
        t, psi = tr["t"], tr["heading"]
        s = self.side
        dpsi = s * (psi - psi[0])
        c, sn = math.cos(psi[0]), math.sin(psi[0])
        ex, ey = tr["x_w"] - tr["x_w"][0], tr["y_w"] - tr["y_w"][0]
        along = ex * c + ey * sn
        cross = -ex * sn + ey * c
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


@dataclasses.dataclass(frozen=True)
class CourseKeeping:
    """Hold the approach heading on autopilot for ``duration_s`` (a straight run)."""

    name: str = text("name of this maneuver (unique in the scenario)")
    duration_s: float = num("length of the run after EXECUTE", "s", 0.0, 1e6, lo_open=True)
    approach_s: float = num("steady approach before EXECUTE (default: 3 L/U)", "s", 0.0, 1e5, default=None)
    kind: str = "course_keeping"

    def rudders(self):
        return []

    def program(self, psi0: float, ap: tuple) -> list[tuple]:
        return [(H.HEADING, psi0, *ap)]

    def finished(self, p: Progress) -> bool:
        return p.elapsed >= self.duration_s

    def truth(self, tr: dict) -> dict:
        U = np.hypot(tr["u_r"], tr["v_r"])
        return {"mean_speed_mps": float(np.mean(U)), "mean_shaft_rps": float(np.mean(tr["shaft_n_0"])),
                "heading_rms_deg": float(np.degrees(np.sqrt(np.mean((tr["heading"] - tr["heading"][0]) ** 2)))),
                "rudder_rms_deg": float(np.degrees(np.sqrt(np.mean(tr["rudder_0"] ** 2))))}


@dataclasses.dataclass(frozen=True)
class RudderStep:
    """Rudder put to ``rudder_deg`` at EXECUTE and held for ``duration_s``."""

    name: str = text("name of this maneuver (unique in the scenario)")
    rudder_deg: float = num("rudder angle, + starboard / − port", "deg", -90.0, 90.0)
    duration_s: float = num("length of the run after EXECUTE", "s", 0.0, 1e6, lo_open=True)
    approach_s: float = num("steady approach before EXECUTE (default: 3 L/U)", "s", 0.0, 1e5, default=None)
    kind: str = "rudder_step"

    def rudders(self):
        return [("rudder_deg", self.rudder_deg)]

    def program(self, psi0: float, ap: tuple) -> list[tuple]:
        return [(H.HOLD, self.rudder_deg * DEG)]

    def finished(self, p: Progress) -> bool:
        return p.elapsed >= self.duration_s

    def truth(self, tr: dict) -> dict:
        return {"heading_change_deg": float(np.degrees(tr["heading"][-1] - tr["heading"][0])),
                "final_rate_of_turn_dps": float(np.degrees(tr["r"][-1])),
                "final_speed_mps": float(np.hypot(tr["u_r"][-1], tr["v_r"][-1])),
                "max_heel_deg": float(np.degrees(np.max(np.abs(tr["roll"]))))}


KINDS = {"turning_circle": TurningCircle, "zigzag": ZigZag, "williamson": Williamson,
         "course_keeping": CourseKeeping, "rudder_step": RudderStep}
