"""The seaway: directional irregular waves by linear (Airy) theory.

Everything is SI inside: ω [rad/s], k [rad/m], lengths [m], angles [rad]. Degrees appear only at
the scenario edge (:class:`Waves`). World axes are north-east-down (x north, y east, z down, z = 0
the mean free surface); the elevation η is positive UP. A component's direction μ is the direction
it PROPAGATES TOWARDS, from north, clockwise; sea-state reports give the direction waves COME FROM,
so μ = direction_from + π (:func:`realize` converts explicitly).

1. Spectra S(ω), one-sided, [m² s/rad], ∫₀^∞ S dω = m0 = H_s²/16 (docs/environment.md):

   * Modified Pierson–Moskowitz, ITTC (1978, 15th ITTC Seakeeping Committee; Lloyd 1989,
     "Seakeeping", §4): S = A ω⁻⁵ exp(−B ω⁻⁴). Its moments are m_n = (A/4) B^((n−4)/4) Γ(1 − n/4),
     so m0 = A/(4B) and A = B H_s²/4 keeps H_s exactly. The period fixes B:
     T_0 = T_p (modal): B = (5/4)(2π/T_0)⁴ ≈ 1948/T_0⁴;
     T_1 = 2π m0/m1:   B = (2π/(Γ(3/4) T_1))⁴ ≈ 691.3/T_1⁴;
     T_z = 2π √(m0/m2): B = (2π)⁴/(π T_z⁴) ≈ 496.1/T_z⁴.
     The ITTC's rounded constants (173/691, 487/1949, 123/495) are these to within 0.7 %
     (A/(4B) = 0.0626, 0.0625, 0.0621 H_s²; tests/test_waves.py) — we use the exact ones so that
     H_s is kept.
   * Bretschneider (1959; form of docs/environment.md): S = (5/16) H_s² ω_p⁴ ω⁻⁵ exp[−1.25 (ω_p/ω)⁴]
     — the same function as ITTC with T_0 = 2π/ω_p.
   * JONSWAP (Hasselmann et al. 1973, Dtsch. Hydrogr. Z. A8(12)): S_J = C(γ) S_PM(ω; H_s, ω_p)
     γ^r, r = exp[−(ω − ω_p)²/(2σ²ω_p²)], σ = σ_a = 0.07 for ω ≤ ω_p, σ_b = 0.09 above. C(γ) is
     computed by quadrature so that ∫S_J = H_s²/16 exactly. The usual closed form C ≈ 1 − 0.287 ln γ
     (DNV-RP-C205 (2010) §3.5.5) holds to 0.35 % for 1 ≤ γ ≤ 5 (m0 within 0.35 %, H_s within
     0.2 %) but is 0.7 % low at γ = 6, 1.8 % at γ = 7 and 6.9 % at γ = 10 (measured here:
     :func:`jonswap_normalisation` vs the closed form, tests/test_waves.py).
   * Sea + swell: the sum of two spectra (one per wave system), H_s,total = √(H_s1² + H_s2²); the
     Ochi–Hubble (1976) six-parameter form is not provided (a sum of two named spectra covers it).

   Finite depth keeps the deep-water spectrum in ω (no TMA transformation) and uses the finite-depth
   dispersion relation and kinematics.

2. Directional spreading D(μ − μ₀), ∫ D dμ = 1 over one turn:
   * cos-2s (Longuet-Higgins, Cartwright & Smith 1963): D = D₀ cos^{2s}((μ − μ₀)/2),
     D₀ = 2^{2s−1} Γ²(s+1)/(π Γ(2s+1)); first circular moment r₁ = s/(s+1), second s(s−1)/((s+1)(s+2)).
   * cos² over ±90° (ITTC; Lloyd 1989): D = (2/π) cos²(μ − μ₀), r₁ = 8/(3π).
   * Mitsuyasu (Mitsuyasu et al. 1975, J. Phys. Oceanogr. 5:750–760), in Goda's (1985, "Random
     seas and design of maritime structures", §2.3) form: cos-2s with s = s_max (ω/ω_p)⁵ for
     ω ≤ ω_p and s_max (ω/ω_p)^−2.5 above; Goda recommends s_max = 10 for wind waves, 25 for swell
     with a short decay distance, 75 for swell with a long one.
   * none: long-crested, every component along μ₀.

3. Dispersion ω² = g k tanh(kh): Newton on x tanh x = ω²h/g (vectorised) from Fenton & McKee's
   (1990, Coastal Eng. 14:499–513) explicit start; deep water (h = ∞ or ω²h/g > 20, where tanh
   differs from 1 by < 1e−17) returns k = ω²/g exactly.

4. Realization by single summation (Shinozuka & Jan 1972, J. Sound Vib. 25:111–128, with
   randomised frequencies):
       η(x, y, t) = Σ_j a_j cos(ω_j t − k_j (x cos μ_j + y sin μ_j) + ε_j).
   Each wave system gets n components. The band [f_lo ω_p, f_hi ω_p] is cut into n bins of EQUAL
   ENERGY (each holds m0_band/n); component j's frequency is drawn inside bin j with density
   ∝ S (stratified sampling of the spectrum as a probability density: the quantile is (j + U_j)/n)
   and its amplitude is a_j = √(2 ∫_bin S dω) = √(2 m0_band/n) — the √(2 S Δω) of the docs with
   S Δω read as the bin's energy. Why equal energy, not equal width: (i) the realized variance is
   exactly m0_band (no random energy per component); (ii) the spurious correlation of η at long
   lags, Σ a_j² cos(ω_j τ)/Σ a_j², has variance Σw_j²/2 with w_j = a_j²/Σa², smallest (1/(2n))
   when all a_j are equal, so for a given n it is the least periodic choice; (iii) frequency
   resolution goes where the energy is. The price is coarse resolution of the high-frequency tail
   (its bins are wide), acceptable for ship motions that the hull filters there.
   Each component's direction is drawn from D(·; ω_j) at its own frequency (Mitsuyasu: s(ω_j)) by
   inverting D's cumulative distribution at the quantile (π(j) + V_j)/n, π a random permutation
   (Latin-hypercube stratification across components: the set of directions follows D closely
   while each component keeps one direction, so there is no double sum). Phases ε_j are uniform in
   [0, 2π). Draw order from the caller's Generator, per system (sea first, then swell): U (n),
   π (permutation of n), V (n), ε (n).
   No two components share a frequency (almost surely), so η at a point has no repeat period; a
   fixed-grid double sum repeats after 2π/Δω (docs/environment.md, seed 001).

5. Kinematics of one component (Airy; e.g. Dean & Dalrymple 1991, "Water wave mechanics for
   engineers and scientists", ch. 4), θ = ω t − k(x cos μ + y sin μ) + ε, z down from the mean
   surface, h the depth:
       η = a cos θ
       horizontal velocity along μ:  u = a ω F_c cos θ,   F_c = cosh k(h − z)/sinh kh
       vertical velocity (down):     w = a ω F_s sin θ,   F_s = sinh k(h − z)/sinh kh
       accelerations ∂/∂t (linear):  −a ω² F_c sin θ along μ,  a ω² F_s cos θ down.
   Written as F_c = e^{−kz} (1 + e^{−2k(h−z)})/(1 − e^{−2kh}) and F_s = e^{−kz}(1 − e^{−2k(h−z)})/
   (1 − e^{−2kh}), which never overflow and reduce exactly to e^{−kz} in deep water (h = ∞).
   Points above the mean surface (z < 0) get the surface values (constant extension); points
   below the bottom are not allowed (the array wrappers raise).

Components are packed as a float64 array (n, 6): [a, ω, k, cos μ, sin μ, ε] (COLUMNS below); the
numba kernels :func:`elevation_at` and :func:`kinematics_at` evaluate one point, allocation free;
:func:`elevation` and :func:`kinematics` do broadcast arrays of points/times in compiled chunks
(numpy.nditer buffers of CHUNK points), with no (points × components) temporaries.

The ``wavespectra`` library (PyPI, 4.9) was considered and not used: it requires xarray, dask,
click, pyyaml, sortedcontainers and matplotlib at install (xarray is only a test extra here), its
spectra are xarray objects in Hz with directions in degrees, and it has no realization or
kinematics; the four spectrum formulas it would replace are a few lines each here.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numba as nb
import numpy as np
from scipy.integrate import quad
from scipy.special import gamma as _gamma
from scipy.special import gammaln

from vtrials.errors import InputError
from vtrials.schema import integer, num, text
from vtrials.units import DEG, G

TWO_PI = 2.0 * math.pi
COLUMNS = ("amplitude", "omega", "k", "cos_mu", "sin_mu", "phase")
NCOL = 6
SPECTRA = ("jonswap", "pierson_moskowitz", "bretschneider")
SPREADINGS = ("cos2s", "cos2", "mitsuyasu", "none")
JONSWAP_SIGMA_A = 0.07  # Hasselmann et al. 1973, below the peak
JONSWAP_SIGMA_B = 0.09  # above the peak
GODA_S_MAX_WIND_SEA = 10.0  # Goda 1985 §2.3: wind waves
GODA_S_MAX_SWELL = 25.0  # Goda 1985 §2.3: swell with a short decay distance
_DEEP_X = 20.0  # ω²h/g above which tanh(kh) == 1 in float64
_N_DIR_GRID = 4097  # nodes of the tabulated spreading CDF over one turn


# =================================================================================================
# 1. Spectra
# =================================================================================================

def ittc_B(t1: float | None = None, t0: float | None = None, tz: float | None = None) -> float:
    """B [rad⁴/s⁴] of the ITTC spectrum A ω⁻⁵ exp(−B ω⁻⁴) from exactly one period [s] (module doc)."""
    given = [(n, v) for n, v in (("t1", t1), ("t0", t0), ("tz", tz)) if v is not None]
    if len(given) != 1:
        raise ValueError(f"give exactly one of t1, t0, tz (got {[n for n, _ in given] or 'none'})")
    name, T = given[0]
    if not T > 0.0:
        raise ValueError(f"period {name} must be > 0 s, got {T!r}")
    if name == "t0":
        return 1.25 * (TWO_PI / T) ** 4
    if name == "t1":
        return (TWO_PI / (_gamma(0.75) * T)) ** 4
    return TWO_PI ** 4 / (math.pi * T ** 4)


def ittc_spectrum(omega, hs: float, t1: float | None = None, t0: float | None = None,
                  tz: float | None = None):
    """Modified Pierson–Moskowitz (ITTC 1978) S(ω) [m² s/rad] from H_s [m] and one of T_1, T_0, T_z [s].

    S = A ω⁻⁵ exp(−B ω⁻⁴), A = B H_s²/4 (exact m0 = H_s²/16), B from :func:`ittc_B`.
    """
    B = ittc_B(t1=t1, t0=t0, tz=tz)
    A = B * hs * hs / 4.0
    w = np.asarray(omega, dtype=float)
    out = np.zeros_like(w)
    pos = w > 0.0
    wp = w[pos]
    out[pos] = A * wp ** -5 * np.exp(-B * wp ** -4)
    return out


def bretschneider_spectrum(omega, hs: float, omega_p: float):
    """Bretschneider S(ω) = (5/16) H_s² ω_p⁴ ω⁻⁵ exp[−1.25 (ω_p/ω)⁴] [m² s/rad] (docs/environment.md)."""
    w = np.asarray(omega, dtype=float)
    out = np.zeros_like(w)
    pos = w > 0.0
    x = w[pos] / omega_p
    out[pos] = 0.3125 * hs * hs / omega_p * x ** -5 * np.exp(-1.25 * x ** -4)
    return out


def _peak_enhancement(x, gamma: float, sigma_a: float, sigma_b: float):
    sig = np.where(x <= 1.0, sigma_a, sigma_b)
    return gamma ** np.exp(-((x - 1.0) ** 2) / (2.0 * sig * sig))


@functools.lru_cache(maxsize=64)
def jonswap_normalisation(gamma: float, sigma_a: float = JONSWAP_SIGMA_A,
                          sigma_b: float = JONSWAP_SIGMA_B) -> float:
    """C(γ) such that C S_PM γ^r integrates to H_s²/16 (quadrature in x = ω/ω_p).

    With S_PM dω = (H_s²/16) 5 x⁻⁵ exp(−1.25 x⁻⁴) dx, C = 1/∫ 5 x⁻⁵ e^{−1.25 x⁻⁴} γ^r(x) dx.
    """
    if not gamma >= 1.0:
        raise ValueError(f"JONSWAP gamma must be >= 1, got {gamma!r}")

    def f(x):
        return 5.0 * x ** -5 * math.exp(-1.25 * x ** -4) * float(_peak_enhancement(x, gamma, sigma_a, sigma_b))

    total = 0.0
    for lo, hi in ((0.1, 0.7), (0.7, 1.0), (1.0, 1.4), (1.4, 4.0), (4.0, math.inf)):
        total += quad(f, lo, hi, limit=200, epsabs=0.0, epsrel=1e-12)[0]
    return 1.0 / total


def jonswap_normalisation_approx(gamma: float) -> float:
    """The closed form C ≈ 1 − 0.287 ln γ (DNV-RP-C205 §3.5.5), for comparison only."""
    return 1.0 - 0.287 * math.log(gamma)


def jonswap_spectrum(omega, hs: float, omega_p: float, gamma: float = 3.3,
                     sigma_a: float = JONSWAP_SIGMA_A, sigma_b: float = JONSWAP_SIGMA_B):
    """JONSWAP S(ω) [m² s/rad] (Hasselmann et al. 1973), normalised to keep H_s (module doc)."""
    w = np.asarray(omega, dtype=float)
    out = np.zeros_like(w)
    pos = w > 0.0
    x = w[pos] / omega_p
    c = jonswap_normalisation(float(gamma), float(sigma_a), float(sigma_b))
    out[pos] = (c * 0.3125 * hs * hs / omega_p * x ** -5 * np.exp(-1.25 * x ** -4)
                * _peak_enhancement(x, gamma, sigma_a, sigma_b))
    return out


@functools.lru_cache(maxsize=64)
def shape_moments(kind: str, gamma: float = 1.0) -> tuple[float, float, float]:
    """(m0, m1, m2) of the spectrum shape with H_s = 4 m and ω_p = 1 rad/s (quadrature).

    Used to turn T_1 or T_z into T_p for any kind: T_1 = 2π m0/(m1 ω_p), T_z = 2π √(m0/m2)/ω_p.
    """
    g = gamma if kind == "jonswap" else 1.0

    def s(x):
        return float(jonswap_spectrum(np.array([x]), 4.0, 1.0, g)[0])

    pieces = ((0.1, 0.7), (0.7, 1.0), (1.0, 1.4), (1.4, 4.0), (4.0, math.inf))
    m = [sum(quad(lambda x, n=n: s(x) * x ** n, lo, hi, limit=200, epsabs=0.0, epsrel=1e-11)[0]
             for lo, hi in pieces) for n in (0, 1, 2)]
    return m[0], m[1], m[2]


def peak_frequency(kind: str, gamma: float = 1.0, tp: float | None = None, tz: float | None = None,
                   t1: float | None = None) -> float:
    """ω_p [rad/s] of a spectrum kind from exactly one of T_p, T_z, T_1 [s]."""
    given = [(n, v) for n, v in (("tp", tp), ("tz", tz), ("t1", t1)) if v is not None]
    if len(given) != 1:
        raise ValueError(f"give exactly one of tp, tz, t1 (got {[n for n, _ in given] or 'none'})")
    name, T = given[0]
    if name == "tp":
        return TWO_PI / T
    m0, m1, m2 = shape_moments(kind, gamma)
    if name == "t1":
        return TWO_PI * m0 / (m1 * T)
    return TWO_PI * math.sqrt(m0 / m2) / T


def spectrum(kind: str, omega, hs: float, omega_p: float, gamma: float = 3.3):
    """S(ω) [m² s/rad] of a named kind ("jonswap", "pierson_moskowitz", "bretschneider")."""
    if kind == "jonswap":
        return jonswap_spectrum(omega, hs, omega_p, gamma)
    if kind in ("pierson_moskowitz", "bretschneider"):
        return bretschneider_spectrum(omega, hs, omega_p)
    raise ValueError(f"unknown spectrum kind {kind!r}; expected one of {SPECTRA}")


# =================================================================================================
# 2. Directional spreading
# =================================================================================================

def cos2s_norm(s):
    """D₀(s) = 2^{2s−1} Γ²(s+1)/(π Γ(2s+1)) (log-gamma form, no overflow for large s)."""
    s = np.asarray(s, dtype=float)
    return np.exp((2.0 * s - 1.0) * math.log(2.0) + 2.0 * gammaln(s + 1.0) - gammaln(2.0 * s + 1.0)) / math.pi


def mitsuyasu_s(omega, omega_p: float, s_max: float):
    """Goda's (1985) form of Mitsuyasu's s(ω): s_max (ω/ω_p)⁵ below ω_p, s_max (ω/ω_p)^−2.5 above."""
    x = np.asarray(omega, dtype=float) / omega_p
    return np.where(x <= 1.0, s_max * x ** 5, s_max * x ** -2.5)


def spreading_function(kind: str, dmu, s=1.0):
    """D [1/rad] at angles dmu = μ − μ₀ [rad] (any range; wrapped). ``s``: cos-2s exponent (array ok).

    "mitsuyasu" takes the frequency-dependent s already evaluated (:func:`mitsuyasu_s`); "none"
    is a delta function and has no density (raises).
    """
    d = np.angle(np.exp(1j * np.asarray(dmu, dtype=float)))  # wrap to (−π, π]
    if kind in ("cos2s", "mitsuyasu"):
        s = np.asarray(s, dtype=float)
        return cos2s_norm(s) * np.abs(np.cos(0.5 * d)) ** (2.0 * s)
    if kind == "cos2":
        return np.where(np.abs(d) <= 0.5 * math.pi, (2.0 / math.pi) * np.cos(d) ** 2, 0.0)
    if kind == "none":
        raise ValueError("long-crested seas ('none') have no spreading density")
    raise ValueError(f"unknown spreading {kind!r}; expected one of {SPREADINGS}")


def spreading_moments(kind: str, s=1.0) -> tuple[np.ndarray, np.ndarray]:
    """Circular moments (r₁, r₂) = (∫D cos Δμ, ∫D cos 2Δμ) in closed form.

    cos-2s: s/(s+1), s(s−1)/((s+1)(s+2)) (Longuet-Higgins et al. 1963); cos²: 8/(3π), 1/2; none: 1, 1.
    """
    if kind in ("cos2s", "mitsuyasu"):
        s = np.asarray(s, dtype=float)
        return s / (s + 1.0), s * (s - 1.0) / ((s + 1.0) * (s + 2.0))
    if kind == "cos2":
        return np.asarray(8.0 / (3.0 * math.pi)), np.asarray(0.5)
    if kind == "none":
        return np.asarray(1.0), np.asarray(1.0)
    raise ValueError(f"unknown spreading {kind!r}; expected one of {SPREADINGS}")


def circular_spread(r1):
    """Circular spread σ₁ = √(2(1 − r₁)) [rad] (Kuik, van Vledder & Holthuijsen 1988); cos-2s: √(2/(s+1))."""
    return np.sqrt(2.0 * (1.0 - np.asarray(r1, dtype=float)))


def _sample_spreading(kind: str, s: np.ndarray, q: np.ndarray, rows: int = 256) -> np.ndarray:
    """Angles Δμ [rad] with density D(Δμ; s_j) at quantiles q_j ∈ (0, 1).

    Inverts the CDF tabulated on _N_DIR_GRID nodes over (−π, π] (trapezoid rule, linear
    interpolation between nodes), ``rows`` components at a time (bounded memory).
    """
    if kind == "none":
        return np.zeros_like(q)
    grid = np.linspace(-math.pi, math.pi, _N_DIR_GRID)
    h = grid[1] - grid[0]
    s = np.broadcast_to(np.asarray(s, dtype=float), q.shape)
    out = np.empty_like(q)
    for i in range(0, q.size, rows):
        sl = slice(i, i + rows)
        qq = q[sl]
        pdf = np.broadcast_to(spreading_function(kind, grid[None, :], s[sl, None]), (qq.size, grid.size))
        cdf = np.zeros(pdf.shape)
        np.cumsum(0.5 * h * (pdf[:, 1:] + pdf[:, :-1]), axis=1, out=cdf[:, 1:])
        cdf /= cdf[:, -1:]
        j = np.clip(np.sum(cdf < qq[:, None], axis=1), 1, grid.size - 1)  # cdf[j−1] < q ≤ cdf[j]
        r = np.arange(qq.size)
        c0, c1 = cdf[r, j - 1], cdf[r, j]
        frac = np.where(c1 > c0, (qq - c0) / np.where(c1 > c0, c1 - c0, 1.0), 0.5)
        out[sl] = grid[j - 1] + frac * h
    return out


# =================================================================================================
# 3. Dispersion
# =================================================================================================

def wavenumber(omega, depth: float = math.inf):
    """k [rad/m] solving ω² = g k tanh(k h) for ω [rad/s] (array) and depth h [m] (math.inf: deep).

    Newton on f(x) = x tanh x − y, x = kh, y = ω²h/g, started from Fenton & McKee (1990)
    x₀ = y coth(y^¾)^⅔; converged to 1e−14 relative (a few steps). Deep water is exact: k = ω²/g.
    """
    w = np.asarray(omega, dtype=float)
    if not depth > 0.0:
        raise ValueError(f"depth must be > 0 m, got {depth!r}")
    k0 = w * w / G
    if math.isinf(depth):
        return k0
    y = k0 * depth
    out = k0.copy()
    shallow = (y < _DEEP_X) & (y > 0.0)
    if np.any(shallow):
        yy = y[shallow]
        x = yy / np.tanh(yy ** 0.75) ** (2.0 / 3.0)
        for _ in range(50):
            t = np.tanh(x)
            f = x * t - yy
            dx = f / (t + x * (1.0 - t * t))
            x = x - dx
            if np.all(np.abs(dx) <= 1e-14 * x):
                break
        out[shallow] = x / depth
    return out


# =================================================================================================
# 4. Kernels (numba): one point, allocation free; and the array loops
# =================================================================================================

@nb.njit(cache=True)
def elevation_at(comp, x, y, t):
    """η [m] (up) at (x north, y east) [m] and time t [s]: Σ a cos(ω t − k(x cos μ + y sin μ) + ε)."""
    eta = 0.0
    for j in range(comp.shape[0]):
        th = comp[j, 1] * t - comp[j, 2] * (x * comp[j, 3] + y * comp[j, 4]) + comp[j, 5]
        eta += comp[j, 0] * math.cos(th)
    return eta


@nb.njit(cache=True)
def kinematics_at(comp, depth, x, y, z, t):
    """Linear wave kinematics at one point (x north, y east, z down [m]; z < 0 → z = 0) and time t [s].

    Returns (η, u_n, u_e, u_d, a_n, a_e, a_d): elevation [m] (up), orbital velocity [m/s] and its
    partial time derivative [m/s²] in north-east-down axes. ``depth`` [m], math.inf for deep water.
    """
    if z < 0.0:
        z = 0.0
    deep = math.isinf(depth)
    eta = 0.0
    un = 0.0
    ue = 0.0
    ud = 0.0
    an = 0.0
    ae = 0.0
    ad = 0.0
    for j in range(comp.shape[0]):
        a = comp[j, 0]
        w = comp[j, 1]
        k = comp[j, 2]
        c = comp[j, 3]
        s = comp[j, 4]
        th = w * t - k * (x * c + y * s) + comp[j, 5]
        ct = math.cos(th)
        st = math.sin(th)
        # depth factors F_c, F_s in the overflow-free form (module doc, section 5)
        e = math.exp(-k * z)
        if deep or k * (depth - z) > 19.0:  # e^{−2k(h−z)} < 3.2e−17: the finite-depth terms round away
            fc = e
            fs = e
        else:
            q = math.exp(-2.0 * k * (depth - z))
            e = e / -math.expm1(-2.0 * k * depth)
            fc = e * (1.0 + q)
            fs = e * (1.0 - q)
        aw = a * w
        eta += a * ct
        h = aw * fc * ct
        un += h * c
        ue += h * s
        ud += aw * fs * st
        ha = -aw * w * fc * st
        an += ha * c
        ae += ha * s
        ad += aw * w * fs * ct
    return eta, un, ue, ud, an, ae, ad


@nb.njit(cache=True)
def _elevation_many(comp, x, y, t, out):
    for i in range(out.shape[0]):
        out[i] = elevation_at(comp, x[i], y[i], t[i])


@nb.njit(cache=True)
def _kinematics_many(comp, depth, x, y, z, t, o0, o1, o2, o3, o4, o5, o6):
    for i in range(o0.shape[0]):
        r = kinematics_at(comp, depth, x[i], y[i], z[i], t[i])
        o0[i] = r[0]
        o1[i] = r[1]
        o2[i] = r[2]
        o3[i] = r[3]
        o4[i] = r[4]
        o5[i] = r[5]
        o6[i] = r[6]


CHUNK = 65536  # points per compiled call in the array wrappers (bounds the temporaries)


def _check_components(comp) -> np.ndarray:
    comp = np.ascontiguousarray(comp, dtype=np.float64)
    if comp.ndim != 2 or comp.shape[1] != NCOL:
        raise ValueError(f"components must be an (n, {NCOL}) array {COLUMNS}, got shape {comp.shape}")
    return comp


def _chunks(inputs, outputs):
    """Buffered 1-D chunks of broadcast inputs and matching output views (numpy.nditer)."""
    ops = [np.asarray(v, dtype=np.float64) for v in inputs] + list(outputs)
    flags = [["readonly"]] * len(inputs) + [["writeonly"]] * len(outputs)
    it = np.nditer(ops, flags=["external_loop", "buffered", "zerosize_ok"], op_flags=flags,
                   buffersize=CHUNK, order="C")
    with it:
        yield from it


def elevation(comp, x, y, t):
    """η [m] for arrays of x, y [m] and t [s] (broadcast together), evaluated in compiled chunks.

    Memory: the output plus O(CHUNK) buffers — never (points × components) temporaries.
    """
    comp = _check_components(comp)
    shape = np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(t))
    out = np.empty(shape)
    for cx, cy, ct, co in _chunks((x, y, t), (out,)):
        _elevation_many(comp, cx, cy, ct, co)
    return out


def kinematics(comp, depth: float, x, y, z, t):
    """(η, velocity (..., 3), acceleration (..., 3)) for arrays of x, y, z [m] (down) and t [s], broadcast.

    Velocity and acceleration are (north, east, down) [m/s, m/s²]; see :func:`kinematics_at`.
    Evaluated in compiled chunks (memory: the outputs plus O(CHUNK) buffers). Raises ValueError
    for points below the bottom (z > depth).
    """
    comp = _check_components(comp)
    if np.size(z) and float(np.max(z)) > depth:
        raise ValueError(f"points below the bottom: z up to {float(np.max(z)):g} m > depth {depth:g} m")
    shape = np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(z), np.shape(t))
    out = np.empty((7,) + shape)
    for c in _chunks((x, y, z, t), tuple(out)):
        _kinematics_many(comp, float(depth), *c)
    return out[0], np.moveaxis(out[1:4], 0, -1), np.moveaxis(out[4:7], 0, -1)


# =================================================================================================
# 5. Scenario edge and realization
# =================================================================================================

@dataclasses.dataclass(frozen=True)
class Waves:
    """The seaway as a scenario states it (degrees at the edge; directions the waves COME FROM).

    Wind sea: ``spectrum`` with ``hs_m`` and exactly one period (``tp_s``, ``tz_s`` or ``t1_s``;
    Bretschneider takes ``tp_s``). Optional swell (``swell_hs_m`` > 0) is a JONSWAP system with its
    own peak period, direction and spreading. ``hs_m`` = 0 and no swell is a calm sea.
    """

    spectrum: str = text("wind-sea spectrum", SPECTRA, default="jonswap")
    hs_m: float = num("significant wave height of the wind sea H_s = 4√m0", "m", 0.0, 20.0, default=0.0)
    tp_s: float | None = num("peak (modal) period T_p = T_0", "s", 1.0, 30.0, default=None)
    tz_s: float | None = num("zero-upcrossing period T_z = 2π√(m0/m2)", "s", 1.0, 30.0, default=None)
    t1_s: float | None = num("mean period T_1 = 2π m0/m1", "s", 1.0, 30.0, default=None)
    gamma: float = num("JONSWAP peak enhancement γ (Hasselmann et al. 1973 mean: 3.3)", "", 1.0, 10.0,
                       default=3.3)
    direction_deg: float = num("direction the wind sea comes FROM (nautical, from north, clockwise)",
                               "deg", -360.0, 360.0, default=0.0)
    spreading: str = text("directional spreading of the wind sea", SPREADINGS, default="cos2s")
    spreading_s: float = num("cos-2s exponent s (Mitsuyasu: s_max; Goda 1985: 10 for wind sea)", "",
                             0.5, 200.0, default=GODA_S_MAX_WIND_SEA)
    n_components: int = integer("number of wave components of the wind sea", 10, 5000, default=200)
    swell_hs_m: float = num("significant wave height of the swell (0: no swell)", "m", 0.0, 20.0, default=0.0)
    swell_tp_s: float | None = num("peak period of the swell", "s", 1.0, 30.0, default=None)
    swell_gamma: float = num("JONSWAP γ of the swell", "", 1.0, 10.0, default=3.3)
    swell_direction_deg: float = num("direction the swell comes FROM (nautical)", "deg", -360.0, 360.0,
                                     default=0.0)
    swell_spreading: str = text("directional spreading of the swell", SPREADINGS, default="cos2s")
    swell_spreading_s: float = num("cos-2s exponent of the swell (Goda 1985: 25 short, 75 long decay)", "",
                                   0.5, 200.0, default=GODA_S_MAX_SWELL)
    swell_n_components: int = integer("number of wave components of the swell", 10, 5000, default=100)
    band_low: float = num("lowest component frequency as a fraction of each system's ω_p", "", 0.2, 1.0,
                          lo_open=False, hi_open=True, default=0.5)
    band_high: float = num("highest component frequency as a multiple of each system's ω_p", "", 1.0, 20.0,
                           lo_open=True, default=5.0)

    def check(self, file: str = "scenario", section: str = "environment.waves") -> None:
        """Consistency of the fields (ranges are checked by :func:`vtrials.schema.read_table`)."""
        where = f"{section}." if section else ""
        periods = [n for n in ("tp_s", "tz_s", "t1_s") if getattr(self, n) is not None]
        if self.hs_m > 0.0:
            if len(periods) != 1:
                raise InputError(file, f"{where}tp_s", f"give exactly one of tp_s, tz_s, t1_s for a sea with "
                                 f"hs_m = {self.hs_m:g} m (given: {', '.join(periods) or 'none'})")
            if self.spectrum == "bretschneider" and periods[0] != "tp_s":
                raise InputError(file, f"{where}{periods[0]}", "the Bretschneider spectrum is defined by "
                                 "tp_s; give tp_s (or choose pierson_moskowitz/jonswap)")
            if self.spectrum not in SPECTRA:
                raise InputError(file, f"{where}spectrum", f"{self.spectrum!r} is not allowed: expected one "
                                 f"of {', '.join(SPECTRA)}")
            if self.spreading not in SPREADINGS:
                raise InputError(file, f"{where}spreading", f"{self.spreading!r} is not allowed: expected one "
                                 f"of {', '.join(SPREADINGS)}")
        if self.swell_hs_m > 0.0:
            if self.swell_tp_s is None:
                raise InputError(file, f"{where}swell_tp_s", f"missing: a swell with swell_hs_m = "
                                 f"{self.swell_hs_m:g} m needs its peak period (a number in [1, 30] s)")
            if self.swell_spreading not in SPREADINGS:
                raise InputError(file, f"{where}swell_spreading", f"{self.swell_spreading!r} is not allowed: "
                                 f"expected one of {', '.join(SPREADINGS)}")
        if not self.band_low < 1.0 < self.band_high:
            raise InputError(file, f"{where}band_low", f"band [{self.band_low:g}, {self.band_high:g}] ω_p "
                             "must contain the peak (band_low < 1 < band_high)")


@dataclasses.dataclass(frozen=True)
class WaveSystem:
    """One wave system (wind sea or swell), SI: the directional spectrum S(ω) D(μ − μ₀; ω) it realizes."""

    spectrum: str
    hs_m: float
    omega_p: float  # [rad/s]
    gamma: float
    direction_to: float  # μ₀ [rad], the direction the system propagates TOWARDS (north 0, clockwise)
    spreading: str
    s: float  # cos-2s exponent; s_max for Mitsuyasu; unused for cos2/none
    omega_lo: float  # realized band [rad/s]
    omega_hi: float
    n: int

    @property
    def tp_s(self) -> float:
        return TWO_PI / self.omega_p

    def spectrum_1d(self, omega):
        """Target S(ω) [m² s/rad] (not truncated to the band)."""
        return spectrum(self.spectrum, omega, self.hs_m, self.omega_p, self.gamma)

    def s_of(self, omega):
        """The cos-2s exponent at ω (constant except for Mitsuyasu)."""
        if self.spreading == "mitsuyasu":
            return mitsuyasu_s(omega, self.omega_p, self.s)
        return np.full(np.shape(omega), self.s, dtype=float)

    def directional(self, omega, mu):
        """S(ω) D(μ − μ₀; ω) [m² s/rad²] on the grid omega[:, None] × mu[None, :] (μ [rad], towards).

        For ``none`` (long-crested) the direction is a delta: the grid gets the 1-D spectrum spread
        over the one bin nearest μ₀ (needs a uniform mu grid) so that the grid integral is right.
        """
        omega = np.asarray(omega, dtype=float)
        mu = np.asarray(mu, dtype=float)
        S = self.spectrum_1d(omega)
        if self.spreading == "none":
            D = np.zeros((omega.size, mu.size))
            dmu = mu[1] - mu[0]
            i = int(np.argmin(np.abs(np.angle(np.exp(1j * (mu - self.direction_to))))))
            D[:, i] = 1.0 / dmu
            return S[:, None] * D
        s = self.s_of(omega)
        D = spreading_function(self.spreading, mu[None, :] - self.direction_to, s[:, None])
        return S[:, None] * D

    def first_moments(self, omega):
        """(a₁, b₁)(ω) = ∫D (cos μ, sin μ) dμ in absolute axes (north, east), closed form."""
        r1, _ = spreading_moments(self.spreading, self.s_of(omega))
        r1 = np.broadcast_to(r1, np.shape(omega))
        return r1 * math.cos(self.direction_to), r1 * math.sin(self.direction_to)


@dataclasses.dataclass(frozen=True, eq=False)
class WaveField:
    """A realized seaway: packed components and the definition truth scoring needs.

    ``components``: (n, 6) float64 [a, ω, k, cos μ, sin μ, ε] (COLUMNS), sea first then swell.
    ``depth_m``: water depth used for k and the kinematics (math.inf: deep water).
    """

    components: np.ndarray
    depth_m: float
    systems: tuple[WaveSystem, ...]

    @property
    def hs_m(self) -> float:
        """Target total H_s = √(Σ H_s,i²) [m]."""
        return math.sqrt(sum(s.hs_m ** 2 for s in self.systems))

    @property
    def hs_realized_m(self) -> float:
        """H_s of the components, 4 √(Σ a²/2) [m] (the band-limited target, exactly)."""
        return 4.0 * math.sqrt(0.5 * float(np.sum(self.components[:, 0] ** 2)))

    def spectrum(self, omega):
        """Target 1-D spectrum S(ω) = Σ systems [m² s/rad]."""
        omega = np.asarray(omega, dtype=float)
        out = np.zeros_like(omega)
        for s in self.systems:
            out = out + s.spectrum_1d(omega)
        return out

    def directional_spectrum(self, omega, mu):
        """Target S(ω, μ) [m² s/rad²] on omega[:, None] × mu[None, :] (μ towards, rad)."""
        omega = np.asarray(omega, dtype=float)
        mu = np.asarray(mu, dtype=float)
        out = np.zeros((omega.size, mu.size))
        for s in self.systems:
            out = out + s.directional(omega, mu)
        return out

    def _grid(self) -> np.ndarray:
        if not self.systems:
            return np.zeros(0)
        lo = min(s.omega_lo for s in self.systems)
        hi = max(s.omega_hi for s in self.systems)
        return np.linspace(lo, hi, 20001)

    @property
    def tp_s(self) -> float:
        """Period of the highest peak of the total target spectrum [s] (nan for a calm sea)."""
        w = self._grid()
        if w.size == 0:
            return math.nan
        S = self.spectrum(w)
        i = int(np.argmax(S))
        if 0 < i < w.size - 1:  # parabolic refinement on the fine grid
            d = S[i - 1] - 2.0 * S[i] + S[i + 1]
            off = 0.5 * (S[i - 1] - S[i + 1]) / d if d != 0.0 else 0.0
            return TWO_PI / (w[i] + off * (w[1] - w[0]))
        return TWO_PI / w[i]

    def bulk_direction(self) -> tuple[float, float]:
        """(mean direction the waves go TOWARDS [rad], circular spread σ₁ [rad]) of the target.

        Energy-weighted first Fourier coefficients over the realized bands (a buoy's bulk values):
        A₁ = ∫S a₁ dω / ∫S dω, B₁ likewise; mean = atan2(B₁, A₁), σ₁ = √(2(1 − √(A₁² + B₁²))).
        """
        if not self.systems:
            return math.nan, math.nan
        w = self._grid()
        num_a = 0.0
        num_b = 0.0
        den = 0.0
        for s in self.systems:
            inband = (w >= s.omega_lo) & (w <= s.omega_hi)
            S = np.where(inband, s.spectrum_1d(w), 0.0)
            a1, b1 = s.first_moments(w)
            num_a += np.trapezoid(S * a1, w)
            num_b += np.trapezoid(S * b1, w)
            den += np.trapezoid(S, w)
        A1, B1 = num_a / den, num_b / den
        return math.atan2(B1, A1) % TWO_PI, float(circular_spread(math.hypot(A1, B1)))

    @property
    def mean_direction_from_deg(self) -> float:
        """Nautical mean direction (waves come FROM) [deg], for reports."""
        to, _ = self.bulk_direction()
        return ((to + math.pi) % TWO_PI) / DEG


def realize_system(system: WaveSystem, depth_m: float, rng: np.random.Generator) -> np.ndarray:
    """(n, 6) components of one wave system (module doc, section 4, for the sampling scheme)."""
    n = system.n
    w = np.linspace(system.omega_lo, system.omega_hi, 16385)
    S = system.spectrum_1d(w)
    F = np.concatenate(([0.0], np.cumsum(0.5 * (S[1:] + S[:-1]) * np.diff(w))))
    m0_band = F[-1]
    u = (np.arange(n) + rng.random(n)) / n
    omega = np.interp(u * m0_band, F, w)
    perm = rng.permutation(n)
    v = (perm + rng.random(n)) / n
    dmu = _sample_spreading(system.spreading, system.s_of(omega), v)
    mu = system.direction_to + dmu
    phase = rng.uniform(0.0, TWO_PI, n)
    comp = np.empty((n, NCOL))
    comp[:, 0] = math.sqrt(2.0 * m0_band / n)
    comp[:, 1] = omega
    comp[:, 2] = wavenumber(omega, depth_m)
    comp[:, 3] = np.cos(mu)
    comp[:, 4] = np.sin(mu)
    comp[:, 5] = phase
    return comp


def systems_of(waves: Waves) -> tuple[WaveSystem, ...]:
    """The wave systems (SI) a :class:`Waves` describes; directions converted from 'from' to 'towards'."""
    waves.check()
    out = []
    if waves.hs_m > 0.0:
        wp = peak_frequency(waves.spectrum, waves.gamma, tp=waves.tp_s, tz=waves.tz_s, t1=waves.t1_s)
        out.append(WaveSystem(waves.spectrum, waves.hs_m, wp, waves.gamma,
                              (waves.direction_deg * DEG + math.pi) % TWO_PI, waves.spreading,
                              waves.spreading_s, waves.band_low * wp, waves.band_high * wp, waves.n_components))
    if waves.swell_hs_m > 0.0:
        wp = TWO_PI / waves.swell_tp_s
        out.append(WaveSystem("jonswap", waves.swell_hs_m, wp, waves.swell_gamma,
                              (waves.swell_direction_deg * DEG + math.pi) % TWO_PI, waves.swell_spreading,
                              waves.swell_spreading_s, waves.band_low * wp, waves.band_high * wp,
                              waves.swell_n_components))
    return tuple(out)


def realize(waves: Waves, depth_m: float, rng: np.random.Generator) -> WaveField:
    """Draw a seaway realization from ``rng`` (a seeded numpy Generator): same seed → same components.

    ``depth_m`` [m] (math.inf for deep water) sets the dispersion and the kinematics' depth factors.
    """
    if not isinstance(rng, np.random.Generator):
        raise TypeError("rng must be a numpy.random.Generator (seeded for reproducibility)")
    try:
        depth = float(depth_m)
    except (TypeError, ValueError):
        depth = math.nan
    if not depth > 0.0:
        raise InputError("scenario", "environment.water_depth_m", f"{depth_m!r} is not allowed: expected a "
                         "depth > 0 m (math.inf for deep water)")
    systems = systems_of(waves)
    parts = [realize_system(s, depth, rng) for s in systems]
    comp = np.concatenate(parts) if parts else np.zeros((0, NCOL))
    return WaveField(np.ascontiguousarray(comp), depth, systems)
