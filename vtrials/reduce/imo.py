"""IMO manoeuvrability verdicts: Standards for ship manoeuvrability, resolution MSC.137(76) (2002),
with the explanatory notes MSC/Circ.1053; trial procedures per ITTC 7.5-04-02-01.

Criteria (L = length between perpendiculars [m], V = test speed [m/s], angles in rad):

* turning ability (§5.3.1): advance ≤ 4.5 L and tactical diameter ≤ 5 L in the turning test;
* initial turning ability (§5.3.2): with 10° rudder to one side, the ship should not have travelled
  more than 2.5 L by the time the heading has changed by 10° from the original heading;
* yaw-checking and course-keeping (§5.3.3): first overshoot of the 10°/10° zig-zag ≤ 10° if
  L/V < 10 s, ≤ 20° if L/V ≥ 30 s, else (5 + ½ L/V)°; second overshoot of the 10°/10° test ≤ 25°,
  40°, or (17.5 + 0.75 L/V)° on the same L/V bands (the limits are continuous at 10 s and 30 s);
  first overshoot of the 20°/20° test ≤ 25°;
* stopping ability (§5.3.4): track reach in the full-astern stopping test ≤ 15 L, which the
  Administration may relax for ships of large displacement but never beyond 20 L.
* The standards apply at a test speed of at least 90 % of the speed corresponding to 85 % MCR
  (:func:`speed_condition_ok`).

Each verdict compares a reduced value (an :class:`Estimate` or a plain float) with its limit:
``passed`` = value ≤ limit; ``margin`` = limit − value (positive = compliant) with the value's
standard uncertainty; ``straddles`` = the two-sided ``level`` interval of the value contains the
limit, i.e. the data cannot decide the verdict at that confidence; ``p_pass`` = probability that
the true value is within the limit under the Estimate's (normal or t) distribution.
"""

from __future__ import annotations

import dataclasses
import math

from scipy import stats

from vtrials.reduce.estimate import Estimate
from vtrials.units import DEG


@dataclasses.dataclass(frozen=True)
class Verdict:
    criterion: str
    value: Estimate
    limit: float
    passed: bool
    margin: Estimate  # limit − value
    straddles: bool
    p_pass: float
    unit: str
    note: str = ""

    def to_dict(self) -> dict:
        return {"criterion": self.criterion, "value": self.value.to_dict(), "limit": self.limit,
                "passed": self.passed, "margin": self.margin.to_dict(), "straddles": self.straddles,
                "p_pass": self.p_pass, "unit": self.unit, "note": self.note}


def _est(x) -> Estimate:
    return x if isinstance(x, Estimate) else Estimate(float(x), 0.0)


def verdict(criterion: str, value, limit: float, *, unit: str = "", level: float = 0.95, note: str = "") -> Verdict:
    """Generic ≤-limit verdict (see the module docstring)."""
    v = _est(value)
    lo, hi = v.interval(level)
    straddles = lo <= limit <= hi and v.std > 0
    if v.std > 0 and math.isfinite(v.std):
        z = (limit - v.value) / v.std
        p = float(stats.norm.cdf(z) if v.dof is None or v.dof <= 0 else stats.t.cdf(z, v.dof))
    else:
        p = 1.0 if v.value <= limit else 0.0
    return Verdict(criterion, v, float(limit), bool(v.value <= limit), Estimate(limit - v.value, v.std, v.dof),
                   bool(straddles), p, unit, note)


def _check_lv(length: float, speed: float) -> float:
    if not (length > 0 and speed > 0):
        raise ValueError("ship length and test speed must be positive")
    return length / speed


def advance(value, length: float, **kw) -> Verdict:
    """Advance [m] ≤ 4.5 L."""
    return verdict("advance <= 4.5 L", value, 4.5 * length, unit="m", **kw)


def tactical_diameter(value, length: float, **kw) -> Verdict:
    """Tactical diameter [m] ≤ 5 L."""
    return verdict("tactical diameter <= 5 L", value, 5.0 * length, unit="m", **kw)


def initial_turning(distance, length: float, **kw) -> Verdict:
    """Distance travelled [m] by 10° of heading change with 10° rudder ≤ 2.5 L."""
    return verdict("initial turning: distance to 10 deg heading change <= 2.5 L", distance, 2.5 * length,
                   unit="m", **kw)


def first_overshoot_10_limit(length: float, speed: float) -> float:
    """10°/10° first-overshoot limit [rad] for L [m], V [m/s]."""
    lv = _check_lv(length, speed)
    if lv < 10.0:
        return 10.0 * DEG
    if lv >= 30.0:
        return 20.0 * DEG
    return (5.0 + 0.5 * lv) * DEG


def second_overshoot_10_limit(length: float, speed: float) -> float:
    """10°/10° second-overshoot limit [rad] for L [m], V [m/s]."""
    lv = _check_lv(length, speed)
    if lv < 10.0:
        return 25.0 * DEG
    if lv >= 30.0:
        return 40.0 * DEG
    return (17.5 + 0.75 * lv) * DEG


def first_overshoot_10(angle, length: float, speed: float, **kw) -> Verdict:
    """10°/10° zig-zag first overshoot angle [rad]."""
    lv = _check_lv(length, speed)
    return verdict("10/10 zig-zag first overshoot", angle, first_overshoot_10_limit(length, speed), unit="rad",
                   note=f"L/V = {lv:.2f} s", **kw)


def second_overshoot_10(angle, length: float, speed: float, **kw) -> Verdict:
    """10°/10° zig-zag second overshoot angle [rad]."""
    lv = _check_lv(length, speed)
    return verdict("10/10 zig-zag second overshoot", angle, second_overshoot_10_limit(length, speed), unit="rad",
                   note=f"L/V = {lv:.2f} s", **kw)


def first_overshoot_20(angle, **kw) -> Verdict:
    """20°/20° zig-zag first overshoot angle [rad] ≤ 25°."""
    return verdict("20/20 zig-zag first overshoot <= 25 deg", angle, 25.0 * DEG, unit="rad", **kw)


def stopping(track_reach, length: float, *, relaxed: bool = False, **kw) -> Verdict:
    """Full-astern stopping track reach [m] ≤ 15 L (≤ 20 L when the Administration relaxes it for a
    ship of large displacement)."""
    k = 20.0 if relaxed else 15.0
    return verdict(f"stopping track reach <= {k:.0f} L", track_reach, k * length, unit="m",
                   note="relaxed limit (large displacement)" if relaxed else "", **kw)


def speed_condition_ok(test_speed: float, speed_85mcr: float) -> bool:
    """The standards apply at a test speed ≥ 90 % of the speed at 85 % MCR [m/s]."""
    return bool(test_speed >= 0.9 * speed_85mcr)


def assess(length: float, speed: float, *, advance_m=None, tactical_diameter_m=None, initial_turning_m=None,
           first_overshoot_10_rad=None, second_overshoot_10_rad=None, first_overshoot_20_rad=None,
           stopping_track_reach_m=None, relaxed_stopping: bool = False, level: float = 0.95) -> dict:
    """All verdicts for which a reduced value is given; ``overall`` True only when every one passed,
    and ``undecided`` lists the criteria whose interval straddles the limit."""
    out: dict = {}
    if advance_m is not None:
        out["advance"] = advance(advance_m, length, level=level)
    if tactical_diameter_m is not None:
        out["tactical_diameter"] = tactical_diameter(tactical_diameter_m, length, level=level)
    if initial_turning_m is not None:
        out["initial_turning"] = initial_turning(initial_turning_m, length, level=level)
    if first_overshoot_10_rad is not None:
        out["first_overshoot_10"] = first_overshoot_10(first_overshoot_10_rad, length, speed, level=level)
    if second_overshoot_10_rad is not None:
        out["second_overshoot_10"] = second_overshoot_10(second_overshoot_10_rad, length, speed, level=level)
    if first_overshoot_20_rad is not None:
        out["first_overshoot_20"] = first_overshoot_20(first_overshoot_20_rad, level=level)
    if stopping_track_reach_m is not None:
        out["stopping"] = stopping(stopping_track_reach_m, length, relaxed=relaxed_stopping, level=level)
    verdicts = [v for v in out.values() if isinstance(v, Verdict)]
    out["overall"] = all(v.passed for v in verdicts) if verdicts else None
    out["undecided"] = [k for k, v in out.items() if isinstance(v, Verdict) and v.straddles]
    return out
