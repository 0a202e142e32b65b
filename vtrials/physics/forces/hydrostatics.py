"""Hydrostatic restoring and the damping of heave, roll and pitch.

Buoyancy is written as "the weight, reversed, acting at G" plus restoring terms, so that with
MuJoCo's gravity (which acts at G) the net is exactly the linear restoring of the model's own
hydrostatics (Fossen 2011, Handbook of Marine Craft Hydrodynamics, §4.2, linear restoring of a
surface vessel):

* heave: a vertical force −ρ g A_wp ζ_F acting at the centre of flotation F (x_F), ζ_F being the
  downward displacement of F from its equilibrium — this also gives the heave–pitch coupling
  −ρ g A_wp x_F and the A_wp x_F² part of pitch stiffness about the origin;
* roll: a couple −ρ g ∇ GM_T sin φ; pitch: a couple −ρ g ∇ GM_L sin θ (GM_L about F).

Froude–Krylov force of an accelerating current: the horizontal pressure gradient that accelerates
the water, −∇p = ρ DV_C/Dt, acts on the displaced volume, a force ρ∇ DV_C/Dt at the centre of
buoyancy B (x_G, 0, d − KB). With the added-mass term of the dynamics it makes a ship without
thrust move with the water, as it must.

Damping: linear in the heave, roll and pitch velocities relative to the water, B_ii set from
damping ratios of the uncoupled modes (see :mod:`vtrials.physics.vessel`), plus an optional quadratic roll
term B_44q |p| p.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from vtrials.physics.forces.registry import register
from vtrials.physics.forces import context as L



def pack_restoring(mass: float, g: float, rho: float, volume: float, waterplane_area: float,
                   x_F: float, GM_T: float, GM_L: float, r_G: np.ndarray, z_B: float) -> np.ndarray:
    return np.array([mass, g, rho, volume, waterplane_area, x_F, GM_T, GM_L, r_G[0], r_G[1], r_G[2], z_B],
                    dtype=np.float64)


def pack_damping(B33: float, B44: float, B55: float, B44q: float) -> np.ndarray:
    return np.array([B33, B44, B55, B44q], dtype=np.float64)


@nb.njit(cache=True, fastmath=False, inline="always")
def restoring_kernel(p, s, env, ctx, aux, w):
    m = p[0]
    g = p[1]
    rho = p[2]
    vol = p[3]
    Awp = p[4]
    xF = p[5]
    GMT = p[6]
    GML = p[7]
    xG = p[8]
    yG = p[9]
    zG = p[10]
    # third row of R: world down-axis expressed in body axes
    ex = ctx[L.ROT + 6]
    ey = ctx[L.ROT + 7]
    ez = ctx[L.ROT + 8]
    # buoyancy equal and opposite to the weight, at G
    fx = -m * g * ex
    fy = -m * g * ey
    fz = -m * g * ez
    kx = yG * fz - zG * fy
    ky = zG * fx - xG * fz
    kz = xG * fy - yG * fx
    # heave restoring at the centre of flotation (x_F, 0, 0)
    zeta = ctx[L.POS + 2] + ctx[L.ROT + 6] * xF
    Fh = -rho * g * Awp * zeta  # world z component (down positive)
    hx = Fh * ex
    hy = Fh * ey
    hz = Fh * ez
    # moment of (hx, hy, hz) at (xF, 0, 0): r × f = (0*hz - 0*hy, 0*hx - xF*hz, xF*hy - 0*hx)
    # Froude-Krylov force of the current's acceleration, at B = (x_G, y_G, z_B)
    an = ctx[L.CUR_ACC]
    ae = ctx[L.CUR_ACC + 1]
    mf = rho * vol
    ax = mf * (ctx[L.ROT + 0] * an + ctx[L.ROT + 3] * ae)
    ay = mf * (ctx[L.ROT + 1] * an + ctx[L.ROT + 4] * ae)
    az = mf * (ctx[L.ROT + 2] * an + ctx[L.ROT + 5] * ae)
    zB = p[11]
    phi = ctx[L.EUL + 0]
    theta = ctx[L.EUL + 1]
    w[0] = fx + hx + ax
    w[1] = fy + hy + ay
    w[2] = fz + hz + az
    w[3] = kx - rho * g * vol * GMT * math.sin(phi) + yG * az - zB * ay
    w[4] = ky - xF * hz - rho * g * vol * GML * math.sin(theta) + zB * ax - xG * az
    w[5] = kz + xF * hy + xG * ay - yG * ax


@nb.njit(cache=True, fastmath=False, inline="always")
def damping_kernel(p, s, env, ctx, aux, w):
    wr = ctx[L.NU_R + 2]
    pr = ctx[L.NU_R + 3]
    qr = ctx[L.NU_R + 4]
    w[0] = 0.0
    w[1] = 0.0
    w[2] = -p[0] * wr
    w[3] = -p[1] * pr - p[3] * abs(pr) * pr
    w[4] = -p[2] * qr
    w[5] = 0.0


HYDROSTATICS_COMPONENT = register("hydrostatics", restoring_kernel)
DAMPING_COMPONENT = register("damping", damping_kernel)
