"""Horizontal added-mass Coriolis–centripetal force of the seakeeping block (heave, roll, pitch) of A∞.

With seakeeping on, the heave/roll/pitch block of the added-mass matrix is the database's A∞
(:mod:`vtrials.physics.seakeeping.timedomain`), applied by the dynamics' exact solve to body-axis
accelerations. A fluid momentum P = M_A ν carried in body axes turns with the body, and the equations
of motion in body axes need the Kirchhoff Coriolis–centripetal term C_A(ν)ν = [ω × P; ω × L + v × P]
(Fossen 2011, Handbook of Marine Craft Hydrodynamics and Motion Control, Thm 3.2 / §6.3). A hull
model whose derivatives already contain their own added-mass Coriolis terms (``added_mass.coriolis =
"none"``, patrol51's Blanke–Christensen model) has the dynamics apply no C_A at all, so the A∞ block
then has none either. Its missing horizontal part is second order in the wave motions but has a
mean: for heave and pitch in head seas the surge term −q P_z, P_z = A33 w + A34 p + A35 q, averages to
about −A33 ⟨q w⟩ ≠ 0. Without it the linear model leaves a spurious mean surge force: at zero speed in
JONSWAP H_s 1.5 m, T_p 8 s head seas ⟨q P_z⟩ = 1.2–1.3 kN (measured) — the "creep" of the ship ahead
(≈ 0.4–0.6 m/s) seen in tests/test_seakeeping_irregular.py — while the true second-order mean force
is the database's drift (:mod:`vtrials.physics.forces.wave_drift`), added separately.

This component supplies the missing horizontal terms of −C_A(ν_r)ν_r for the block (P_x = P_y = 0,
L_z = 0 there), with ν_r the velocity through the water as in the dynamics:

    X = −q P_z,   Y = p P_z,   N = −(p L_y − q L_x),   L_x = A43 w + A44 p + A45 q,  L_y = A53 w + A54 p + A55 q.

The vertical-plane terms (heave; roll and pitch moments, among them the Munk moment u P_z, which is
first order at forward speed and would change the speed coupling that :func:`vtrials.physics.seakeeping.rao.rao`
matches) are left out: they oscillate about zero against the hydrostatic restoring, whereas a mean
horizontal force has no restoring and drives the ship away. For vessels with ``coriolis`` "no_munk" or
"kirchhoff" the dynamics already include these horizontal terms for the whole M_A, so
:func:`vtrials.scenario.sea_vessel` adds this component only for ``coriolis = "none"``.

Parameter block: [A33, A34, A35, A43, A44, A45, A53, A54, A55] (the A∞ entries, SI).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from vtrials.physics.forces import context as L
from vtrials.physics.forces.registry import register


def pack(A_inf: np.ndarray) -> np.ndarray:
    """Parameter block from the 6×6 infinite-frequency added mass (the heave/roll/pitch block is used)."""
    A = np.asarray(A_inf, dtype=np.float64)
    return np.ascontiguousarray(A[2:5, 2:5].ravel())


@nb.njit(cache=True, fastmath=False)
def seakeeping_coriolis_kernel(p, s, env, ctx, aux, w):
    wr = ctx[L.NU_R + 2]
    pr = ctx[L.NU_R + 3]
    qr = ctx[L.NU_R + 4]
    Pz = p[0] * wr + p[1] * pr + p[2] * qr
    Lx = p[3] * wr + p[4] * pr + p[5] * qr
    Ly = p[6] * wr + p[7] * pr + p[8] * qr
    w[0] = -qr * Pz
    w[1] = pr * Pz
    w[2] = 0.0
    w[3] = 0.0
    w[4] = 0.0
    w[5] = -(pr * Ly - qr * Lx)


SEAKEEPING_CORIOLIS_COMPONENT = register("seakeeping_coriolis", seakeeping_coriolis_kernel)
