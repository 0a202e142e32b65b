"""Identification input designs: schedules of maneuvers for a system-identification agenda.

Each maneuver is a plain dict whose keys follow the agenda's ``[[agenda.trial.maneuver]]`` fields
(``type``, ``rudder_deg``, ``check_deg``, ``executes``, ``heading_change_deg``, ``hold_s``,
``sequence_deg``), degrees at this edge as in agenda files. The one addition is ``type = "prbs"``:
a pseudo-random binary rudder sequence with ``rudder_deg`` (amplitude, sign of the first bit) and
``switch_times_s`` (instants after EXECUTE at which the rudder changes side), ``duration_s``.

Designs follow the usual identification practice: zig-zags of several amplitudes excite the linear
and cubic ranges (Alexandersson et al. 2022, Ocean Eng. 247: KVLCC2 zig-zags 10/10, 20/20 and
turns), turns reach large r', spirals and pull-outs probe the course-stability range (ITTC 7.5-04-02-01),
PRBS rudder spreads the input power over frequencies (maximum-length sequences: Godfrey 1993,
"Perturbation Signals for System Identification", ch. 3).
"""

from __future__ import annotations

import numpy as np

from vtrials.errors import InputError

_WHERE = "vtrials.sysid.inputs"

#: Feedback taps of maximum-length shift registers of order 5..10 (Godfrey 1993, Table 3.1).
_TAPS = {5: (5, 3), 6: (6, 5), 7: (7, 6), 8: (8, 6, 5, 4), 9: (9, 5), 10: (10, 7)}


def _amp(field: str, value: float, lo: float = 0.0, hi: float = 45.0) -> float:
    value = float(value)
    if not (lo < abs(value) <= hi):
        raise InputError(_WHERE, field, f"{value:g}°; allowed: {lo:g} < |angle| ≤ {hi:g}°")
    return value


def zigzags(amplitudes_deg=(5.0, 10.0, 20.0), first_sides=(1, -1), executes: int = 5) -> list[dict]:
    """δ/ψ zig-zags (check angle = rudder angle) of each amplitude, first to each side given."""
    out = []
    for a in amplitudes_deg:
        a = abs(_amp("zigzag.rudder_deg", a))
        for s in first_sides:
            if s not in (1, -1):
                raise InputError(_WHERE, "zigzag.first_side", f"{s}; allowed: 1 (starboard) or -1 (port)")
            out.append(dict(type="zigzag", rudder_deg=s * a, check_deg=a, executes=int(executes)))
    return out


def turns(rudders_deg=(35.0, -35.0, 20.0, -20.0), heading_change_deg: float = 540.0) -> list[dict]:
    """Turning circles at each rudder angle (FINEX after ``heading_change_deg``)."""
    return [dict(type="turn", rudder_deg=_amp("turn.rudder_deg", d), heading_change_deg=float(heading_change_deg))
            for d in rudders_deg]


def pull_outs(rudders_deg=(20.0, -20.0), heading_change_deg: float = 90.0, hold_s: float = 300.0) -> list[dict]:
    """Pull-outs: turn, centre the rudder after ``heading_change_deg``, record ``hold_s``."""
    return [dict(type="pull_out", rudder_deg=_amp("pull_out.rudder_deg", d),
                 heading_change_deg=float(heading_change_deg), hold_s=float(hold_s)) for d in rudders_deg]


def spiral(sequence_deg=(15.0, 10.0, 5.0, 2.0, 0.0, -2.0, -5.0, -10.0, -15.0), hold_s: float = 120.0) -> dict:
    """A direct (Dieudonné) spiral with the rudder settings in order."""
    seq = [float(d) for d in sequence_deg]
    for i, d in enumerate(seq):
        if abs(d) > 45.0:
            raise InputError(_WHERE, f"spiral.sequence_deg[{i}]", f"{d:g}°; allowed: |angle| ≤ 45°")
    return dict(type="direct_spiral", sequence_deg=seq, hold_s=float(hold_s))


def mls(order: int, seed: int = 1) -> np.ndarray:
    """One period (2^order − 1) of a maximum-length ±1 sequence; ``seed`` (≠ 0 mod 2^order) sets the
    register's start state, i.e. the phase of the sequence."""
    if order not in _TAPS:
        raise InputError(_WHERE, "prbs.order", f"{order}; allowed: {min(_TAPS)}..{max(_TAPS)}")
    state = int(seed) % (1 << order)
    if state == 0:
        raise InputError(_WHERE, "prbs.seed", f"{seed}; allowed: not a multiple of 2^{order}")
    out = np.empty((1 << order) - 1)
    for i in range(out.size):
        bit = 0
        for t in _TAPS[order]:
            bit ^= (state >> (order - t)) & 1
        out[i] = 1.0 if state & 1 else -1.0
        state = (state >> 1) | (bit << (order - 1))
    return out


def prbs(rudder_deg: float = 10.0, bit_s: float = 5.0, order: int = 6, seed: int = 1) -> dict:
    """PRBS rudder: a maximum-length sequence of ``order`` with bit length ``bit_s`` seconds, as the
    instants at which the rudder switches side (first side: the sign of ``rudder_deg``)."""
    a = _amp("prbs.rudder_deg", rudder_deg)
    if not bit_s > 0:
        raise InputError(_WHERE, "prbs.bit_s", f"{bit_s:g} s; allowed: > 0")
    seq = mls(order, seed)
    seq = seq * np.sign(a) * seq[0]
    switch = [float(i * bit_s) for i in range(1, seq.size) if seq[i] != seq[i - 1]]
    return dict(type="prbs", rudder_deg=a, switch_times_s=switch, duration_s=float(seq.size * bit_s))


def prbs_rudder(maneuver: dict, t_s) -> np.ndarray:
    """Rudder order (deg) of a PRBS maneuver at times ``t_s`` after EXECUTE (0 outside the run)."""
    t = np.asarray(t_s, float)
    k = np.searchsorted(np.asarray(maneuver["switch_times_s"], float), t, side="right")
    out = maneuver["rudder_deg"] * np.where(k % 2 == 0, 1.0, -1.0)
    return np.where((t >= 0) & (t < maneuver["duration_s"]), out, 0.0)


def identification_agenda(prbs_seed: int = 1) -> list[dict]:
    """A standard identification day: zig-zags 5/5, 10/10, 20/20 both sides, 35° and 20° turns both
    sides, two pull-outs, one PRBS run and a direct spiral."""
    return (zigzags() + turns() + pull_outs() + [prbs(seed=prbs_seed), spiral()])
