"""Wind: mean profile, gust spectra and their synthesis, and the wind loads on the ship.

Everything is SI inside: speeds in m/s, heights in m, frequencies f in Hz (ω = 2πf in rad/s),
angles in rad. Knots and degrees appear only in names that say so (the scenario edge, :class:`Wind`).

1. Mean wind profile (power law to the 10 m reference), exponent 1/9 as in ITTC 7.5-04-01-01.1
   (2017, rev. 2021) §"Resistance increase due to wind" and ISO 15016:2015, which the trial analysis
   (vtrials.reduce.speedpower) uses to bring the anemometer's wind to the reference height:
       U(z) = U₁₀ (z / 10 m)^α.

2. Gust spectra, one-sided S(f) in (m/s)²/Hz of the longitudinal gust u'(t) (zero mean):

   * NPD / Frøya (ISO 19901-1:2015; DNV-RP-C205 §2.3; Andersen & Løvseth 2006, "The Frøya
     database and maritime boundary layer wind description", Marine Structures 19:173–192):
         S(f) = 320 (U₀/10)² (z/10)^0.45 / (1 + f̃ⁿ)^(5/(3n)),
         f̃ = 172 f (z/10)^(2/3) (U₀/10)^(−0.75),   n = 0.468,
     U₀ the 1-hour mean speed at 10 m [m/s], z [m]. The ratios U₀/10 and z/10 are dimensionless
     (U₀ divided by 10 m/s, z by 10 m), so the constant 320 carries the units of S·Hz: it is
     320 m²/s, i.e. S in m²/s²/Hz. ``f̃`` is dimensionless, so 172 carries seconds. The check:
     the variance ∫S df agrees with the NPD turbulence intensity I_u = 0.06 (1 + 0.043 U₀)
     (z/10)^−0.22 (same standards) to within the ~10–25 % that the two published formulas differ
     by (tests/test_wind.py); reading 320 in any other unit would miss by a factor ≥ 3.
     Asymptotes: S(0) = 320 (U₀/10)² (z/10)^0.45; S ∝ f^(−5/3) for f → ∞ (Kolmogorov).
   * Harris (1971, "The nature of the wind", CIRIA seminar, London; the form of docs/
     environment.md and Ochi & Shin 1988, OTC 5736): f S(f) / (κ U₁₀²) = 4 χ / (2 + χ²)^(5/6),
     χ = f L / U₁₀, i.e.
         S(f) = 4 κ U₁₀² (L/U₁₀) / (2 + χ²)^(5/6) = 4 κ L U₁₀ / (2 + χ²)^(5/6),
     L = 1800 m, κ ≈ 0.0025 the surface drag coefficient over sea (dimensionless). Dimensions:
     κ [–] · L [m] · U₁₀ [m/s] = m²/s = (m/s)²/Hz — the two written forms are the same thing and
     both are dimensionally right; no extra U₁₀ factor is missing. Height independent (it
     describes the gust at the 10 m reference). Variance (closed form, Beta function):
         σ² = 4 κ U₁₀² ∫₀^∞ (2 + χ²)^(−5/6) dχ = 4 κ U₁₀² · 2^(−1/3) · ½ B(½, ⅓) ≈ 6.68 κ U₁₀².
   * Davenport (1961, "The spectrum of horizontal gustiness near the ground in high winds",
     Q. J. R. Meteorol. Soc. 87:194–211): f S(f)/(κ U₁₀²) = 4 χ² / (1 + χ²)^(4/3), L = 1200 m,
     σ² = 6 κ U₁₀² (Davenport's own result).

3. Gust synthesis: u'(t) = Σ_k a_k cos(ω_k t + ε_k), a_k = √(2 S(f_k) Δf_k) (Shinozuka & Jan 1972,
   "Digital simulation of random processes and its applications", J. Sound Vib. 25:111–128).
   The band [f_min, f_max] is cut into n log-spaced bins; f_k is drawn uniformly inside bin k and
   ε_k uniformly in [0, 2π), both from the caller's ``numpy.random.Generator`` (seeded →
   reproducible). Random frequencies avoid the periodicity and non-ergodicity of an equal grid
   (docs/environment.md, Waves); and E[S(f_k)] Δf_k = ∫_bin S df, so the variance of a realization,
   Σ a_k²/2, is an unbiased estimate of ∫_{f_min}^{f_max} S df. Energy below f_min (periods longer
   than ~1 h by default) belongs to the 1-hour mean and is not synthesized.
   The gust is a function of time only: spatial coherence over the ship and lateral/vertical gust
   components are ignored; the gust adds to the mean speed along the mean direction.

4. Wind loads — Isherwood (1973), "Wind resistance of merchant ships", Trans. RINA 115:327–338
   (read 1972). Regression at 10° steps of the wind angle ε ∈ [0°, 180°] off the bow:
       C_X,I = A0 + A1·2A_L/L² + A2·2A_F/B² + A3·L/B + A4·S/L + A5·C/L + A6·M
       C_Y,I = B0 + B1·2A_L/L² + B2·2A_F/B² + B3·L/B + B4·S/L + B5·C/L + B6·A_SS/A_L
       C_N,I = C0 + C1·2A_L/L² + C2·2A_F/B² + C3·L/B + C4·S/L + C5·C/L
   with L = L_oa, B beam, A_F frontal and A_L lateral projected areas above the waterline, A_SS
   lateral area of the superstructure, S the perimeter of the lateral projection (excluding the
   waterline and slender bodies such as masts and ventilators), C the distance of the centroid of
   A_L from the bow, M the number of distinct groups of masts or king posts seen in lateral
   projection. Forces X = q A_F C_X, Y = q A_L C_Y, N = q A_L L_oa C_N, q = ½ ρ_a V_r².
   Between the tabulated angles the coefficients are interpolated linearly (the regression is
   only published at 10° steps; this is our choice, as in Fossen 2011, §8.1).

   Sign mapping. Isherwood's own coefficients are magnitudes-with-sense for ε ∈ [0°, 180°]:
   C_X,I > 0 is a force pointing aft (head wind: C_X,I ≈ +0.5…1.1 for any plausible ship, the
   drag of a bluff body), C_Y,I > 0 a side force towards leeward, C_N,I > 0 a yaw moment turning
   the bow to leeward (evidence from the table itself: at 90°, C_N,I = 0.2627 − 0.508 C/L is
   positive exactly when the area centroid lies forward of ≈ 0.52 L_oa, i.e. when the side force
   acts forward of mid-length and pushes the bow downwind). Our axes: x forward, y starboard, z
   down, N > 0 turns the bow to starboard; γ_r = the angle the apparent wind comes FROM, off the
   bow, positive to starboard, in (−π, π]. Wind from starboard (γ_r > 0) has leeward = port
   (−y) and "bow to leeward" = N < 0. Hence
       C_X(γ_r) = −C_X,I(|γ_r|),   C_Y(γ_r) = −sgn(γ_r) C_Y,I(|γ_r|),   C_N(γ_r) = −sgn(γ_r) C_N,I(|γ_r|).
   Head wind: X < 0; stern wind: X > 0; beam wind from starboard: Y < 0 (pushed to port).

   Moment reference: the regression's yaw moment is about mid-length of L_oa (the 90° row above
   balances at C/L ≈ 0.52); ``x_ref`` is that point's x in our axes (0 if midship and mid-L_oa
   coincide), N at our origin = N_ref + x_ref·Y.

   Heel and pitch (assumptions — Isherwood gives no roll or pitch moment): the side force acts at
   the height h_L of the centroid of A_L above the waterline, times an optional lever factor κ_K
   (default 1): K = κ_K h_L Y (K = −z F_y with z = −h_L). This is Blendermann's form
   C_K = κ (s_H/H_M) C_Y with K = q A_L H_M C_K, H_M = A_L/L_oa (Blendermann 1994, "Parameter
   identification of wind loads on ships", J. Wind Eng. Ind. Aerodyn. 51:339–351, whose measured
   κ ranges from about 1.1 to 3.1 by ship type, being larger than 1 because of the wind's vertical
   profile). Beam wind from starboard: Y < 0 → K < 0, heel to port. The longitudinal force acts at
   the height h_F of the centroid of A_F: M = −h_F X (head wind: bow up). Z = 0.

   Coefficient table: the published numbers of Isherwood's regression tables, as reproduced by
   Fossen (2011, Handbook of Marine Craft Hydrodynamics and Motion Control, Wiley, §8.1; and the
   MSS toolbox's ``isherwood72.m``). One other public transcription differs at a few entries
   (C_X 40°: A0 2.323; C_X 50°: A4 0.343; C_Y 40°: B5 −0.55; C_Y 50°: B5 −0.69; C_Y 60°:
   B4 −0.127; C_N 130°: C0 +0.0189, C4 0.0728); the values here give smooth coefficient curves
   where those give a kink (C_Y near 50°). Check against the original paper when it is at hand.
   The regression was fitted to 1960s-era merchant ship models; for modern container ships and
   car carriers it extrapolates.

5. Kernel. ``wind_kernel(p, s, env, ctx, aux, w)`` follows the force-component interface of
   :mod:`vtrials.physics.forces.context`. The wind description lives in the environment block at the
   ``E_WIND_*`` indices (16…20) and the gust components from ``E_GUST`` (64) on; the ship's
   windage in ``p`` (:func:`pack_wind`). True wind velocity (world, north-east-down) =
   −U(t)·(cos β_w, sin β_w, 0), β_w the direction it blows FROM; U(t) = U₁₀ (z_ref/10)^α + u'(t)
   at the reference height z_ref of the loads, the gust u'(t) read from ``ctx`` (the step kernel
   puts it there, :func:`gust_step`); it is rotated into body axes with ctx's rotation
   matrix and the ship's velocity over ground is subtracted (apparent wind = true wind − ship
   velocity, both vectors). Only the components in the body x–y plane are used (heel and trim
   are taken not to change the coefficients); the wind is taken at the origin (the ship's yaw rate
   does not change it along the hull).

Air density default: 1.225 kg/m³, ISO 2533:1975 standard atmosphere at sea level (15 °C).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numba as nb
import numpy as np
from scipy.special import beta as _beta

from vtrials.physics.forces.registry import register
from vtrials.physics.forces import context as L
from vtrials.schema import integer, num, text
from vtrials.units import DEG, KNOT


RHO_AIR = 1.225  # [kg/m³] ISO 2533:1975 standard atmosphere, sea level, 15 °C
TRIALS_PROFILE_EXPONENT = 1.0 / 9.0  # mean wind profile exponent, ITTC 7.5-04-01-01.1 (2017) and ISO 15016:2015
ISO15016_EXPONENT = TRIALS_PROFILE_EXPONENT  # former name
Z_REF_10 = 10.0  # [m] reference height of U₁₀

NPD_N = 0.468  # ISO 19901-1:2015 / DNV-RP-C205 NPD spectrum exponent
KAPPA_SEA = 0.0025  # surface drag coefficient over sea (docs/environment.md; Harris 1971, Davenport 1961)
HARRIS_L = 1800.0  # [m] Harris (1971) length scale
DAVENPORT_L = 1200.0  # [m] Davenport (1961) length scale

# --- environment block (per ship), after the current's 0..15 (see vtrials.physics.environment.current) ------------------
E_WIND_U10 = 16  # mean wind speed at 10 m [m/s]
E_WIND_DIR = 17  # direction the wind blows FROM [rad], north = 0, clockwise
E_WIND_ALPHA = 18  # power-law exponent of the mean profile [–]
E_WIND_ZREF = 19  # reference height of the ship's wind loads (and of the gusts) [m]
E_WIND_NG = 20  # number of gust components n_g (stored as a float)
E_GUST = 64  # gust components, blocked: amplitudes [m/s] at E_GUST + k, angular frequencies [rad/s] at
#              E_GUST + n_g + k, phases [rad] at E_GUST + 2 n_g + k, k = 0..n_g−1 (block length 64 + 3 n_g)

# --- context slots written by the kernel (inside layout.WIND, 33..39) --------------------------
C_WIND_REL_SPEED = L.WIND + 0  # 33: apparent wind speed V_r [m/s]
C_WIND_REL_ANGLE = L.WIND + 1  # 34: angle the apparent wind comes FROM, off the bow, + to starboard [rad]
C_WIND_TRUE_SPEED = L.WIND + 2  # 35: true wind speed at z_ref, gust included [m/s]
C_WIND_TRUE_DIR = L.WIND + 3  # 36: direction the true wind blows FROM [rad], north = 0, clockwise
C_WIND_GUST = L.WIND + 4  # 37: gust u'(t) at z_ref [m/s], written by the step kernel before the components
#                           (:func:`gust_step`); the wind kernel reads it

# --- gust phasor state (per ship, kept by the simulator between steps; see gust_step) ------------
G_T, G_DT, G_COUNT = 0, 1, 2  # time of the phasors, step of the rotation, rotations since the exact sum
G_PHASORS = 3  # then cos, sin of the phases, cos, sin of the per-step rotation: 4 blocks of n_g
GUST_RESYNC = 200  # rotations between exact evaluations (bounds the rounding drift, see gust_step)

# --- parameter block of the kernel (pack_wind) -----------------------------------------------
P_RHO, P_AF, P_AL, P_LOA, P_HL, P_HF, P_XREF, P_KHEEL = range(8)
P_NODES = 16  # Isherwood coefficients at the 19 tabulated angles, Isherwood's sign: C_X,I, C_Y,I, C_N,I
N_ANGLES = 19
P_CX = P_NODES
P_CY = P_NODES + N_ANGLES
P_CN = P_NODES + 2 * N_ANGLES
NP = P_NODES + 3 * N_ANGLES


def env_width(n_gusts: int) -> int:
    """Length of an environment block holding ``n_gusts`` gust components."""
    return E_GUST + 3 * int(n_gusts)


# =================================================================================================
# 1. Mean wind profile
# =================================================================================================

def mean_wind_at_height(U10, z, exponent: float = TRIALS_PROFILE_EXPONENT):
    """Mean wind speed at height z [m] from U₁₀ [m/s]: U₁₀ (z/10)^exponent (ITTC 2017 / ISO 15016:2015: 1/9)."""
    z = np.asarray(z, dtype=float)
    if np.any(z <= 0.0):
        raise ValueError("height z must be > 0 m")
    out = np.asarray(U10, dtype=float) * (z / Z_REF_10) ** exponent
    return float(out) if out.ndim == 0 else out


# =================================================================================================
# 2. Gust spectra (one-sided, (m/s)²/Hz, f in Hz)
# =================================================================================================

def npd_spectrum(f, U0: float, z: float = Z_REF_10):
    """NPD (Frøya) gust spectrum S(f) [(m/s)²/Hz], ISO 19901-1:2015 / DNV-RP-C205.

    ``U0`` is the 1-hour mean wind speed at 10 m [m/s], ``z`` the height [m]; see the module
    docstring for the units of the constants 320 (m²/s) and 172 (s).
    """
    f = np.asarray(f, dtype=float)
    ft = 172.0 * f * (z / 10.0) ** (2.0 / 3.0) * (U0 / 10.0) ** -0.75
    return 320.0 * (U0 / 10.0) ** 2 * (z / 10.0) ** 0.45 / (1.0 + ft ** NPD_N) ** (5.0 / (3.0 * NPD_N))


def harris_spectrum(f, U10: float, kappa: float = KAPPA_SEA, length: float = HARRIS_L):
    """Harris (1971) gust spectrum S(f) = 4κ L U₁₀ / (2 + χ²)^(5/6), χ = f L/U₁₀ [(m/s)²/Hz]."""
    f = np.asarray(f, dtype=float)
    chi = f * length / U10
    return 4.0 * kappa * length * U10 / (2.0 + chi * chi) ** (5.0 / 6.0)


def davenport_spectrum(f, U10: float, kappa: float = KAPPA_SEA, length: float = DAVENPORT_L):
    """Davenport (1961) gust spectrum S(f) = 4κ U₁₀² χ² / (f (1 + χ²)^(4/3)), χ = f L/U₁₀.

    Written as 4κ L U₁₀ χ / (1 + χ²)^(4/3), finite (zero) at f = 0.
    """
    f = np.asarray(f, dtype=float)
    chi = f * length / U10
    return 4.0 * kappa * length * U10 * chi / (1.0 + chi * chi) ** (4.0 / 3.0)


SPECTRA = {"npd": npd_spectrum, "harris": harris_spectrum, "davenport": davenport_spectrum}


def spectrum_function(spectrum: str | Callable, U10: float, z: float = Z_REF_10,
                      **kwargs) -> Callable[[np.ndarray], np.ndarray]:
    """S as a function of f only. ``spectrum``: "npd", "harris", "davenport", or a callable
    ``spectrum(f, U10, z)`` returning (m/s)²/Hz. ``kwargs`` go to Harris/Davenport (kappa, length)."""
    if callable(spectrum):
        return lambda f: np.asarray(spectrum(np.asarray(f, dtype=float), U10, z), dtype=float)
    key = str(spectrum).lower()
    if key == "npd":
        if kwargs:
            raise TypeError(f"the NPD spectrum takes no extra parameters, got {sorted(kwargs)}")
        return lambda f: npd_spectrum(f, U10, z)
    if key in ("harris", "davenport"):
        fn = SPECTRA[key]
        return lambda f: fn(f, U10, **kwargs)
    raise ValueError(f"unknown gust spectrum {spectrum!r}; expected one of {sorted(SPECTRA)} or a callable")


def spectrum_variance(spectrum: str, U10: float, z: float = Z_REF_10, **kwargs) -> float:
    """∫₀^∞ S(f) df [(m/s)²] in closed form (Beta functions), for the named spectra.

    NPD: with S = A/(1 + (b f)ⁿ)^(5/(3n)), ∫ = (A/b)(1/n) B(1/n, 2/(3n)) (substitute x = (bf)ⁿ).
    Harris: 4κU₁₀² · 2^(−1/3) · ½ B(½, ⅓). Davenport: 6κU₁₀².
    """
    key = str(spectrum).lower()
    if key == "npd":
        A = 320.0 * (U10 / 10.0) ** 2 * (z / 10.0) ** 0.45
        b = 172.0 * (z / 10.0) ** (2.0 / 3.0) * (U10 / 10.0) ** -0.75
        n = NPD_N
        return float(A / b / n * _beta(1.0 / n, 2.0 / (3.0 * n)))
    kappa = kwargs.get("kappa", KAPPA_SEA)
    if key == "harris":
        return float(4.0 * kappa * U10 ** 2 * 2.0 ** (-1.0 / 3.0) * 0.5 * _beta(0.5, 1.0 / 3.0))
    if key == "davenport":
        return float(6.0 * kappa * U10 ** 2)
    raise ValueError(f"no closed-form variance for {spectrum!r}")


# =================================================================================================
# 3. Gust synthesis
# =================================================================================================

def gust_components(spectrum: str | Callable, U10: float, z: float, rng: np.random.Generator,
                    n_components: int = 256, f_min: float = 1.0 / 3600.0, f_max: float = 1.0,
                    **spectrum_kwargs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Amplitudes [m/s], angular frequencies [rad/s] and phases [rad] of a gust realization.

    u'(t) = Σ a_k cos(ω_k t + ε_k), a_k = √(2 S(f_k) Δf_k), with n_components log-spaced bins on
    [f_min, f_max] Hz, f_k uniform inside its bin and ε_k uniform in [0, 2π) — drawn in that order
    from ``rng`` (see the module docstring). ``z`` is the height the gust is wanted at [m] (used by
    the NPD spectrum; Harris and Davenport are height independent).
    """
    if not isinstance(rng, np.random.Generator):
        raise TypeError("rng must be a numpy.random.Generator (seeded for reproducibility)")
    n = int(n_components)
    if n < 1:
        raise ValueError("n_components must be >= 1")
    if not (0.0 < f_min < f_max):
        raise ValueError("need 0 < f_min < f_max [Hz]")
    S = spectrum_function(spectrum, U10, z, **spectrum_kwargs)
    edges = np.geomspace(f_min, f_max, n + 1)
    df = np.diff(edges)
    f = edges[:-1] + rng.random(n) * df
    phase = rng.uniform(0.0, 2.0 * math.pi, n)
    amp = np.sqrt(2.0 * S(f) * df)
    return amp, 2.0 * math.pi * f, phase


@nb.njit(cache=True)
def gust_at(amp, omega, phase, t):
    """Gust u'(t) [m/s] at scalar time t [s]: Σ a_k cos(ω_k t + ε_k). Allocation free."""
    s = 0.0
    for k in range(amp.shape[0]):
        s += amp[k] * math.cos(omega[k] * t + phase[k])
    return s


def gust_series(amp: np.ndarray, omega: np.ndarray, phase: np.ndarray, t, chunk: int = 2_000_000):
    """Vectorized numpy twin of :func:`gust_at` for post-processing: u'(t) for an array of times."""
    t = np.asarray(t, dtype=float)
    flat = t.ravel()
    out = np.empty(flat.shape)
    step = max(1, chunk // max(1, amp.shape[0]))
    for i in range(0, flat.size, step):
        tt = flat[i:i + step]
        out[i:i + step] = np.cos(np.outer(tt, omega) + phase) @ amp
    return out.reshape(t.shape)


# =================================================================================================
# 4. Wind loads: Isherwood (1973) regression
# =================================================================================================

ISHERWOOD_ANGLES_DEG = np.arange(0.0, 181.0, 10.0)

# Isherwood (1973) Trans. RINA 115, regression coefficients; one row per angle 0°, 10°, ..., 180°
# (transcription: Fossen 2011 §8.1 / MSS isherwood72.m; see the module docstring).
#                    A0      A1      A2      A3      A4      A5     A6
ISHERWOOD_A = np.array([
    [2.152, -5.00, 0.243, -0.164, 0.0, 0.0, 0.0],  # 0
    [1.714, -3.33, 0.145, -0.121, 0.0, 0.0, 0.0],  # 10
    [1.818, -3.97, 0.211, -0.143, 0.0, 0.0, 0.033],  # 20
    [1.965, -4.81, 0.243, -0.154, 0.0, 0.0, 0.041],  # 30
    [2.333, -5.99, 0.247, -0.190, 0.0, 0.0, 0.042],  # 40
    [1.726, -6.54, 0.189, -0.173, 0.348, 0.0, 0.048],  # 50
    [0.913, -4.68, 0.0, -0.104, 0.482, 0.0, 0.052],  # 60
    [0.457, -2.88, 0.0, -0.068, 0.346, 0.0, 0.043],  # 70
    [0.341, -0.91, 0.0, -0.031, 0.0, 0.0, 0.032],  # 80
    [0.355, 0.0, 0.0, 0.0, -0.247, 0.0, 0.018],  # 90
    [0.601, 0.0, 0.0, 0.0, -0.372, 0.0, -0.020],  # 100
    [0.651, 1.29, 0.0, 0.0, -0.582, 0.0, -0.031],  # 110
    [0.564, 2.54, 0.0, 0.0, -0.748, 0.0, -0.024],  # 120
    [-0.142, 3.58, 0.0, 0.047, -0.700, 0.0, -0.028],  # 130
    [-0.677, 3.64, 0.0, 0.069, -0.529, 0.0, -0.032],  # 140
    [-0.723, 3.14, 0.0, 0.064, -0.475, 0.0, -0.032],  # 150
    [-2.148, 2.56, 0.0, 0.081, 0.0, 1.27, -0.027],  # 160
    [-2.707, 3.97, -0.175, 0.126, 0.0, 1.81, 0.0],  # 170
    [-2.529, 3.76, -0.174, 0.128, 0.0, 1.55, 0.0],  # 180
])
#                    B0      B1      B2      B3      B4      B5     B6
ISHERWOOD_B = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],  # 0
    [0.096, 0.22, 0.0, 0.0, 0.0, 0.0, 0.0],  # 10
    [0.176, 0.71, 0.0, 0.0, 0.0, 0.0, 0.0],  # 20
    [0.225, 1.38, 0.0, 0.023, 0.0, -0.29, 0.0],  # 30
    [0.329, 1.82, 0.0, 0.043, 0.0, -0.59, 0.0],  # 40
    [1.164, 1.26, 0.121, 0.0, -0.242, -0.95, 0.0],  # 50
    [1.163, 0.96, 0.101, 0.0, -0.177, -0.88, 0.0],  # 60
    [0.916, 0.53, 0.069, 0.0, 0.0, -0.65, 0.0],  # 70
    [0.844, 0.55, 0.082, 0.0, 0.0, -0.54, 0.0],  # 80
    [0.889, 0.0, 0.138, 0.0, 0.0, -0.66, 0.0],  # 90
    [0.799, 0.0, 0.155, 0.0, 0.0, -0.55, 0.0],  # 100
    [0.797, 0.0, 0.151, 0.0, 0.0, -0.55, 0.0],  # 110
    [0.996, 0.0, 0.184, 0.0, -0.212, -0.66, 0.34],  # 120
    [1.014, 0.0, 0.191, 0.0, -0.280, -0.69, 0.44],  # 130
    [0.784, 0.0, 0.166, 0.0, -0.209, -0.53, 0.38],  # 140
    [0.536, 0.0, 0.176, -0.029, -0.163, 0.0, 0.27],  # 150
    [0.251, 0.0, 0.106, -0.022, 0.0, 0.0, 0.0],  # 160
    [0.125, 0.0, 0.046, -0.012, 0.0, 0.0, 0.0],  # 170
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],  # 180
])
#                    C0       C1      C2       C3      C4      C5
ISHERWOOD_C = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],  # 0
    [0.0596, 0.061, 0.0, 0.0, 0.0, -0.074],  # 10
    [0.1106, 0.204, 0.0, 0.0, 0.0, -0.170],  # 20
    [0.2258, 0.245, 0.0, 0.0, 0.0, -0.380],  # 30
    [0.2017, 0.457, 0.0, 0.0067, 0.0, -0.472],  # 40
    [0.1759, 0.573, 0.0, 0.0118, 0.0, -0.523],  # 50
    [0.1925, 0.480, 0.0, 0.0115, 0.0, -0.546],  # 60
    [0.2133, 0.315, 0.0, 0.0081, 0.0, -0.526],  # 70
    [0.1827, 0.254, 0.0, 0.0053, 0.0, -0.443],  # 80
    [0.2627, 0.0, 0.0, 0.0, 0.0, -0.508],  # 90
    [0.2102, 0.0, -0.0195, 0.0, 0.0335, -0.492],  # 100
    [0.1567, 0.0, -0.0258, 0.0, 0.0497, -0.457],  # 110
    [0.0801, 0.0, -0.0311, 0.0, 0.0740, -0.396],  # 120
    [-0.0189, 0.0, -0.0488, 0.0101, 0.1128, -0.420],  # 130
    [0.0256, 0.0, -0.0422, 0.0100, 0.0889, -0.463],  # 140
    [0.0552, 0.0, -0.0381, 0.0109, 0.0689, -0.476],  # 150
    [0.0881, 0.0, -0.0306, 0.0091, 0.0366, -0.415],  # 160
    [0.0851, 0.0, -0.0122, 0.0025, 0.0, -0.220],  # 170
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],  # 180
])


@dataclasses.dataclass(frozen=True)
class Windage:
    """The ship above the waterline, as Isherwood's regression and the heel/pitch levers need it."""

    L_oa: float = num("length overall", "m", 0.0, 1000.0, lo_open=True)
    B: float = num("beam", "m", 0.0, 200.0, lo_open=True)
    A_F: float = num("frontal (transverse) projected area above the waterline", "m^2", 0.0, lo_open=True)
    A_L: float = num("lateral projected area above the waterline", "m^2", 0.0, lo_open=True)
    A_SS: float = num("lateral projected area of the superstructure", "m^2", 0.0)
    S: float = num("perimeter of the lateral projection, without waterline and slender bodies", "m",
                   0.0, lo_open=True)
    C: float = num("distance of the centroid of the lateral area from the bow", "m", 0.0)
    M: int = integer("number of distinct groups of masts or king posts in lateral projection", 0, 20)
    h_L: float = num("height of the centroid of the lateral area above the waterline", "m", 0.0)
    h_F: float = num("height of the centroid of the frontal area above the waterline", "m", 0.0)
    x_ref: float = num("x of mid-L_oa (the regression's yaw reference) from the origin, + forward", "m",
                       default=0.0)
    heel_lever_factor: float = num("κ_K: heel lever = κ_K h_L (Blendermann 1994 measured 1.1–3.1)", "",
                                   0.0, 10.0, default=1.0)

    def regressors(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The regressor vectors multiplying Isherwood's A, B and C rows."""
        aL = 2.0 * self.A_L / self.L_oa ** 2
        aF = 2.0 * self.A_F / self.B ** 2
        common = [1.0, aL, aF, self.L_oa / self.B, self.S / self.L_oa, self.C / self.L_oa]
        return (np.array(common + [float(self.M)]), np.array(common + [self.A_SS / self.A_L]),
                np.array(common))


def isherwood_nodes(params: Windage) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Isherwood's C_X,I, C_Y,I, C_N,I (his signs) at 0°, 10°, ..., 180° for this ship."""
    xa, xb, xc = params.regressors()
    return ISHERWOOD_A @ xa, ISHERWOOD_B @ xb, ISHERWOOD_C @ xc


def wind_coefficients(gamma_r, params: Windage):
    """(C_X, C_Y, C_N, C_K) in our axes for apparent-wind angles ``gamma_r`` [rad] (scalar or array).

    γ_r: angle the wind comes FROM off the bow, positive to starboard (0 head wind, π/2 from
    starboard). X = q A_F C_X, Y = q A_L C_Y, N = q A_L L_oa C_N (about mid-L_oa),
    K = q A_L H_M C_K with H_M = A_L/L_oa, so C_K = κ_K (h_L/H_M) C_Y (module docstring).
    """
    g = np.asarray(gamma_r, dtype=float)
    g = np.arctan2(np.sin(g), np.cos(g))  # wrap to (−π, π]
    a = np.abs(g) / DEG
    sgn = np.where(g >= 0.0, 1.0, -1.0)
    cx_n, cy_n, cn_n = isherwood_nodes(params)
    cx = -np.interp(a, ISHERWOOD_ANGLES_DEG, cx_n)
    cy = -sgn * np.interp(a, ISHERWOOD_ANGLES_DEG, cy_n)
    cn = -sgn * np.interp(a, ISHERWOOD_ANGLES_DEG, cn_n)
    H_M = params.A_L / params.L_oa
    ck = params.heel_lever_factor * params.h_L / H_M * cy
    if np.ndim(gamma_r) == 0:
        return float(cx), float(cy), float(cn), float(ck)
    return cx, cy, cn, ck


def wind_loads(V_r, gamma_r, params: Windage, rho_air: float = RHO_AIR) -> np.ndarray:
    """Body wrench (X, Y, Z, K, M, N) [N, N m] at the origin from apparent wind speed and angle."""
    cx, cy, cn, ck = wind_coefficients(gamma_r, params)
    q = 0.5 * rho_air * np.asarray(V_r, dtype=float) ** 2
    X = q * params.A_F * cx
    Y = q * params.A_L * cy
    H_M = params.A_L / params.L_oa
    K = q * params.A_L * H_M * ck
    Mp = -params.h_F * X
    N = q * params.A_L * params.L_oa * cn + params.x_ref * Y
    return np.array([X, Y, np.zeros_like(X), K, Mp, N])


def apparent_wind(U_true, direction_from, u, v, heading):
    """Apparent wind speed V_r [m/s] and angle γ_r [rad] for an upright ship (horizontal plane).

    True wind of speed U_true blowing FROM ``direction_from`` (north = 0, clockwise); ship velocity
    over ground (u, v) in body axes; heading ψ from north, clockwise. Apparent = true − ship.
    """
    rel = np.asarray(direction_from, dtype=float) - np.asarray(heading, dtype=float)
    wx = -np.asarray(U_true, dtype=float) * np.cos(rel)  # true wind velocity in body axes
    wy = -np.asarray(U_true, dtype=float) * np.sin(rel)
    ax = wx - u
    ay = wy - v
    Vr = np.hypot(ax, ay)
    gam = np.where(Vr > 0.0, np.arctan2(-ay, -ax), 0.0)  # dead calm: 0 by convention
    if np.ndim(Vr) == 0:
        return float(Vr), float(gam)
    return Vr, gam


# =================================================================================================
# 5. Packing and the numba kernel
# =================================================================================================

def pack_wind(params: Windage, rho_air: float = RHO_AIR) -> np.ndarray:
    """Parameter block of :func:`wind_kernel` (float64, length ``NP``).

    0 ρ_air, 1 A_F, 2 A_L, 3 L_oa, 4 h_L, 5 h_F, 6 x_ref, 7 κ_K, 8..15 unused,
    16..34 C_X,I, 35..53 C_Y,I, 54..72 C_N,I at 0°, 10°, ..., 180° (Isherwood's signs).
    """
    if not rho_air > 0.0:
        raise ValueError("air density must be > 0")
    p = np.zeros(NP)
    p[P_RHO] = rho_air
    p[P_AF] = params.A_F
    p[P_AL] = params.A_L
    p[P_LOA] = params.L_oa
    p[P_HL] = params.h_L
    p[P_HF] = params.h_F
    p[P_XREF] = params.x_ref
    p[P_KHEEL] = params.heel_lever_factor
    cx_n, cy_n, cn_n = isherwood_nodes(params)
    p[P_CX:P_CX + N_ANGLES] = cx_n
    p[P_CY:P_CY + N_ANGLES] = cy_n
    p[P_CN:P_CN + N_ANGLES] = cn_n
    return p


def pack_wind_env(base_env: np.ndarray, U10: float, direction_from: float,
                  exponent: float = TRIALS_PROFILE_EXPONENT, z_ref: float = Z_REF_10,
                  gusts: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """A copy of ``base_env`` (e.g. :func:`vtrials.physics.environment.current.pack`) with the wind written in (SI).

    The result is widened to :func:`env_width` (n_g) when the gusts need more room; gust
    components are ``(amp, omega, phase)`` as returned by :func:`gust_components`, generated for
    the height ``z_ref``.
    """
    if U10 < 0.0:
        raise ValueError("U10 must be >= 0")
    if z_ref <= 0.0:
        raise ValueError("z_ref must be > 0 m")
    amp, omega, phase = (np.zeros(0), np.zeros(0), np.zeros(0)) if gusts is None else gusts
    n = int(len(amp))
    if not (len(omega) == n and len(phase) == n):
        raise ValueError("gust amp, omega and phase must have the same length")
    base = np.asarray(base_env, dtype=np.float64)
    env = np.zeros(max(base.shape[0], env_width(n)))
    env[:base.shape[0]] = base
    env[E_WIND_U10] = U10
    env[E_WIND_DIR] = direction_from
    env[E_WIND_ALPHA] = exponent
    env[E_WIND_ZREF] = z_ref
    env[E_WIND_NG] = n
    env[E_GUST:E_GUST + n] = amp
    env[E_GUST + n:E_GUST + 2 * n] = omega
    env[E_GUST + 2 * n:E_GUST + 3 * n] = phase
    return env


@dataclasses.dataclass(frozen=True)
class Wind:
    """Wind as a scenario states it (knots and degrees at the edge; converted by :func:`pack_env`)."""

    speed_kn: float = num("mean wind speed at 10 m (1-hour mean for NPD)", "kn", 0.0, 150.0, default=0.0)
    direction_deg: float = num("direction the wind blows FROM (from north, clockwise)", "deg",
                               -360.0, 360.0, default=0.0)
    profile_exponent: float = num("power-law exponent of the mean profile (ITTC 2017 and ISO 15016:2015: 1/9)",
                                  "", 0.0, 1.0, default=TRIALS_PROFILE_EXPONENT)
    reference_height_m: float = num("height the ship's wind loads refer to", "m", 0.0, 200.0,
                                    lo_open=True, default=Z_REF_10)
    gust_spectrum: str = text("gust spectrum", ("none", "npd", "harris", "davenport"), default="none")
    gust_components: int = integer("number of gust components", 1, 4096, default=256)
    gust_f_min_hz: float = num("lowest gust frequency", "Hz", 0.0, 10.0, lo_open=True, default=1.0 / 3600.0)
    gust_f_max_hz: float = num("highest gust frequency", "Hz", 0.0, 100.0, lo_open=True, default=1.0)


def pack_env(wind: Wind, base_env: np.ndarray, rng: np.random.Generator | None = None) -> np.ndarray:
    """Environment block with ``wind`` written into ``base_env`` (gusts drawn from ``rng``)."""
    U10 = wind.speed_kn * KNOT
    gusts = None
    if wind.gust_spectrum != "none" and U10 > 0.0:
        if rng is None:
            raise ValueError("a numpy Generator is needed to draw the gusts")
        gusts = gust_components(wind.gust_spectrum, U10, wind.reference_height_m, rng,
                                wind.gust_components, wind.gust_f_min_hz, wind.gust_f_max_hz)
    return pack_wind_env(base_env, U10, wind.direction_deg * DEG, wind.profile_exponent,
                         wind.reference_height_m, gusts)


@nb.njit(cache=True, fastmath=False, inline="always")
def _table_interp(p, start, a_deg):
    """Linear interpolation of the 19 nodes p[start..start+18] at a_deg ∈ [0, 180]."""
    x = a_deg / 10.0
    i = int(x)
    if i > N_ANGLES - 2:
        i = N_ANGLES - 2
    fr = x - i
    return p[start + i] + fr * (p[start + i + 1] - p[start + i])


def gust_state_width(n_gusts: int) -> int:
    """Length of the per-ship phasor state :func:`gust_step` keeps for ``n_gusts`` components."""
    return G_PHASORS + 4 * int(n_gusts)


def max_gusts(env_len: int) -> int:
    """The most gust components an environment block of length ``env_len`` can hold."""
    return max(0, (int(env_len) - E_GUST) // 3)


@nb.njit(cache=True, fastmath=False)
def gust_step(env, g, t, dt):
    """Gust u'(t) = Σ a_k cos(ω_k t + ε_k) [m/s] at the step's time t, by phasor rotation.

    A time-stepping loop asks for the gust at t, t + dt, t + 2dt, ...: each phasor e^{i(ω_k t + ε_k)}
    is turned by e^{iω_k dt} (4 multiplications) instead of a cosine being evaluated afresh (the
    cosines were ~30 % of a twin-screw ship's force kernel at 64 components). The sum is exact (as
    :func:`gust_at`) at the first call, whenever t is not the previous call's t + dt (a new state,
    a changed step, time set back), and every GUST_RESYNC rotations; in between it differs from the
    exact sum at the floating-point time t by rounding only: the rotation steps exactly dt where the
    accumulated time steps fl(t + dt) − t, so the drift is ≲ GUST_RESYNC · ulp(t) · Σ a_k ω_k
    (about 1e-8 m/s a day into a run, 1e-12 m/s in the first minutes). ``g`` is the ship's
    state (length ≥ gust_state_width(n_g)); all zeros means "no phasors yet". A call at the same t
    as the previous one returns the same value."""
    n = int(env[E_WIND_NG])
    if n == 0:
        return 0.0
    c0 = G_PHASORS
    s0 = c0 + n
    cd0 = s0 + n
    sd0 = cd0 + n
    if g[G_DT] == dt and dt > 0.0 and t == g[G_T]:
        pass  # the same instant again: the phasors already hold it
    elif g[G_DT] == dt and dt > 0.0 and t == g[G_T] + dt and g[G_COUNT] < GUST_RESYNC:
        for k in range(n):
            c = g[c0 + k]
            s = g[s0 + k]
            cd = g[cd0 + k]
            sd = g[sd0 + k]
            g[c0 + k] = c * cd - s * sd
            g[s0 + k] = s * cd + c * sd
        g[G_COUNT] += 1.0
    else:
        for k in range(n):
            om = env[E_GUST + n + k]
            ph = om * t + env[E_GUST + 2 * n + k]
            g[c0 + k] = math.cos(ph)
            g[s0 + k] = math.sin(ph)
            g[cd0 + k] = math.cos(om * dt)
            g[sd0 + k] = math.sin(om * dt)
        g[G_DT] = dt
        g[G_COUNT] = 0.0
    g[G_T] = t
    u = 0.0
    for k in range(n):
        u += env[E_GUST + k] * g[c0 + k]
    return u


@nb.njit(cache=True, fastmath=False, inline="always")
def wind_kernel(p, s, env, ctx, aux, w):
    """Wind wrench at the origin, body axes (X, Y, Z, K, M, N); writes ctx[33..36].

    See the module docstring for the apparent wind, the regression and the sign conventions.
    """
    zr = env[E_WIND_ZREF]
    U = env[E_WIND_U10] * (zr / 10.0) ** env[E_WIND_ALPHA] + ctx[C_WIND_GUST]
    bw = env[E_WIND_DIR]
    # true wind velocity, north-east-down (it blows towards bw + π)
    vn = -U * math.cos(bw)
    ve = -U * math.sin(bw)
    # into body axes: v_b = Rᵀ v_world (R body→world, row major)
    wbx = ctx[L.ROT + 0] * vn + ctx[L.ROT + 3] * ve
    wby = ctx[L.ROT + 1] * vn + ctx[L.ROT + 4] * ve
    # apparent wind = true wind − ship velocity over ground
    ax = wbx - ctx[L.NU + 0]
    ay = wby - ctx[L.NU + 1]
    Vr2 = ax * ax + ay * ay
    Vr = math.sqrt(Vr2)
    gam = math.atan2(-ay, -ax) if Vr2 > 0.0 else 0.0  # direction it comes FROM, + to starboard
    a_deg = abs(gam) * (180.0 / math.pi)
    sgn = 1.0 if gam >= 0.0 else -1.0
    cx = -_table_interp(p, P_CX, a_deg)
    cy = -sgn * _table_interp(p, P_CY, a_deg)
    cn = -sgn * _table_interp(p, P_CN, a_deg)
    q = 0.5 * p[P_RHO] * Vr2
    X = q * p[P_AF] * cx
    Y = q * p[P_AL] * cy
    w[0] = X
    w[1] = Y
    w[2] = 0.0
    w[3] = p[P_KHEEL] * p[P_HL] * Y
    w[4] = -p[P_HF] * X
    w[5] = q * p[P_AL] * p[P_LOA] * cn + p[P_XREF] * Y
    ctx[C_WIND_REL_SPEED] = Vr
    ctx[C_WIND_REL_ANGLE] = gam
    ctx[C_WIND_TRUE_SPEED] = U
    ctx[C_WIND_TRUE_DIR] = bw


kernel = wind_kernel  # the name the other force components use


COMPONENT = register("wind", wind_kernel)
