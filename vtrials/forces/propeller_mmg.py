"""Propeller thrust and torque of the MMG standard method (first quadrant).

Yasukawa & Yoshimura (2015) eqs. (15)–(17): X_P = (1 − t_P) ρ n² D_P⁴ K_T(J),
J = u (1 − w_P)/(n D_P), K_T = k₀ + k₁J + k₂J², and the wake fraction in maneuvering motion
(1 − w_P)/(1 − w_P0) = 1 + [1 − exp(−C₁|β_P|)](C₂ − 1), β_P = β − x′_P r′ (their eq. 16, the
KVLCC2 form). Torque uses K_Q = q₀ + q₁J + q₂J² (open-water torque curve of the ship's own
propeller). The thrust acts along the shaft at (x, y, z); the torque is returned in ``aux`` for the
shaft dynamics. Valid for n > 0 and J in the first quadrant; four-quadrant propellers come with
the propulsion work.
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from ..schema import num, text
from . import layout as L

KIND = 2


@dataclasses.dataclass(frozen=True)
class PropellerMMG:
    name: str = text("propeller name (referenced by shafts and rudders)")
    diameter: float = num("propeller diameter D_P", "m", 0.0, 20.0, lo_open=True)
    x: float = num("longitudinal position from midship (+ forward)", "m", -300, 300)
    y: float = num("lateral position (+ starboard)", "m", -50, 50)
    z: float = num("depth of the shaft line below the waterline", "m", -10, 50)
    t_P: float = num("thrust deduction factor t_P", "", 0.0, 0.9)
    w_P0: float = num("wake fraction in straight motion w_P0", "", 0.0, 0.9)
    x_P_prime: float = num("longitudinal propeller position in the wake model x'_P (÷L)", "", -1, 1)
    k0: float = num("K_T polynomial k0", "", -2, 2)
    k1: float = num("K_T polynomial k1", "", -2, 2)
    k2: float = num("K_T polynomial k2", "", -2, 2)
    q0: float = num("K_Q polynomial q0", "", -1, 1)
    q1: float = num("K_Q polynomial q1", "", -1, 1)
    q2: float = num("K_Q polynomial q2", "", -1, 1)
    C1: float = num("wake model C1", "", 0, 20)
    C2_pos: float = num("wake model C2 for β_P > 0", "", 0, 5)
    C2_neg: float = num("wake model C2 for β_P ≤ 0", "", 0, 5)


def pack(pr: PropellerMMG, index: int, length: float, rho: float, u_floor: float) -> np.ndarray:
    return np.array([index, length, rho, u_floor, pr.diameter, pr.x, pr.y, pr.z, pr.t_P, pr.w_P0,
                     pr.x_P_prime, pr.k0, pr.k1, pr.k2, pr.q0, pr.q1, pr.q2,
                     pr.C1, pr.C2_pos, pr.C2_neg], dtype=np.float64)


@nb.njit(cache=True)
def wake_factor(beta_p, C1, C2_pos, C2_neg):
    """(1 − w_P)/(1 − w_P0) in maneuvering motion (MMG, KVLCC2 form)."""
    C2 = C2_pos if beta_p > 0.0 else C2_neg
    return 1.0 + (1.0 - math.exp(-C1 * abs(beta_p))) * (C2 - 1.0)


@nb.njit(cache=True, fastmath=False, inline="always")
def kernel(p, env, ctx, aux, w):
    k = int(p[0])
    Lpp = p[1]
    rho = p[2]
    D = p[4]
    u = ctx[L.NU_R + 0]
    v = ctx[L.NU_R + 1]
    r = ctx[L.NU_R + 5]
    U = math.sqrt(u * u + v * v)
    if U < p[3]:
        U = p[3]
    beta = math.atan2(-v, u)
    beta_p = beta - p[10] * r * Lpp / U
    one_minus_w = (1.0 - p[9]) * wake_factor(beta_p, p[17], p[18], p[19])
    uA = u * one_minus_w
    n = ctx[L.SHAFT_N + k]
    if n > 1e-9:
        J = uA / (n * D)
        KT = p[11] + p[12] * J + p[13] * J * J
        KQ = p[14] + p[15] * J + p[16] * J * J
    else:
        J = 0.0
        KT = 0.0
        KQ = 0.0
    T = rho * n * n * D ** 4 * KT
    Q = rho * n * n * D ** 5 * KQ
    XP = (1.0 - p[8]) * T
    w[0] = XP
    w[1] = 0.0
    w[2] = 0.0
    w[3] = 0.0
    w[4] = p[7] * XP
    w[5] = -p[6] * XP
    b = L.AUX_PROP + 8 * k
    aux[b + L.P_THRUST] = T
    aux[b + L.P_TORQUE] = Q
    aux[b + L.P_J] = J
    aux[b + L.P_KT] = KT
    aux[b + L.P_KQ] = KQ
    aux[b + L.P_UA] = uA
    aux[b + L.P_WAKE] = 1.0 - one_minus_w
    aux[b + L.P_N] = n
