"""The helm: rudder orders produced every simulation step, inside the dynamics kernel.

A helm program is a short list of *phases* per ship; each phase has a mode and up to seven
arguments and ends on its own condition, after which the next phase starts. Slow decisions
(when to execute, when a run is finished) belong to the crew in Python; whatever must react
within one time step (a zig-zag's heading threshold, the autopilot) lives here.

Modes (argument list a1..a7; angles in rad, rates in rad/s):

* ``OFF``        – the helm leaves the rudder order alone (set from Python, e.g. by an agent).
* ``HOLD``       – rudder order a1; ends after a2 seconds if a2 > 0.
* ``HEADING``    – PID autopilot: δ = −(K_p e + K_i ∫e + K_d r), e = wrap(ψ − a1), |δ| ≤ a2,
                   K_p = a3, K_i = a4 [1/s], K_d = a5 [s]; ends after a6 seconds if a6 > 0.
* ``ZIGZAG``     – δ/ψ zig-zag: rudder σ·a1, base heading a3 (unwrapped), first side a4 (±1);
                   when σ(ψ − a3) ≥ a2 the rudder is shifted (σ → −σ); ends after a5 shifts if a5 > 0.
* ``TURN_UNTIL`` – rudder a1 until the heading has changed by a2 (signed) from the phase start,
                   or, if a4 = 1, from the (unwrapped) base heading a3.
* ``RATE``       – hold a rate of turn a1 [rad/s] (the reverse spiral, Bech): the autopilot law of
                   ``HEADING`` tracking a heading that advances at a1 from the phase start,
                   δ = −(K_p e + K_i ∫e + K_d (r − a1)), e = ψ − ψ_start − a1·t, |δ| ≤ a2,
                   gains a3, a4, a5; ends after a6 seconds if a6 > 0.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

OFF, HOLD, HEADING, ZIGZAG, TURN_UNTIL, RATE = 0, 1, 2, 3, 4, 5
MODE_NAMES = {OFF: "off", HOLD: "hold", HEADING: "heading", ZIGZAG: "zigzag", TURN_UNTIL: "turn_until",
              RATE: "rate"}
MAX_PHASES = 8
NPHASE = 8  # mode + 7 arguments
# helm state (per ship)
H_PHASE, H_NPHASE, H_TSTART, H_PSISTART, H_INTEG, H_SIGMA, H_NSWITCH, H_ACTIVE = range(8)
NHELM = 8
MAX_EVENTS = 64
EV_PHASE_END, EV_ZIGZAG_SHIFT = 1, 2


def new_arrays(n_ships: int):
    """Phase table, helm state, event log and event count for n ships."""
    return (np.zeros((n_ships, MAX_PHASES, NPHASE)), np.zeros((n_ships, NHELM)),
            np.zeros((n_ships, MAX_EVENTS, 3)), np.zeros(n_ships, dtype=np.int64))


@nb.njit(cache=True)
def wrap(a):
    """Angle to (−π, π]."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@nb.njit(cache=True)
def _log(events, ecount, i, t, kind, value):
    c = ecount[i]
    if c < events.shape[1]:
        events[i, c, 0] = t
        events[i, c, 1] = kind
        events[i, c, 2] = value
        ecount[i] = c + 1


@nb.njit(cache=True)
def helm_step(i, t, psi_u, r, dt, phases, hs, events, ecount, current_order):
    """Rudder order [rad] for ship i at time t; advances phases. Returns current_order when OFF."""
    if hs[i, H_ACTIVE] == 0.0:
        return current_order
    for _guard in range(MAX_PHASES + 1):
        k = int(hs[i, H_PHASE])
        if k >= int(hs[i, H_NPHASE]):
            return current_order
        ph = phases[i, k]
        mode = int(ph[0])
        if hs[i, H_TSTART] < 0.0:  # phase starts now
            hs[i, H_TSTART] = t
            hs[i, H_PSISTART] = psi_u
            hs[i, H_INTEG] = 0.0
            hs[i, H_NSWITCH] = 0.0
            if mode == ZIGZAG:
                hs[i, H_SIGMA] = ph[4]
        elapsed = t - hs[i, H_TSTART]
        done = False
        order = current_order
        if mode == OFF:
            return current_order
        elif mode == HOLD:
            order = ph[1]
            done = ph[2] > 0.0 and elapsed >= ph[2]
        elif mode == HEADING:
            e = wrap(psi_u - ph[1])
            lim = ph[2]
            u = -(ph[3] * e + ph[4] * hs[i, H_INTEG] + ph[5] * r)
            if u > lim:
                u = lim
            elif u < -lim:
                u = -lim
            else:
                hs[i, H_INTEG] += e * dt
            order = u
            done = ph[6] > 0.0 and elapsed >= ph[6]
        elif mode == ZIGZAG:
            sigma = hs[i, H_SIGMA]
            if sigma * (psi_u - ph[3]) >= ph[2]:
                sigma = -sigma
                hs[i, H_SIGMA] = sigma
                hs[i, H_NSWITCH] += 1.0
                _log(events, ecount, i, t, EV_ZIGZAG_SHIFT, hs[i, H_NSWITCH])
            order = sigma * ph[1]
            done = ph[5] > 0.0 and hs[i, H_NSWITCH] >= ph[5]
        elif mode == RATE:
            e = psi_u - hs[i, H_PSISTART] - ph[1] * elapsed
            lim = ph[2]
            u = -(ph[3] * e + ph[4] * hs[i, H_INTEG] + ph[5] * (r - ph[1]))
            if u > lim:
                u = lim
            elif u < -lim:
                u = -lim
            else:
                hs[i, H_INTEG] += e * dt
            order = u
            done = ph[6] > 0.0 and elapsed >= ph[6]
        elif mode == TURN_UNTIL:
            order = ph[1]
            target = ph[2]
            base = ph[3] if ph[4] == 1.0 else hs[i, H_PSISTART]
            change = psi_u - base
            done = (target >= 0.0 and change >= target) or (target < 0.0 and change <= target)
        if not done:
            return order
        _log(events, ecount, i, t, EV_PHASE_END, float(k))
        hs[i, H_PHASE] = k + 1
        hs[i, H_TSTART] = -1.0
        current_order = order
    return current_order
