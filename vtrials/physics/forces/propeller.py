"""Propeller thrust and torque in all four quadrants, fixed or controllable pitch.

Representation (β-angle form): V_r² = V_A² + (0.7πnD)², β = atan2(V_A, 0.7πnD), and
T = ½ρV_r²(π/4)D² C_T*(β), Q = ½ρV_r²(π/4)D³ C_Q*(β) — continuous through n = 0 and V_A = 0
(Van Lammeren, Van Manen & Oosterveld 1969, "The Wageningen B-screw series", SNAME Trans. 77).
In the first quadrant C_T* = 8K_T/(π(J² + (0.7π)²)).

C_T*, C_Q* come from two parts:

1. The propeller's OWN first-quadrant curve (the ship's open-water polynomial, e.g. MMG's
   K_T = k₀ + k₁J + k₂J², or the Wageningen B-series at the current pitch ratio), exact where it is
   valid: 0 ≤ J ≤ J_hi and, for the B-series, 0.6 ≤ P/D ≤ 1.4.
2. Everywhere else a quasi-steady blade-section model at the representative radius 0.7R, a
   documented simplification of measured four-quadrant data: the section, set at the geometric
   pitch angle φ = atan((P/D)/(0.7π)), meets the flow at α = φ − β; its normal-force coefficient
   is c_N = f_r(α)·sin(α + α₀) (all-angle flat plate with camber offset α₀; f_r = 1 − (1 − η_r)
   (1 − cos α)/2 lowers the force when the flow attacks the trailing edge, η_r being the
   reverse-flow efficiency) and chordwise friction c_F cos α; projected on the shaft axis and
   the rotation direction,
       C_T* = k_A (c_N cos φ − c_F cos α sin φ),   C_Q* = k_A r_q (c_N sin φ + c_F cos α cos φ).
   k_A, α₀, c_F and r_q are fitted (at load) to the own curve at the design pitch, so the two
   parts agree where both exist; η_r is a stated assumption. A one-radius section model makes
   thrust grow too slowly with pitch (it leaves out the induced inflow), so for a series curve k_A
   is multiplied by a quadratic g(P/D) fitted to the series' bollard thrust over its pitch range and
   held at its end values beyond. The section model is 2π-periodic and
   smooth in β, so thrust and torque are continuous across every quadrant boundary, through
   windmilling, locked-propeller drag, crash-back and backing, and through zero and negative
   pitch (controllable-pitch reversal).
The own-curve correction is blended in with C¹ cosine tapers (10° of β, 0.1 of P/D) at the edges
of its validity, keeping continuity.

Wake: MMG maneuvering wake (1 − w_P)/(1 − w_P0) = 1 + [1 − exp(−C₁|β_P|)](C₂ − 1) (Yasukawa &
Yoshimura 2015) or a constant w_P0; no wake when the ship goes astern (the propeller then leads
the hull; u_A = u(1 − w) is continuous at u = 0). Thrust deduction t_P ahead, t_P_astern for
negative thrust. When the thrust is negative the propeller also pushes its stern sideways (the
unequal blade loading of the upper and lower halves in the hull's wake): a lateral force
Y_P = rot·sign(n)·c_side·|T| (right-handed propeller going astern: stern to port, bow to starboard;
twin screws turning outward cancel), c_side a stated fraction, zero for positive thrust.
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np
from scipy.optimize import least_squares

from vtrials.physics.forces.registry import register
from vtrials.schema import integer, num, text
from vtrials.physics.forces import bseries
from vtrials.physics.forces import context as L

TAPER_BETA = math.radians(10.0)
TAPER_PD = 0.1
K07 = 0.7 * math.pi


@dataclasses.dataclass(frozen=True, kw_only=True)
class Propeller:
    name: str = text("propeller name (referenced by shafts and rudders)")
    diameter: float = num("propeller diameter D_P", "m", 0.0, 20.0, lo_open=True)
    x: float = num("longitudinal position from the origin (+ forward)", "m", -300, 300)
    y: float = num("lateral position (+ starboard)", "m", -50, 50)
    z: float = num("depth of the shaft line below the waterline", "m", -10, 50)
    t_P: float = num("thrust deduction factor t_P (ahead thrust)", "", 0.0, 0.9)
    t_P_astern: float = num("thrust deduction for negative thrust", "", 0.0, 0.9, default=0.0)
    wake_model: str = text("maneuvering wake: 'mmg' (KVLCC2 form) or 'constant'", ("mmg", "constant"),
                           default="constant")
    w_P0: float = num("wake fraction in straight motion w_P0", "", 0.0, 0.9)
    x_P_prime: float = num("longitudinal propeller position in the MMG wake model x'_P (÷L)", "", -1, 1,
                           default=0.0)
    C1: float = num("MMG wake model C1", "", 0, 20, default=0.0)
    C2_pos: float = num("MMG wake model C2 for β_P > 0", "", 0, 5, default=1.0)
    C2_neg: float = num("MMG wake model C2 for β_P ≤ 0", "", 0, 5, default=1.0)
    curve: str = text("first-quadrant curve: 'polynomial' (k0..k2, q0..q2) or 'bseries'",
                      ("polynomial", "bseries"))
    k0: float = num("K_T polynomial k0", "", -2, 2, default=0.0)
    k1: float = num("K_T polynomial k1", "", -2, 2, default=0.0)
    k2: float = num("K_T polynomial k2", "", -2, 2, default=0.0)
    q0: float = num("K_Q polynomial q0", "", -1, 1, default=0.0)
    q1: float = num("K_Q polynomial q1", "", -1, 1, default=0.0)
    q2: float = num("K_Q polynomial q2", "", -1, 1, default=0.0)
    j_max: float = num("largest J at which the polynomial curve is valid", "", 0.05, 3.0, default=0.0)
    blades: int = integer("number of blades Z (B-series)", 2, 7, default=4)
    area_ratio: float = num("expanded blade area ratio A_E/A_0", "", 0.3, 1.05, default=0.7)
    pitch_ratio: float = num("design pitch ratio P/D at 0.7R", "", 0.3, 2.0)
    reverse_efficiency: float = num("reverse-flow efficiency η_r of the section model", "", 0.3, 1.0,
                                    default=0.75)
    backing_side_force: float = num("transverse force of the propeller when its thrust is negative, as a "
                                    "fraction of |T| (the 'paddle-wheel' effect when backing)", "", 0.0, 0.5,
                                    default=0.0)

    def own_curve(self) -> tuple[np.ndarray, np.ndarray, float, float, float]:
        """(K_T terms, K_Q terms, J_hi or J_hi per P/D, P/D low, P/D high) of the own curve."""
        if self.curve == "polynomial":
            kt = np.array([[self.k0, 0, 0], [self.k1, 1, 0], [self.k2, 2, 0]], dtype=float)
            kq = np.array([[self.q0, 0, 0], [self.q1, 1, 0], [self.q2, 2, 0]], dtype=float)
            return kt, kq, -self.j_max, -1e9, 1e9  # negative: a fixed J_hi
        kt = bseries.reduce_terms(bseries.KT_TERMS, self.area_ratio, self.blades)
        kq = bseries.reduce_terms(bseries.KQ_TERMS, self.area_ratio, self.blades)
        return kt, kq, 0.95, 0.6, 1.4  # J_hi = 0.95 × (J at zero thrust ≈ 1.05 P/D) ≈ P/D


def _eval_terms(terms, J, pd):
    """K = Σ C' J^s (P/D)^t (numpy)."""
    return sum(c * J ** s * pd ** t for c, s, t in terms)


def section_coefficients(beta, phi, p):
    """C_T*, C_Q* of the blade-section model (numpy); p = (k_A, α₀, c_F, r_q, η_r)."""
    kA, a0, cF, rq, eta_r = p
    al = phi - beta
    fr = 1.0 - (1.0 - eta_r) * 0.5 * (1.0 - np.cos(al))
    cn = fr * np.sin(al + a0)
    ct = kA * (cn * np.cos(phi) - cF * np.cos(al) * np.sin(phi))
    cq = kA * rq * (cn * np.sin(phi) + cF * np.cos(al) * np.cos(phi))
    return ct, cq


def fit_section_model(prop: Propeller) -> tuple[np.ndarray, float]:
    """Fit k_A, α₀, c_F, r_q to the own curve at the design pitch; return (params, max |ΔK_T|)."""
    kt_t, kq_t, jhi, _, _ = prop.own_curve()
    pd = prop.pitch_ratio
    J_hi = -jhi if jhi < 0 else jhi * pd
    J = np.linspace(0.0, J_hi, 40)
    kt = _eval_terms(kt_t, J, pd)
    kq = _eval_terms(kq_t, J, pd)
    den = np.pi * (J ** 2 + K07 ** 2)
    ct, cq = 8 * kt / den, 8 * kq / den
    beta = np.arctan2(J, K07)
    phi = math.atan(pd / K07)
    eta_r = prop.reverse_efficiency

    def res(x):
        a, b = section_coefficients(beta, phi, (*x, eta_r))
        return np.concatenate([(a - ct) / max(ct.max(), 1e-6), (b - cq) / max(cq.max(), 1e-6)])

    sol = least_squares(res, [0.6, 0.03, 0.02, 0.3], bounds=([0.01, -0.5, 0.0, 0.05], [10.0, 0.5, 0.5, 2.0]))
    p = np.array([*sol.x, eta_r])
    a, _ = section_coefficients(beta, phi, p)
    return p, float(np.max(np.abs(a - ct) * den / 8))


def pitch_gain(prop: Propeller, p: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Quadratic g(P/D) that scales the section model to the own curve's bollard thrust at every pitch
    of the own curve's range (the one-radius section model under-predicts how thrust grows with
    pitch, the induced inflow being left out); returns (g coefficients, P/D low, P/D high), g held
    constant outside. A fixed-pitch own curve has one pitch: g = 1."""
    kt_t, _, _, pd_lo, pd_hi = prop.own_curve()
    if prop.curve == "polynomial":
        return np.array([1.0, 0.0, 0.0]), prop.pitch_ratio, prop.pitch_ratio
    lo = pd_lo - TAPER_PD
    pds = np.linspace(lo, pd_hi, 25)
    ratio = []
    for pd in pds:
        ct_sec, _ = section_coefficients(np.array([0.0]), math.atan(pd / K07), p)
        kt0 = float(_eval_terms(kt_t, 0.0, pd))
        ratio.append(8 * kt0 / (math.pi * K07 ** 2) / ct_sec[0])
    g = np.polynomial.polynomial.polyfit(pds, ratio, 2)
    return g, lo, pd_hi


def pack(pr: Propeller, index: int, length: float, rho: float, u_floor: float, rotation: int = 1) -> np.ndarray:
    kt_t, kq_t, jhi, pd_lo, pd_hi = pr.own_curve()
    sec, _ = fit_section_model(pr)
    g, g_lo, g_hi = pitch_gain(pr, sec)
    wake = 1.0 if pr.wake_model == "mmg" else 0.0
    head = [index, length, rho, u_floor, pr.diameter, pr.x, pr.y, pr.z, pr.t_P, pr.t_P_astern, wake, pr.w_P0,
            pr.x_P_prime, pr.C1, pr.C2_pos, pr.C2_neg, *sec, jhi, pd_lo, pd_hi, rotation * pr.backing_side_force,
            *g, g_lo, g_hi, len(kt_t), len(kq_t)]
    assert len(head) == P_TERMS
    return np.concatenate([np.array(head, dtype=np.float64), kt_t.ravel(), kq_t.ravel(), _dense(kt_t, kq_t)])


def _dense(kt_t: np.ndarray, kq_t: np.ndarray) -> np.ndarray:
    """Tail of the parameter block: [n_J, n_PD, C_T (n_J × n_PD), C_Q (n_J × n_PD)], the terms
    (C', s, t) of each curve summed into a dense coefficient table by exponent, row major, for the
    kernel's two-variable Horner evaluation (:func:`own_curve`)."""
    ex = np.concatenate([kt_t[:, 1:3], kq_t[:, 1:3]])
    if np.any(ex < 0) or np.any(ex != np.round(ex)):
        raise ValueError("own-curve exponents must be whole numbers ≥ 0")
    nj = int(ex[:, 0].max()) + 1
    npd = int(ex[:, 1].max()) + 1
    tables = np.zeros((2, nj, npd))
    for tab, terms in zip(tables, (kt_t, kq_t)):
        for c, s, t in terms:
            tab[int(s), int(t)] += c
    return np.concatenate([[nj, npd], tables.ravel()])


# parameter block indices (then the K_T and K_Q terms (C', s, t), then the dense tables of _dense)
(P_IDX, P_L, P_RHO, P_UFLOOR, P_D, P_X, P_Y, P_Z, P_TP, P_TPA, P_WAKE, P_W0, P_XP, P_C1, P_C2P, P_C2N,
 P_KA, P_A0, P_CF, P_RQ, P_ETA, P_JHI, P_PDLO, P_PDHI, P_SIDE, P_G0, P_G1, P_G2, P_GLO, P_GHI, P_NT,
 P_NQ) = range(32)
P_TERMS = 32


@nb.njit(cache=True)
def wake_factor(beta_p, C1, C2_pos, C2_neg):
    """(1 − w_P)/(1 − w_P0) in maneuvering motion (MMG, KVLCC2 form)."""
    C2 = C2_pos if beta_p > 0.0 else C2_neg
    return 1.0 + (1.0 - math.exp(-C1 * abs(beta_p))) * (C2 - 1.0)


@nb.njit(cache=True)
def _taper(x, lo, hi, width):
    """1 on [lo, hi], cosine taper to 0 over `width` outside, 0 beyond (C¹)."""
    if x < lo - width or x > hi + width:
        return 0.0
    if x < lo:
        return 0.5 * (1.0 + math.cos(math.pi * (lo - x) / width))
    if x > hi:
        return 0.5 * (1.0 + math.cos(math.pi * (x - hi) / width))
    return 1.0


@nb.njit(cache=True)
def own_curve(p, J, pd):
    """K_T, K_Q of the own first-quadrant curve, Σ C' J^s (P/D)^t, for parameter block p.

    Evaluated by Horner's rule in both variables over the dense coefficient tables of the block's
    tail (:func:`_dense`): Σ_s J^s (Σ_t C_st (P/D)^t), no power function and no allocation (a
    B-series curve is 7 × 7: ~100 multiply-adds where the term-by-term sum raised ~11 powers and
    tabulated them in an allocated array). Equal to the term-by-term sum to rounding.
    """
    nt = int(p[P_NT])
    nq = int(p[P_NQ])
    o = P_TERMS + 3 * (nt + nq)
    nj = int(p[o])
    npd = int(p[o + 1])
    bt = o + 2
    bq = bt + nj * npd
    kt = 0.0
    kq = 0.0
    for s in range(nj - 1, -1, -1):
        it = 0.0
        iq = 0.0
        r = s * npd
        for t in range(npd - 1, -1, -1):
            it = it * pd + p[bt + r + t]
            iq = iq * pd + p[bq + r + t]
        kt = kt * J + it
        kq = kq * J + iq
    return kt, kq


@nb.njit(cache=True)
def coefficients(p, beta, pd):
    """C_T*(β), C_Q*(β) at pitch ratio pd for parameter block p (see module docstring)."""
    phi = math.atan(pd / K07)
    al = phi - beta
    ca = math.cos(al)
    fr = 1.0 - (1.0 - p[P_ETA]) * 0.5 * (1.0 - ca)
    cn = fr * math.sin(al + p[P_A0])
    pg = min(max(pd, p[P_GLO]), p[P_GHI])
    kA = p[P_KA] * (p[P_G0] + pg * (p[P_G1] + pg * p[P_G2]))
    ct = kA * (cn * math.cos(phi) - p[P_CF] * ca * math.sin(phi))
    cq = kA * p[P_RQ] * (cn * math.sin(phi) + p[P_CF] * ca * math.cos(phi))
    jhi = -p[P_JHI] if p[P_JHI] < 0.0 else p[P_JHI] * pd
    wgt = _taper(beta, 0.0, math.atan(jhi / K07), TAPER_BETA) * _taper(pd, p[P_PDLO], p[P_PDHI], TAPER_PD)
    if wgt > 0.0:
        J = K07 * math.tan(beta)
        kt, kq = own_curve(p, J, pd)
        den = math.pi * (J * J + K07 * K07)
        ct += wgt * (8.0 * kt / den - ct)
        cq += wgt * (8.0 * kq / den - cq)
    return ct, cq


@nb.njit(cache=True, fastmath=False, inline="always")
def kernel(p, s, env, ctx, aux, w):
    k = int(p[P_IDX])
    Lpp = p[P_L]
    rho = p[P_RHO]
    D = p[P_D]
    u = ctx[L.NU_R + 0]
    v = ctx[L.NU_R + 1] - aux[L.AUX_FLOW]          # relative to the waves' cross-flow (wave_flow)
    r = ctx[L.NU_R + 5] - aux[L.AUX_FLOW + 1]
    if u > 0.0:
        if p[P_WAKE] > 0.0:
            U = math.sqrt(u * u + v * v)
            if U < p[P_UFLOOR]:
                U = p[P_UFLOOR]
            beta_p = math.atan2(-v, u) - p[P_XP] * r * Lpp / U
            one_minus_w = (1.0 - p[P_W0]) * wake_factor(beta_p, p[P_C1], p[P_C2P], p[P_C2N])
        else:
            one_minus_w = 1.0 - p[P_W0]
    else:
        one_minus_w = 1.0
    uA = u * one_minus_w
    n = ctx[L.SHAFT_N + k]
    pd = ctx[L.PITCH + k]
    Ut = K07 * n * D
    Vr2 = uA * uA + Ut * Ut
    if Vr2 > 0.0:
        ct, cq = coefficients(p, math.atan2(uA, Ut), pd)
    else:
        ct = 0.0
        cq = 0.0
    T = 0.5 * rho * Vr2 * 0.25 * math.pi * D * D * ct
    Q = 0.5 * rho * Vr2 * 0.25 * math.pi * D * D * D * cq
    XP = (1.0 - p[P_TP]) * T if T >= 0.0 else (1.0 - p[P_TPA]) * T
    YP = 0.0
    if T < 0.0:
        YP = p[P_SIDE] * (1.0 if n >= 0.0 else -1.0) * (-T)
    w[0] = XP
    w[1] = YP
    w[2] = 0.0
    w[3] = -p[P_Z] * YP
    w[4] = p[P_Z] * XP
    w[5] = p[P_X] * YP - p[P_Y] * XP
    b = L.AUX_PROP + 8 * k
    aux[b + L.P_THRUST] = T
    aux[b + L.P_TORQUE] = Q
    if abs(n) > 1e-9:
        aux[b + L.P_J] = uA / (n * D)
        aux[b + L.P_KT] = T / (rho * n * n * D ** 4)
        aux[b + L.P_KQ] = Q / (rho * n * n * D ** 5)
    else:
        aux[b + L.P_J] = 0.0
        aux[b + L.P_KT] = 0.0
        aux[b + L.P_KQ] = 0.0
    aux[b + L.P_UA] = uA
    aux[b + L.P_WAKE] = 1.0 - one_minus_w
    aux[b + L.P_N] = n


COMPONENT = register("propeller", kernel)
