"""Shafts, governors and engines.

A shaft is a MuJoCo hinge whose armature is the polar inertia of engine, shafting and propeller,
with the propeller's entrained water (a common estimate is +25 % of the propeller's own inertia).
Its equation is I ω̇ = Q_E − Q_P − Q_F, with Q_P the propeller's hydrodynamic torque, Q_F the
shaft-line friction (viscous, c_F n) and Q_E the engine torque. The governor is a PI controller
on shaft speed; its output is limited by the engine's torque limit and by its power limit
|Q_E| ≤ P_max/(2π|n|). The integrator is clamped to the same limits (anti-windup).
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from .schema import integer, num, text


@dataclasses.dataclass(frozen=True)
class Shaft:
    name: str = text("shaft name")
    joint: str = text("MJCF hinge joint of this shaft")
    propeller: str = text("propeller on this shaft")
    inertia: float = num("polar inertia of engine, shafting, propeller and entrained water", "kg m^2",
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
    rotation: int = integer("+1 right-handed (clockwise seen from astern), −1 left-handed", -1, 1)


# per-shaft parameter block of the dynamics kernel
S_INERTIA, S_FRICTION, S_KP, S_KI, S_QMAX, S_PMAX, S_ROT, S_QADR, S_DADR, S_PROP = range(10)
NSHAFTP = 10


def pack(s: Shaft, prop_index: int, qadr: int, dadr: int) -> np.ndarray:
    kp = 2.0 * math.pi * s.inertia / s.governor_time_constant  # N m per (rev/s)
    return np.array([s.inertia, s.friction, kp, kp / s.governor_integral_time, s.max_torque,
                     s.max_power, float(s.rotation), qadr, dadr, prop_index], dtype=np.float64)


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
