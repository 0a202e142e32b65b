"""Added resistance in waves for the speed–power reduction: STAWAVE-1 and STAWAVE-2.

ITTC Recommended Procedure 7.5-04-01-01.1 (2017), "Preparation, conduct and analysis of speed/power
trials", §10.3.2 and its annex on STAWAVE-2 (from the STA-JIP: Boom, Huisman & Mennen 2013, "New
guidelines for speed/power trials", SWZ Maritime). SI throughout; ρ [kg/m³], g = 9.80665 m/s².

STAWAVE-1 (head waves within ±45° off the bow, negligible heave and pitch: H_s ≤ 2.25 √(L_pp/100),
bow vertical acceleration below 0.05 g): the wave-reflection resistance of the bow,

    R_AWL = (1/16) ρ g H_s² B √(B/L_BWL),

L_BWL the length of the bow on the waterline to 95 % of the maximum breadth [m].

STAWAVE-2 (head waves, ±45°; ships with motions): the regular-wave transfer function
R_wave/ζ_A² = (R_AWML + R_AWRL)/ζ_A² integrated over the wave spectrum,

    R_AW = 2 ∫₀^∞ S_η(ω) R_wave(ω; V)/ζ_A² dω,

* motion-induced part: R_AWML = 4 ρ g ζ_A² (B²/L_pp) r̄_aw(ω̄),
  r̄_aw = ω̄^{b₁} exp[(b₁/d₁)(1 − ω̄^{d₁})] a₁ Fr^{1.50} exp(−3.50 Fr),
  ω̄ = √(L_pp/g) ∛(k_yy) ω / (1.17 Fr^{−0.143}),  a₁ = 60.3 C_B^{1.34},
  b₁ = 11.0, d₁ = 14.0 for ω̄ < 1;  b₁ = −8.50, d₁ = −14.0 for ω̄ ≥ 1;
* reflection part: R_AWRL = ½ ρ g ζ_A² B α₁(ω),
  α₁ = π² I₁²(1.5 k T) / (π² I₁²(1.5 k T) + K₁²(1.5 k T)) · f₁,  f₁ = 0.692 (V/√(T g))^{0.769} + 1.81 C_B^{6.95},
  k = ω²/g, T the draught at midship, I₁, K₁ the modified Bessel functions of the first and second kind.
k_yy is the non-dimensional pitch radius of gyration (k_yy/L_pp, ≈ 0.25), Fr = V/√(g L_pp).

Caveat: the coefficients above were taken from the STAWAVE-2 annex as we know it; the search corpus
available when this module was written held only the procedure's contents pages, not the annex text, so
they could not be re-checked against the document here (see the report of the change). The structure
(the peak of r̄_aw at ω̄ = 1, the reflection limit ½ρgζ²B f₁ in short waves, STAWAVE-1 as the
irregular-sea integral of a constant reflection coefficient) is checked in tests/test_reduce_stawave.py.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import i1e, k1e

from vtrials.errors import InputError
from vtrials.units import G

RHO_SEA = 1025.0  # [kg/m³] a default only; pass the measured density


def _positive(name: str, v: float) -> float:
    v = float(v)
    if not (math.isfinite(v) and v > 0.0):
        raise InputError("record", name, f"{v!r}: must be a finite number > 0")
    return v


def stawave1(hs: float, B: float, L_bwl: float, rho: float = RHO_SEA) -> float:
    """R_AWL = (1/16) ρ g H_s² B √(B/L_BWL) [N]; H_s, B, L_BWL [m] (ITTC 7.5-04-01-01.1, STAWAVE-1)."""
    if not (math.isfinite(hs) and hs >= 0.0):
        raise InputError("record", "hs", f"{hs!r} m: must be a finite number ≥ 0")
    B = _positive("B", B)
    L_bwl = _positive("L_bwl", L_bwl)
    return rho * G * hs * hs * B * math.sqrt(B / L_bwl) / 16.0


def stawave1_limit_hs(L_pp: float) -> float:
    """Largest H_s [m] for STAWAVE-1: 2.25 √(L_pp/100) (ITTC 7.5-04-01-01.1)."""
    return 2.25 * math.sqrt(_positive("L_pp", L_pp) / 100.0)


def _omega_bar(omega, V, L_pp, k_yy):
    Fr = V / math.sqrt(G * L_pp)
    return math.sqrt(L_pp / G) * k_yy ** (1.0 / 3.0) * np.asarray(omega, dtype=float) / (1.17 * Fr ** -0.143)


def raw_motion(omega, V: float, L_pp: float, B: float, C_B: float, k_yy: float = 0.25, rho: float = RHO_SEA):
    """R_AWML/ζ_A² [N/m²] (STAWAVE-2 motion part) at wave frequency ω [rad/s], speed V [m/s] (module doc)."""
    V = _positive("V", V)
    L_pp = _positive("L_pp", L_pp)
    Fr = V / math.sqrt(G * L_pp)
    wb = _omega_bar(omega, V, L_pp, k_yy)
    a1 = 60.3 * C_B ** 1.34
    b1 = np.where(wb < 1.0, 11.0, -8.50)
    d1 = np.where(wb < 1.0, 14.0, -14.0)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        r = np.where(wb > 0.0, wb ** b1 * np.exp((b1 / d1) * (1.0 - wb ** d1)), 0.0)
    r = np.nan_to_num(r, nan=0.0, posinf=0.0)
    return 4.0 * rho * G * B * B / L_pp * r * a1 * Fr ** 1.50 * math.exp(-3.50 * Fr)


def raw_reflection(omega, V: float, B: float, T: float, C_B: float, rho: float = RHO_SEA):
    """R_AWRL/ζ_A² [N/m²] (STAWAVE-2 reflection part) at ω [rad/s], speed V [m/s], draught T [m]."""
    T = _positive("T", T)
    B = _positive("B", B)
    k = np.asarray(omega, dtype=float) ** 2 / G
    x = 1.5 * k * T
    # I₁²/(I₁² + K₁²/π²) with the scaled Bessel functions (i1e = e^{−x} I₁, k1e = e^{x} K₁): no overflow
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = np.where(x > 0.0, 1.0 / (1.0 + (k1e(x) * np.exp(-2.0 * x) / (math.pi * i1e(x))) ** 2), 0.0)
    ratio = np.nan_to_num(ratio, nan=0.0)
    f1 = 0.692 * (V / math.sqrt(T * G)) ** 0.769 + 1.81 * C_B ** 6.95
    return 0.5 * rho * G * B * ratio * f1


def stawave2(omega, S, V: float, L_pp: float, B: float, T: float, C_B: float, k_yy: float = 0.25,
             rho: float = RHO_SEA) -> float:
    """R_AW = 2 ∫ S(ω) (R_AWML + R_AWRL)/ζ_A² dω [N] for a wave spectrum S [m² s/rad] on the grid ω [rad/s]."""
    omega = np.asarray(omega, dtype=float)
    S = np.asarray(S, dtype=float)
    if omega.shape != S.shape or omega.ndim != 1:
        raise InputError("record", "S", f"spectrum shape {S.shape} must match the frequency grid {omega.shape}")
    if C_B <= 0.0 or C_B > 1.0:
        raise InputError("record", "C_B", f"{C_B!r}: block coefficient must be in (0, 1]")
    raw = raw_motion(omega, V, L_pp, B, C_B, k_yy, rho) + raw_reflection(omega, V, B, T, C_B, rho)
    return 2.0 * float(np.trapezoid(S * raw, omega))


#: Standard uncertainty of the STAWAVE-2 method itself, relative (assumption: the scatter of its
#: regression of r̄_aw over a ship family against model tests).
METHOD_REL_STD = 0.25
#: Outside ±45° of the bow ITTC applies no correction, but the added resistance there is not zero (a
#: fast ship loses speed in following and quartering seas too). Knowing only that it lies between none
#: and the head-sea value at the same speed, the analysis takes it uniform on that range: mean ½, standard
#: deviation 1/√12 of the head-sea STAWAVE-2 value. A correction beyond ITTC 7.5-04-01-01.1, stated in
#: the results as such.
OUTSIDE_SECTOR_MEAN = 0.5
OUTSIDE_SECTOR_REL_STD = 1.0 / math.sqrt(12.0)
SECTOR = math.radians(45.0)


def observed_spectrum(omega, hs: float, tp: float, gamma: float | None = None):
    """S(ω) [m² s/rad] of an observed sea: H_s [m], T_p [s]; ``gamma`` None → Pierson–Moskowitz
    (fully developed wind sea), else JONSWAP with that peak enhancement (σ 0.07/0.09), scaled on the
    grid so that 4√m₀ = H_s (the team's own forms of the standard spectra, docs/environment.md)."""
    w = np.asarray(omega, dtype=float)
    wp = 2.0 * math.pi / _positive("tp", tp)
    x = np.where(w > 0.0, w / wp, np.inf)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        S = np.where(w > 0.0, x ** -5 * np.exp(-1.25 * x ** -4), 0.0)
        if gamma is not None:
            sig = np.where(x <= 1.0, 0.07, 0.09)
            S = S * gamma ** np.exp(-((x - 1.0) ** 2) / (2.0 * sig * sig))
    S = np.nan_to_num(S)
    m0 = float(np.trapezoid(S, w))
    return S * (hs * hs / 16.0) / m0 if m0 > 0.0 else S


def run_wave_resistance(sea: list[dict], course: float, V: float, L_pp: float, B: float, T: float, C_B: float,
                        k_yy: float = 0.25, rho: float = RHO_SEA) -> tuple[float, float]:
    """Added resistance in waves on one run [N] and its standard uncertainty, ITTC 7.5-04-01-01.1 §10.3.2:
    STAWAVE-2 for each observed wave system (dicts with ``hs_m``, ``tp_s``, ``gamma`` or None,
    ``from_rad`` the direction it comes from, ``hs_rel_std``) within ±45° of the bow at ``course`` [rad];
    outside, half the head-sea value ± its 1/√12 (:data:`OUTSIDE_SECTOR_MEAN`). Uncertainty also from
    the observed H_s (R ∝ H_s²) and the method (:data:`METHOD_REL_STD`)."""
    R, var = 0.0, 0.0
    for s in sea:
        if not s.get("hs_m", 0.0) > 0.0:
            continue
        w = np.linspace(0.2, 6.0, 600) * (2.0 * math.pi / float(s["tp_s"]))
        r = stawave2(w, observed_spectrum(w, float(s["hs_m"]), float(s["tp_s"]), s.get("gamma")), V, L_pp, B, T,
                     C_B, k_yy, rho)
        off = abs(math.remainder(course - float(s["from_rad"]), 2.0 * math.pi))
        if off <= SECTOR:
            R += r
            var += (r * math.hypot(2.0 * float(s.get("hs_rel_std", 0.0)), METHOD_REL_STD)) ** 2
        else:
            R += OUTSIDE_SECTOR_MEAN * r
            var += (OUTSIDE_SECTOR_REL_STD * r) ** 2
    return R, math.sqrt(var)
