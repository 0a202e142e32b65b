"""Hull forces of the 4-DOF surge–sway–roll–yaw model of a 51.5 m naval vessel.

Blanke M. & Christensen A. (1993) "Rudder-roll damping autopilot robustness to sway-yaw-roll
couplings", Proc. 10th Ship Control Systems Symposium, Ottawa (model from the Danish Maritime
Institute's PMM tests; coefficients as in ships.md §2). Dimensional coefficients, forces at the
PMM origin (the model's body origin), velocities through the water, φ the roll angle:

  X_H = −R(u) + X_vr v r
  Y_H = Y_|u|v |u|v + Y_ur ur + Y_v|v| v|v| + Y_v|r| v|r| + Y_r|v| r|v|
        + Y_φ|uv| φ|uv| + Y_φ|ur| φ|ur| + Y_φuu φu²
  K_H = K_|u|v |u|v + K_ur ur + K_v|v| v|v| + K_v|r| v|r| + K_r|v| r|v| + K_φ|uv| φ|uv|
        + K_φ|ur| φ|ur| + K_φuu φu² + K_|u|p |u|p + K_p|p| p|p| + K_p p + K_φφφ φ³
  N_H = N_|u|v |u|v + N_|u|r |u|r + N_r|r| r|r| + N_r|v| r|v| + N_φ|uv| φ|uv| + N_φu|r| φu|r|
        + N_φu|u| φu|u|

The published surge term X_u|u| u|u| is replaced by a resistance curve R(u) that equals it at the
nominal speed and extends to 30 kn (model file, with its source); going astern R(u) =
−c_astern R(|u|). The linear hydrostatic roll restoring −ρg∇GM φ comes from the hydrostatics
component; the published K_φ = 0.776 mg is not used, as in the MSS toolbox's implementation of
this model (with it the roll period would be 10 s instead of the 5.6 s GM 1.1 m gives).
The added-mass Coriolis terms are part of these derivatives (the model lists only rigid-body
centripetal terms besides them), so the vessel file sets added_mass.coriolis = "none".
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from vtrials.physics.forces.registry import register
from vtrials.schema import num
from vtrials.physics.forces import context as L


_NAMES = ["X_vr", "Y_uv", "Y_ur", "Y_vv", "Y_vr", "Y_rv", "Y_phiuv", "Y_phiur", "Y_phiuu",
          "K_uv", "K_ur", "K_vv", "K_vr", "K_rv", "K_phiuv", "K_phiur", "K_phiuu", "K_up", "K_pp", "K_p",
          "K_phiphiphi", "N_uv", "N_ur", "N_rr", "N_rv", "N_phiuv", "N_phiur", "N_phiuu"]


@dataclasses.dataclass(frozen=True, kw_only=True)
class HullBlanke:
    """Dimensional derivatives (SI). Names: Y_uv = Y_|u|v, Y_vv = Y_v|v|, Y_vr = Y_v|r|, Y_rv = Y_r|v|,
    Y_phiuv = Y_φ|uv|, Y_phiur = Y_φ|ur|, Y_phiuu = Y_φuu, K_up = K_|u|p, K_pp = K_p|p|,
    N_ur = N_|u|r, N_rr = N_r|r|, N_phiur = N_φu|r|, N_phiuu = N_φu|u|."""

    X_vr: float = num("X_vr (surge force per v r)", "kg/rad", -1e9, 1e9)
    Y_uv: float = num("Y_|u|v", "kg/m", -1e9, 1e9)
    Y_ur: float = num("Y_ur", "kg/rad", -1e9, 1e9)
    Y_vv: float = num("Y_v|v|", "kg/m", -1e9, 1e9)
    Y_vr: float = num("Y_v|r|", "kg/rad", -1e10, 1e10)
    Y_rv: float = num("Y_r|v|", "kg/rad", -1e10, 1e10)
    Y_phiuv: float = num("Y_φ|uv|", "kg/m", -1e9, 1e9)
    Y_phiur: float = num("Y_φ|ur|", "kg", -1e9, 1e9)
    Y_phiuu: float = num("Y_φuu", "kg/m", -1e9, 1e9)
    K_uv: float = num("K_|u|v", "kg", -1e9, 1e9)
    K_ur: float = num("K_ur", "kg m", -1e9, 1e9)
    K_vv: float = num("K_v|v|", "kg", -1e9, 1e9)
    K_vr: float = num("K_v|r|", "kg m", -1e10, 1e10)
    K_rv: float = num("K_r|v|", "kg m", -1e10, 1e10)
    K_phiuv: float = num("K_φ|uv|", "kg", -1e9, 1e9)
    K_phiur: float = num("K_φ|ur|", "kg m", -1e9, 1e9)
    K_phiuu: float = num("K_φuu", "kg", -1e9, 1e9)
    K_up: float = num("K_|u|p", "kg m", -1e9, 1e9)
    K_pp: float = num("K_p|p|", "kg m^2", -1e10, 1e10)
    K_p: float = num("K_p", "kg m^2/s", -1e10, 1e10)
    K_phiphiphi: float = num("K_φφφ", "N m", -1e10, 1e10)
    N_uv: float = num("N_|u|v", "kg", -1e10, 1e10)
    N_ur: float = num("N_|u|r", "kg m", -1e10, 1e10)
    N_rr: float = num("N_r|r|", "kg m^2", -1e11, 1e11)
    N_rv: float = num("N_r|v|", "kg m", -1e10, 1e10)
    N_phiuv: float = num("N_φ|uv|", "kg", -1e10, 1e10)
    N_phiur: float = num("N_φu|r|", "kg m", -1e10, 1e10)
    N_phiuu: float = num("N_φu|u|", "kg", -1e10, 1e10)
    astern_resistance_factor: float = num("R(−u) = −factor·R(u): transom stern leading", "", 0.5, 5.0)
    z_H: float = num("depth of the centre of the hull's surge force (for its pitch moment)", "m", -50, 50)


def pack(h: HullBlanke, speeds: np.ndarray, resistance: np.ndarray) -> np.ndarray:
    """Parameter block: the 28 derivatives, astern factor, z_H, table length, speeds, resistances."""
    vals = [getattr(h, n) for n in _NAMES]
    return np.concatenate([np.array(vals + [h.astern_resistance_factor, h.z_H, len(speeds)], dtype=np.float64),
                           np.asarray(speeds, float), np.asarray(resistance, float)])


NHEAD = len(_NAMES) + 3


@nb.njit(cache=True)
def resistance(p, u):
    """Calm-water resistance [N] at surge speed u (linear interpolation; quadratic beyond the
    table's end; astern scaled by the astern factor)."""
    n = int(p[NHEAD - 1])
    au = abs(u)
    sp = p[NHEAD:NHEAD + n]
    rs = p[NHEAD + n:NHEAD + 2 * n]
    if au >= sp[n - 1]:
        R = rs[n - 1] * (au / sp[n - 1]) ** 2
    else:
        k = 0
        while sp[k + 1] < au:
            k += 1
        R = rs[k] + (rs[k + 1] - rs[k]) * (au - sp[k]) / (sp[k + 1] - sp[k])
    if u < 0.0:
        return -p[NHEAD - 3] * R
    return R


@nb.njit(cache=True, fastmath=False, inline="always")
def kernel(p, s, env, ctx, aux, w):
    u = ctx[L.NU_R + 0]
    # cross-flow, yaw rate and heel relative to the waves' flow and surface (wave_flow; zero in calm water)
    v = ctx[L.NU_R + 1] - aux[L.AUX_FLOW]
    pr = ctx[L.NU_R + 3]
    r = ctx[L.NU_R + 5] - aux[L.AUX_FLOW + 1]
    phi_abs = ctx[L.EUL + 0]
    phi = phi_abs - aux[L.AUX_FLOW + 2]
    au = abs(u)
    av = abs(v)
    ar = abs(r)
    auv = abs(u * v)
    aur = abs(u * r)
    X = -resistance(p, u) + p[0] * v * r
    Y = (p[1] * au * v + p[2] * u * r + p[3] * v * av + p[4] * v * ar + p[5] * r * av
         + p[6] * phi * auv + p[7] * phi * aur + p[8] * phi * u * u)
    K = (p[9] * au * v + p[10] * u * r + p[11] * v * av + p[12] * v * ar + p[13] * r * av
         + p[14] * phi * auv + p[15] * phi * aur + p[16] * phi * u * u + p[17] * au * pr
         + p[18] * pr * abs(pr) + p[19] * pr + p[20] * phi_abs ** 3)
    N = (p[21] * au * v + p[22] * au * r + p[23] * r * ar + p[24] * r * av + p[25] * phi * auv
         + p[26] * phi * u * ar + p[27] * phi * u * au)
    w[0] = X
    w[1] = Y
    w[2] = 0.0
    w[3] = K
    w[4] = p[NHEAD - 2] * X
    w[5] = N


COMPONENT = register("hull_blanke", kernel)
