"""Rudder forces behind a propeller: MMG inflow, MMG or foil (lift/drag with stall) section force.

Yasukawa & Yoshimura (2015) eqs. (18)–(26):
u_R = ε u (1 − w_P) √(η{1 + κ[√(1 + 8K_T/(πJ²)) − 1]}² + (1 − η)), η = D_P/H_R, written here
as ε √(η(u_P + κ(√(u_P² + 8T/(πρD_P²)) − u_P))² + (1 − η)u_P²) with u_P = u(1 − w_P) and T the
thrust, which is the same for n > 0, stays finite as J → 0 and is defined in every quadrant (a
negative jet term is cut at zero); v_R = U γ_R β_R, β_R = β − l′_R r′;
α_R = δ − atan(v_R/u_R); F_N = ½ρA_R(u_R² + v_R²) f_α sin α_R;
X_R = −(1 − t_R)F_N sin δ, Y_R = −(1 + a_H)F_N cos δ, N_R = −(x_R + a_H x_H)F_N cos δ.
Sign: δ > 0 (trailing edge to starboard) gives N_R > 0, a turn to starboard.

Section force, two models (``lift_model``):
* ``mmg``:  F_N = ½ρA_R U_R² f_α sin α_R, no chordwise force (MMG2015 eq. 23);
* ``foil``: lift and drag of a low-aspect-ratio foil with stall, from the rudder's own lift slope
  dC_L/dα, stall angle and aspect ratio. Attached flow: C_L = a α, C_D = C_D0 + C_L²/(π e Λ);
  separated flow (flat plate, Hoerner 1965, Fluid-Dynamic Drag, ch. 3): C_L = C_N90 sin α cos α,
  C_D = C_D0 + C_N90 sin²α; blended by a logistic weight centred on the stall angle, so the force
  is continuous and the lift breaks down past stall. Normal and chordwise forces
  F_N = q A (C_L cos α + C_D sin α), F_T = q A (C_D cos α − C_L sin α); on the hull
  X = −F_N sin δ − F_T cos δ, Y = −F_N cos δ + F_T sin δ, with the MMG interaction factors.
The rudder's own lateral force acts at the rudder's centre depth z_R, the hull force it induces
(a_H part) at the hull's force depth z_H — the heel moment in a turn follows from these.
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from vtrials.physics.forces.registry import register
from vtrials.schema import num, text
from vtrials.physics.forces import context as L



@dataclasses.dataclass(frozen=True, kw_only=True)
class Rudder:
    name: str = text("rudder name")
    joint: str = text("MJCF hinge joint of this rudder (axis 0 0 -1: positive = trailing edge to starboard)")
    propeller: str = text("name of the propeller in front of this rudder")
    area: float = num("rudder area A_R", "m^2", 0.0, 500.0, lo_open=True)
    span: float = num("rudder span H_R", "m", 0.0, 50.0, lo_open=True)
    x: float = num("longitudinal position x_R from midship (MMG: −0.5 L)", "m", -300, 300)
    y: float = num("lateral position (+ starboard)", "m", -50, 50)
    z: float = num("depth of the rudder's centre of pressure below the waterline", "m", -10, 50)
    t_R: float = num("steering resistance deduction factor t_R", "", 0.0, 1.0)
    a_H: float = num("rudder force increase factor a_H", "", 0.0, 2.0)
    x_H_prime: float = num("position of the additional lateral force x'_H (÷L)", "", -1, 1)
    gamma_R_neg: float = num("flow straightening coefficient γ_R for β_R < 0", "", 0.0, 2.0)
    gamma_R_pos: float = num("flow straightening coefficient γ_R for β_R > 0", "", 0.0, 2.0)
    l_R_prime: float = num("effective longitudinal coordinate l'_R (÷L)", "", -2, 2)
    epsilon: float = num("ratio of wake fractions at rudder and propeller ε", "", 0.0, 3.0)
    kappa: float = num("propeller-to-rudder flow acceleration factor κ", "", 0.0, 2.0)
    lift_model: str = text("section force model", ("mmg", "foil"), default="mmg")
    f_alpha: float = num("MMG rudder lift gradient coefficient f_α", "1/rad", 0.0, 10.0, default=0.0)
    lift_slope: float = num("foil: lift slope dC_L/dα", "1/rad", 0.0, 10.0, default=0.0)
    stall_angle_deg: float = num("foil: stall angle", "deg", 0.0, 60.0, default=0.0)
    stall_width_deg: float = num("foil: width of the stall transition", "deg", 0.1, 20.0, default=2.0)
    drag_zero: float = num("foil: zero-lift drag coefficient C_D0", "", 0.0, 0.5, default=0.0)
    aspect_ratio: float = num("foil: effective aspect ratio Λ", "", 0.1, 20.0, default=1.0)
    oswald: float = num("foil: span efficiency e", "", 0.1, 1.5, default=0.9)
    normal_force_90: float = num("foil: flat-plate normal-force coefficient C_N90", "", 0.5, 2.5, default=1.2)
    max_angle_deg: float = num("maximum rudder angle", "deg", 0.0, 90.0, lo_open=True)
    rate_deg_s: float = num("steering gear maximum rate", "deg/s", 0.0, 100.0, lo_open=True)
    time_constant: float = num("steering gear follow-up time constant (proportional band = rate × T)",
                               "s", 0.0, 30.0, lo_open=True)


def pack(rd: Rudder, index: int, prop_index: int, prop_diameter: float, length: float,
         rho: float, u_floor: float, z_hull: float) -> np.ndarray:
    foil = 1.0 if rd.lift_model == "foil" else 0.0
    return np.array([index, prop_index, length, rho, u_floor, rd.area, rd.span, rd.x, rd.y, rd.z,
                     rd.t_R, rd.a_H, rd.x_H_prime, rd.gamma_R_neg, rd.gamma_R_pos, rd.l_R_prime,
                     rd.epsilon, rd.kappa, rd.f_alpha, prop_diameter, z_hull, foil, rd.lift_slope,
                     math.radians(rd.stall_angle_deg), math.radians(rd.stall_width_deg), rd.drag_zero,
                     rd.aspect_ratio, rd.oswald, rd.normal_force_90], dtype=np.float64)


@nb.njit(cache=True)
def foil_coefficients(alpha, a, stall, width, cd0, ar, e, cn90):
    """C_L, C_D of the foil model at angle of attack alpha [rad] (any angle)."""
    sa = math.sin(alpha)
    ca = math.cos(alpha)
    cl_sep = cn90 * sa * ca
    cd_sep = cd0 + cn90 * sa * sa
    if ca <= 0.0:  # flow from the trailing edge (going astern): flat plate only
        return cl_sep, cd_sep
    al = math.atan2(sa, ca)  # |α| < 90°
    cl_att = a * al
    cd_att = cd0 + cl_att * cl_att / (math.pi * e * ar)
    wgt = 1.0 / (1.0 + math.exp((abs(al) - stall) / width))
    return wgt * cl_att + (1.0 - wgt) * cl_sep, wgt * cd_att + (1.0 - wgt) * cd_sep


@nb.njit(cache=True, fastmath=False, inline="always")
def kernel(p, s, env, ctx, aux, w):
    k = int(p[0])
    kp = int(p[1])
    Lpp = p[2]
    rho = p[3]
    AR = p[5]
    HR = p[6]
    xR = p[7]
    yR = p[8]
    zR = p[9]
    D = p[19]
    u = ctx[L.NU_R + 0]
    v = ctx[L.NU_R + 1] - aux[L.AUX_FLOW]          # relative to the waves' cross-flow (wave_flow)
    r = ctx[L.NU_R + 5] - aux[L.AUX_FLOW + 1]
    U = math.sqrt(u * u + v * v)
    beta = math.atan2(-v, u)
    delta = ctx[L.DELTA + k]
    b = L.AUX_PROP + 8 * kp
    uP = aux[b + L.P_UA]
    eta = min(D / HR, 1.0)  # the share of the rudder span in the propeller race
    # 8 K_T n² D²/π written with the thrust itself, 8T/(πρD²): valid in every quadrant
    jet = uP * uP + 8.0 * aux[b + L.P_THRUST] / (math.pi * rho * D * D)
    if jet < 0.0:
        jet = 0.0
    slip = uP + p[17] * (math.sqrt(jet) - uP)
    uR = p[16] * math.sqrt(eta * slip * slip + (1.0 - eta) * uP * uP)
    # v_R = U γ_R β_R with β_R = β − l'_R r', multiplied out: γ_R (U β − l'_R r L)
    UbR = U * beta - p[15] * r * Lpp
    gamma = p[13] if UbR < 0.0 else p[14]
    vR = gamma * UbR
    alpha = delta - math.atan2(vR, uR)
    UR2 = uR * uR + vR * vR
    q = 0.5 * rho * AR * UR2
    if p[21] > 0.0:
        cl, cdr = foil_coefficients(alpha, p[22], p[23], p[24], p[25], p[26], p[27], p[28])
        FN = q * (cl * math.cos(alpha) + cdr * math.sin(alpha))
        FT = q * (cdr * math.cos(alpha) - cl * math.sin(alpha))
    else:
        FN = q * p[18] * math.sin(alpha)
        FT = 0.0
    aH = p[11]
    xH = p[12] * Lpp
    cd = math.cos(delta)
    sd = math.sin(delta)
    Xr = -FN * sd - FT * cd  # the rudder's own force on the hull, body axes
    Yr = -FN * cd + FT * sd
    XR = (1.0 - p[10]) * Xr
    YR = (1.0 + aH) * Yr
    NR = (xR + aH * xH) * Yr
    z_hull = p[20]
    w[0] = XR
    w[1] = YR
    w[2] = 0.0
    w[3] = -(zR * Yr + aH * z_hull * Yr)
    w[4] = zR * XR
    w[5] = NR - yR * XR
    br = L.AUX_RUD + 8 * k
    aux[br + L.R_FN] = FN
    aux[br + L.R_UR] = uR
    aux[br + L.R_VR] = vR
    aux[br + L.R_ALPHA] = alpha
    aux[br + L.R_UR2] = UR2


COMPONENT = register("rudder", kernel)
