"""Hull maneuvering forces of the MMG standard method.

Yasukawa H. & Yoshimura Y. (2015) "Introduction of MMG standard method for ship maneuvering
predictions", J. Mar. Sci. Technol. 20:37–52, eqs. (7)–(9). Forces act at midship; the velocity
used is the velocity relative to the water. The hull lateral force and surge force are taken to
act at depth ``z_H`` below the waterline, which gives the heel moment in a turn (an assumption of
this project: MMG is a horizontal-plane model and names no vertical centre).

Validity: ahead motion (u > 0). The terms are evaluated multiplied out (e.g. Y'_v v' U² = Y'_v v U) so
that the hull is force-free at rest; where U divides, it is floored at ``u_floor`` so the kernel stays
finite, but low-speed maneuvers need a low-speed hull model.
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from vtrials.physics.forces.registry import register
from vtrials.schema import num
from vtrials.physics.forces import context as L



@dataclasses.dataclass(frozen=True)
class HullMMG:
    """Non-dimensional hull derivatives (prime system: forces ½ρLdU², moments ½ρL²dU²)."""

    R0: float = num("resistance coefficient R'_0", "", 0.0, 1.0)
    X_vv: float = num("X'_vv", "", -5, 5)
    X_vr: float = num("X'_vr", "", -5, 5)
    X_rr: float = num("X'_rr", "", -5, 5)
    X_vvvv: float = num("X'_vvvv", "", -10, 10)
    Y_v: float = num("Y'_v", "", -5, 5)
    Y_r: float = num("Y'_r", "", -5, 5)
    Y_vvv: float = num("Y'_vvv", "", -10, 10)
    Y_vvr: float = num("Y'_vvr", "", -10, 10)
    Y_vrr: float = num("Y'_vrr", "", -10, 10)
    Y_rrr: float = num("Y'_rrr", "", -10, 10)
    N_v: float = num("N'_v", "", -5, 5)
    N_r: float = num("N'_r", "", -5, 5)
    N_vvv: float = num("N'_vvv", "", -10, 10)
    N_vvr: float = num("N'_vvr", "", -10, 10)
    N_vrr: float = num("N'_vrr", "", -10, 10)
    N_rrr: float = num("N'_rrr", "", -10, 10)
    z_H: float = num("depth of the centre of hull surge and sway forces below the waterline", "m", -100, 100)


def pack(h: HullMMG, length: float, draught: float, rho: float, u_floor: float) -> np.ndarray:
    """Parameter block of the kernel."""
    return np.array([length, draught, rho, u_floor, h.R0, h.X_vv, h.X_vr, h.X_rr, h.X_vvvv,
                     h.Y_v, h.Y_r, h.Y_vvv, h.Y_vvr, h.Y_vrr, h.Y_rrr,
                     h.N_v, h.N_r, h.N_vvv, h.N_vvr, h.N_vrr, h.N_rrr, h.z_H], dtype=np.float64)


@nb.njit(cache=True, fastmath=False, inline="always")
def kernel(p, s, env, ctx, aux, w):
    Lpp = p[0]
    d = p[1]
    rho = p[2]
    u = ctx[L.NU_R + 0]
    v = ctx[L.NU_R + 1] - aux[L.AUX_FLOW]          # relative to the waves' cross-flow (wave_flow)
    r = ctx[L.NU_R + 5] - aux[L.AUX_FLOW + 1]
    U2 = u * u + v * v
    Ud = math.sqrt(U2)
    if Ud < p[3]:
        Ud = p[3]  # floor only where U divides: at rest every term is zero
    rl = r * Lpp
    h = 0.5 * rho * Lpp * d
    # ½ρLdU²·(polynomial in v' = v/U, r' = rL/U), multiplied out
    X = h * (-p[4] * U2 + p[5] * v * v + p[6] * v * rl + p[7] * rl * rl + p[8] * v ** 4 / (Ud * Ud))
    Y = h * (p[9] * v * Ud + p[10] * rl * Ud + (p[11] * v ** 3 + p[12] * v * v * rl
                                                 + p[13] * v * rl * rl + p[14] * rl ** 3) / Ud)
    N = h * Lpp * (p[15] * v * Ud + p[16] * rl * Ud + (p[17] * v ** 3 + p[18] * v * v * rl
                                                       + p[19] * v * rl * rl + p[20] * rl ** 3) / Ud)
    zH = p[21]
    w[0] = X
    w[1] = Y
    w[2] = 0.0
    w[3] = -zH * Y
    w[4] = zH * X
    w[5] = N


COMPONENT = register("hull_mmg", kernel)
