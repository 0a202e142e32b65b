"""Response spectra of a run: Welch estimates, their degrees of freedom, m0/RMS/H_s with chi-square intervals.

Conventions: one-sided spectra in angular frequency, S(ω) [unit² s/rad], ∫₀^∞ S dω = variance (= m0);
ω [rad/s]. For waves H_s = 4 √m0.

* Welch (1967, IEEE Trans. Audio Electroacoust. 15:70–73) averaging of windowed, overlapping segments
  (scipy.signal.welch / csd, density scaling, converted from per-Hz to per-rad/s: S_ω = S_f/(2π)).
* Equivalent degrees of freedom of a Welch bin (Welch 1967; Percival & Walden 1993, "Spectral analysis
  for physical applications", eq. 292b): ν = 2 K / (1 + 2 Σ_{m=1}^{K−1} (1 − m/K) ρ(m)²),
  ρ(m) = Σ_n h_n h_{n+mD}, h the window normalised to Σ h² = 1, D the segment step, K segments.
  Hann with 50 % overlap: ρ(1) = 0.1667, ν ≈ 1.89 K for large K.
* Variance of the sample variance of a Gaussian record of duration T (Bendat & Piersol 2010, "Random
  data", 4th ed., §8.2.1): Var(m̂0) = (2π/T) ∫₀^∞ S(ω)² dω for T much longer than the correlation time,
  so m0 has ν₀ = 2 m0²/Var(m̂0) = T m0² / (π ∫ S² dω) equivalent degrees of freedom; the interval
  ν₀ m̂0/χ²_{ν₀}(1 − α/2) ≤ m0 ≤ ν₀ m̂0/χ²_{ν₀}(α/2) (Satterthwaite's chi-square approximation),
  and H_s, RMS through the square root.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import signal, stats

from vtrials.errors import InputError

TWO_PI = 2.0 * math.pi


@dataclasses.dataclass(frozen=True)
class Spectrum:
    """A Welch spectrum: ω [rad/s], S [unit² s/rad] (or a cross-spectrum, complex), ν per bin, K segments."""

    omega: np.ndarray
    S: np.ndarray
    dof: float
    n_segments: int
    duration_s: float


def _check_record(x, fs: float, nperseg: int, name: str = "x") -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.ndim != 1 or x.size < 8:
        raise InputError("record", name, f"must be a 1-D array of at least 8 samples, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError("record", name, "contains non-finite samples; clean the record first")
    if not (math.isfinite(fs) and fs > 0.0):
        raise InputError("record", "fs", f"sampling rate {fs!r} Hz: must be a finite number > 0")
    if not (8 <= int(nperseg) <= x.size):
        raise InputError("record", "nperseg", f"{nperseg!r}: must be an integer in [8, {x.size}] (record length)")
    return x


def welch_dof(n: int, nperseg: int, noverlap: int | None = None, window: str = "hann") -> tuple[float, int]:
    """(ν, K): equivalent degrees of freedom of a Welch bin and the number of segments (module doc)."""
    if noverlap is None:
        noverlap = nperseg // 2
    step = nperseg - noverlap
    K = 1 + (n - nperseg) // step
    h = signal.get_window(window, nperseg)
    h = h / math.sqrt(float(np.sum(h * h)))
    denom = 1.0
    for m in range(1, K):
        shift = m * step
        if shift >= nperseg:
            break
        rho = float(np.sum(h[:nperseg - shift] * h[shift:]))
        denom += 2.0 * (1.0 - m / K) * rho * rho
    return 2.0 * K / denom, K


def cross_spectrum(x, y, fs: float, nperseg: int, noverlap: int | None = None, window: str = "hann") -> Spectrum:
    """One-sided cross-spectral density G_xy(ω) = E[X* Y] per rad/s (scipy.signal.csd convention), ω [rad/s].

    G_xx is real; G_xy of y lagging x by φ has phase −φ. Linear detrending per segment.
    """
    x = _check_record(x, fs, nperseg, "x")
    y = _check_record(y, fs, nperseg, "y")
    if x.size != y.size:
        raise InputError("record", "y", f"length {y.size} differs from x's {x.size}")
    f, G = signal.csd(x, y, fs=fs, window=window, nperseg=nperseg, noverlap=noverlap, detrend="linear")
    nu, K = welch_dof(x.size, nperseg, noverlap, window)
    return Spectrum(TWO_PI * f, G / TWO_PI, nu, K, x.size / fs)


def response_spectrum(x, fs: float, nperseg: int, noverlap: int | None = None, window: str = "hann") -> Spectrum:
    """Auto-spectrum S(ω) [unit² s/rad] of a record sampled at fs [Hz] (Welch; module doc)."""
    sp = cross_spectrum(x, x, fs, nperseg, noverlap, window)
    return dataclasses.replace(sp, S=sp.S.real)


def cross_spectral_matrix(records, fs: float, nperseg: int, noverlap: int | None = None,
                          window: str = "hann") -> Spectrum:
    """G_mn(ω) = E[X_m* X_n] for records (m, N): S has shape (n_ω, m, m), Hermitian per ω."""
    recs = [np.asarray(r, dtype=float) for r in records]
    m = len(recs)
    out = None
    for i in range(m):
        for j in range(i, m):
            sp = cross_spectrum(recs[i], recs[j], fs, nperseg, noverlap, window)
            if out is None:
                out = np.zeros((sp.omega.size, m, m), dtype=complex)
                base = sp
            out[:, i, j] = sp.S
            out[:, j, i] = np.conj(sp.S)
    return dataclasses.replace(base, S=out)


def spectral_moment(omega, S, n: int = 0) -> float:
    """m_n = ∫ ω^n S(ω) dω (trapezoid on the given grid) [unit² (rad/s)^n]."""
    omega = np.asarray(omega, dtype=float)
    return float(np.trapezoid(omega ** n * np.asarray(S, dtype=float), omega))


@dataclasses.dataclass(frozen=True)
class VarianceEstimate:
    """m0 [unit²] with its equivalent degrees of freedom ν₀; chi-square intervals of m0, RMS and H_s."""

    m0: float
    dof: float

    def m0_interval(self, level: float = 0.95) -> tuple[float, float]:
        a = 1.0 - level
        return (self.dof * self.m0 / stats.chi2.ppf(1.0 - a / 2.0, self.dof),
                self.dof * self.m0 / stats.chi2.ppf(a / 2.0, self.dof))

    @property
    def rms(self) -> float:
        return math.sqrt(self.m0)

    @property
    def hs(self) -> float:
        """4 √m0 (significant wave height if the record is a wave elevation) [m]."""
        return 4.0 * math.sqrt(self.m0)

    def rms_interval(self, level: float = 0.95) -> tuple[float, float]:
        lo, hi = self.m0_interval(level)
        return math.sqrt(lo), math.sqrt(hi)

    def hs_interval(self, level: float = 0.95) -> tuple[float, float]:
        lo, hi = self.m0_interval(level)
        return 4.0 * math.sqrt(lo), 4.0 * math.sqrt(hi)


def variance_estimate(x, fs: float, nperseg: int, omega_min: float = 0.0) -> VarianceEstimate:
    """m0 of a record with ν₀ = T m0²/(π ∫S² dω) (module doc; S from Welch with ``nperseg``).

    m0 is the integral of the Welch spectrum above ``omega_min`` [rad/s] (0: the whole spectrum, which
    equals the variance of the detrended record up to the window's averaging).
    """
    sp = response_spectrum(x, fs, nperseg)
    keep = sp.omega >= omega_min
    w, S = sp.omega[keep], sp.S[keep]
    m0 = spectral_moment(w, S)
    s2 = spectral_moment(w, S * S)
    if not m0 > 0.0:
        raise InputError("record", "x", "has no variance in the band: m0 = 0")
    # the Welch estimate of ∫S² is biased high by the bins' own scatter: E[Ŝ²] = S²(1 + 2/ν)
    s2 /= 1.0 + 2.0 / sp.dof
    nu0 = sp.duration_s * m0 * m0 / (math.pi * s2)
    return VarianceEstimate(m0, nu0)
