"""Shafts, engines, governors, controllable pitch and the engine-order telegraph.

A shaft is a MuJoCo hinge whose armature is the polar inertia of engine, gearing, shafting and
propeller with its entrained water (commonly +25 % of the propeller's own inertia). Its equation
is I ω̇ = Q_M − Q_P − c_F n, with Q_P the propeller's hydrodynamic torque, c_F n the shaft-line
friction and Q_M the machinery torque, which depends on the shaft's mode:

* governed – the engine, a torque source commanded by a PI speed governor, limited by its torque
  limit and its power limit |Q| ≤ P_max/(2π|n|), and slewing at most at its torque rate; the
  governor's set-point follows the r/min order at the machinery's allowed acceleration (load-up
  programme). The integrator is clamped to the available torque (anti-windup). A reversing engine
  is a torque source of either sign: the stop-and-restart of a slow-speed diesel is represented by
  the torque rate and the set-point ramp, not by a start-air sequence.
* trailed  – declutched: no machinery torque, the propeller windmills;
* locked   – held by the shaft brake at zero r/min; Q_M is then the brake torque.

Controllable pitch: the pitch ratio follows its order at the actuator's rate within its range.
The telegraph maps each engine order to (r/min, pitch ratio) per ship (ship.toml [telegraph]).
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from vtrials.schema import flag, integer, num, text


@dataclasses.dataclass(frozen=True, kw_only=True)
class Shaft:
    name: str = text("shaft name")
    joint: str = text("MJCF hinge joint of this shaft")
    propeller: str = text("propeller on this shaft")
    inertia: float = num("polar inertia of engine, gearing, shafting, propeller and entrained water", "kg m^2",
                         0.0, 1e9, lo_open=True)
    friction: float = num("shaft-line viscous friction coefficient c_F (Q_F = c_F n)", "N m s", 0.0, 1e9)
    governor_time_constant: float = num("governor proportional time constant τ (K_p = 2π I/τ)", "s",
                                        0.0, 600.0, lo_open=True)
    governor_integral_time: float = num("governor integral time T_i (K_i = K_p/T_i)", "s",
                                        0.0, 6000.0, lo_open=True)
    max_torque: float = num("engine torque limit", "N m", 0.0, 1e10, lo_open=True)
    max_power: float = num("engine power limit (MCR)", "W", 0.0, 1e9, lo_open=True)
    max_rps: float = num("highest shaft speed the governor accepts as an order", "1/s", 0.0, 100.0,
                         lo_open=True)
    torque_rate: float = num("fastest change of engine torque", "N m/s", 0.0, 1e12, lo_open=True)
    rps_rate: float = num("fastest change of the governor's shaft-speed set-point", "1/s^2", 0.0, 100.0,
                          lo_open=True)
    rotation: int = integer("+1 right-handed (clockwise seen from astern), −1 left-handed", -1, 1)
    controllable_pitch: bool = flag("controllable-pitch propeller (pitch ratio is an order)", default=False)
    pitch_min: float = num("smallest pitch ratio (astern)", "", -2.0, 2.0, default=0.0)
    pitch_max: float = num("largest pitch ratio", "", -2.0, 3.0, default=0.0)
    pitch_rate: float = num("fastest change of pitch ratio", "1/s", 0.0, 10.0, default=0.0)


# per-shaft parameter block of the dynamics kernel
(S_INERTIA, S_FRICTION, S_KP, S_KI, S_QMAX, S_PMAX, S_ROT, S_QADR, S_DADR, S_PROP, S_TRATE, S_NRATE, S_CP,
 S_PITCH_MIN, S_PITCH_MAX, S_PITCH_RATE, S_PITCH_DESIGN) = range(17)
NSHAFTP = 17
# machinery state per ship and shaft
M_INTEG, M_PITCH, M_TORQUE, M_SETPOINT = range(4)
NMACH = 4
# shaft modes
GOVERNED, TRAILED, LOCKED = 0, 1, 2
MODE_NAMES = {"governed": GOVERNED, "trailed": TRAILED, "locked": LOCKED}


def pack(s: Shaft, prop_index: int, qadr: int, dadr: int, design_pitch: float) -> np.ndarray:
    kp = 2.0 * math.pi * s.inertia / s.governor_time_constant  # N m per (rev/s)
    cp = 1.0 if s.controllable_pitch else 0.0
    pmin, pmax = (s.pitch_min, s.pitch_max) if s.controllable_pitch else (design_pitch, design_pitch)
    return np.array([s.inertia, s.friction, kp, kp / s.governor_integral_time, s.max_torque,
                     s.max_power, float(s.rotation), qadr, dadr, prop_index, s.torque_rate, s.rps_rate, cp,
                     pmin, pmax, s.pitch_rate, design_pitch], dtype=np.float64)


@nb.njit(cache=True)
def engine_torque(sp, n, n_order, integ):
    """Governor output [N m] (limited) and the unclamped integrator rate, for one shaft."""
    err = n_order - n
    q = sp[S_KP] * err + integ
    qmax = sp[S_QMAX]
    an = abs(n)
    if an > 1e-9:
        ql = sp[S_PMAX] / (2.0 * math.pi * an)
        if ql < qmax:
            qmax = ql
    if q > qmax:
        q = qmax
    elif q < -qmax:
        q = -qmax
    return q, sp[S_KI] * err, qmax
