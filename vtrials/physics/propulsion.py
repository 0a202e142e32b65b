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

Load control of a CP plant (``load_control = true``; :func:`machinery_step`). A CP plant's prime
mover turns one way only and cannot brake the shaft, and its propulsion control does not let the
propeller load run ahead of the engine (seed 002: orders are met "at the maximum rate allowable
without exceeding design operating limits"). Three parts:

* non-reversing engine: the machinery torque is limited to [0, Q_avail] (fuel can only be cut);
* reversal schedule: when the pitch is ordered to the other side of zero (a reversal, latched
  until the pitch has reached its order), the r/min set-point is capped by the combinator's r/min
  for the ACTUAL pitch (``reversal_pitch`` → ``reversal_rps``, linear, held at the end values), so
  the shaft does not run at the astern r/min while the blades pass through zero;
* load-dependent pitch rate: while the pitch moves away from zero (loading the engine), its rate is
  scaled by clip((1 − λ)/(1 − λ_lim), 0, 1), λ = Q_engine/Q_avail the engine's load on its torque/power
  limit at the larger of the actual and the set-point shaft speed (a load the engine could carry
  only by losing r/min counts as an overload) and λ_lim = ``load_limit``; above λ = 1 the factor
  turns negative and the pitch is taken back toward zero (at most at its rate) until the engine
  carries the load at its set-point r/min. Moves toward zero (unloading) keep the full rate.
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from vtrials.errors import InputError
from vtrials.schema import flag, integer, num, text, vector


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
    load_control: bool = flag("CP plant load control (non-reversing engine, reversal r/min schedule, "
                              "load-dependent pitch rate; see the module docstring)", default=False)
    reversal_pitch: tuple = vector("pitch ratios of the reversal r/min schedule (increasing)", "", -2.0, 3.0,
                                   default=())
    reversal_rps: tuple = vector("shaft-speed cap at those actual pitch ratios during a reversal", "1/s",
                                 0.0, 100.0, default=())
    load_limit: float = num("engine load Q/Q_avail above which the pitch rate away from zero is reduced "
                            "(to zero at full load)", "", 0.0, 1.0, hi_open=True, default=0.9)


# per-shaft parameter block of the dynamics kernel
(S_INERTIA, S_FRICTION, S_KP, S_KI, S_QMAX, S_PMAX, S_ROT, S_QADR, S_DADR, S_PROP, S_TRATE, S_NRATE, S_CP,
 S_PITCH_MIN, S_PITCH_MAX, S_PITCH_RATE, S_PITCH_DESIGN, S_LC, S_LOADLIM, S_NREV) = range(20)
MAX_REVERSAL = 12          # points of the reversal schedule
S_REV = 20                 # pitch ratios at S_REV .. S_REV+MAX_REVERSAL-1, r/s after them
NSHAFTP = S_REV + 2 * MAX_REVERSAL
# machinery state per ship and shaft
M_INTEG, M_PITCH, M_TORQUE, M_SETPOINT, M_REV = range(5)
NMACH = 5
# shaft modes
GOVERNED, TRAILED, LOCKED = 0, 1, 2
MODE_NAMES = {"governed": GOVERNED, "trailed": TRAILED, "locked": LOCKED}


def pack(s: Shaft, prop_index: int, qadr: int, dadr: int, design_pitch: float,
         file: str = "ship.toml") -> np.ndarray:
    kp = 2.0 * math.pi * s.inertia / s.governor_time_constant  # N m per (rev/s)
    cp = 1.0 if s.controllable_pitch else 0.0
    pmin, pmax = (s.pitch_min, s.pitch_max) if s.controllable_pitch else (design_pitch, design_pitch)
    lc = 0.0
    rp, rn = tuple(s.reversal_pitch), tuple(s.reversal_rps)
    if s.load_control:
        field = f"shaft {s.name!r}"
        if not s.controllable_pitch:
            raise InputError(file, f"{field}.load_control", "load control needs controllable_pitch = true")
        if not 1 <= len(rp) <= MAX_REVERSAL or len(rp) != len(rn):
            raise InputError(file, f"{field}.reversal_pitch", f"{len(rp)} pitch ratios and {len(rn)} shaft speeds: "
                                                              f"give 1 to {MAX_REVERSAL} of each, as many of one as "
                                                              f"of the other")
        if any(b <= a for a, b in zip(rp, rp[1:])):
            raise InputError(file, f"{field}.reversal_pitch", f"{list(rp)} must increase strictly")
        lc = 1.0
    row = np.zeros(NSHAFTP)
    row[:S_REV] = [s.inertia, s.friction, kp, kp / s.governor_integral_time, s.max_torque,
                   s.max_power, float(s.rotation), qadr, dadr, prop_index, s.torque_rate, s.rps_rate, cp,
                   pmin, pmax, s.pitch_rate, design_pitch, lc, s.load_limit, float(len(rp) if lc else 0)]
    if lc:
        row[S_REV:S_REV + len(rp)] = rp
        row[S_REV + MAX_REVERSAL:S_REV + MAX_REVERSAL + len(rn)] = rn
    return row


@nb.njit(cache=True)
def _clip(x, lim):
    if x > lim:
        return lim
    if x < -lim:
        return -lim
    return x


@nb.njit(cache=True)
def reversal_cap(sp, pitch):
    """Shaft-speed cap [rev/s] of the reversal schedule at the actual pitch ratio (linear, held at
    the ends)."""
    m = int(sp[S_NREV])
    if pitch <= sp[S_REV]:
        return sp[S_REV + MAX_REVERSAL]
    for j in range(1, m):
        a = sp[S_REV + j - 1]
        b = sp[S_REV + j]
        if pitch <= b:
            na = sp[S_REV + MAX_REVERSAL + j - 1]
            nb_ = sp[S_REV + MAX_REVERSAL + j]
            return na + (nb_ - na) * (pitch - a) / (b - a)
    return sp[S_REV + MAX_REVERSAL + m - 1]


@nb.njit(cache=True)
def available_torque(sp, n):
    """Engine torque available at shaft speed n [rev/s]: min(Q_max, P_max/(2π|n|))."""
    qmax = sp[S_QMAX]
    an = abs(n)
    if an > 1e-9:
        ql = sp[S_PMAX] / (2.0 * math.pi * an)
        if ql < qmax:
            qmax = ql
    return qmax


@nb.njit(cache=True)
def machinery_step(sp, ms, n, n_cmd, p_cmd, mode, dt):
    """One step of a shaft's machinery before the forces: pitch actuator, governor set-point ramp
    and engine torque (state ``ms`` updated in place; see the module docstring). ``n`` the shaft
    speed [rev/s], ``n_cmd`` the r/min order [rev/s], ``p_cmd`` the pitch-ratio order."""
    lc = sp[S_LC] > 0.0
    if sp[S_CP] > 0.0:
        pc = p_cmd
        if pc > sp[S_PITCH_MAX]:
            pc = sp[S_PITCH_MAX]
        elif pc < sp[S_PITCH_MIN]:
            pc = sp[S_PITCH_MIN]
        p = ms[M_PITCH]
        rate = sp[S_PITCH_RATE]
        back = 0.0
        if lc:
            if pc * p < 0.0:
                ms[M_REV] = 1.0           # ordered to the other side of zero: a reversal
            if (pc - p) * p >= 0.0 and pc != p:
                # moving away from zero: limited by the engine's load on its torque/power limit
                lam = ms[M_TORQUE] / available_torque(sp, max(abs(n), abs(ms[M_SETPOINT])))
                f = (1.0 - lam) / (1.0 - sp[S_LOADLIM])
                if f < 1.0:
                    if f >= 0.0:
                        rate *= f
                    else:
                        # overloaded: the pitch is taken back toward zero, at most at its rate
                        back = min(-f, 1.0) * rate * dt
                        if back > abs(p):
                            back = abs(p)
        if back > 0.0:
            ms[M_PITCH] = p - back if p > 0.0 else p + back
        else:
            ms[M_PITCH] = p + _clip(pc - p, rate * dt)
        if lc and ms[M_PITCH] == pc:
            ms[M_REV] = 0.0               # the pitch has reached its order
    else:
        ms[M_PITCH] = sp[S_PITCH_DESIGN]
    target = n_cmd
    if lc and ms[M_REV] > 0.0:
        cap = reversal_cap(sp, ms[M_PITCH])
        if target > cap:
            target = cap
    ms[M_SETPOINT] += _clip(target - ms[M_SETPOINT], sp[S_NRATE] * dt)
    if mode == GOVERNED:
        q_t, dint, qmax = engine_torque(sp, n, ms[M_SETPOINT], ms[M_INTEG])
        qe = ms[M_TORQUE] + _clip(q_t - ms[M_TORQUE], sp[S_TRATE] * dt)
        qe = _clip(qe, qmax)
        integ = _clip(ms[M_INTEG] + dt * dint, qmax)
        if lc:
            # a non-reversing prime mover: fuel can only be cut, the torque does not go negative
            if qe < 0.0:
                qe = 0.0
            if integ < 0.0:
                integ = 0.0
        ms[M_TORQUE] = qe
        # governor integrator, clamped to the torque available (anti-windup)
        ms[M_INTEG] = integ
    else:
        ms[M_TORQUE] = 0.0
        ms[M_INTEG] = 0.0


@nb.njit(cache=True)
def engine_torque(sp, n, n_order, integ):
    """Governor output [N m] (limited) and the unclamped integrator rate, for one shaft."""
    err = n_order - n
    q = sp[S_KP] * err + integ
    qmax = available_torque(sp, n)
    if q > qmax:
        q = qmax
    elif q < -qmax:
        q = -qmax
    return q, sp[S_KI] * err, qmax
