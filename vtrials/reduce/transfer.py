"""Transfer functions from cross-spectra: H₁ = G_xy/G_xx, coherence, random errors and intervals.

Bendat & Piersol (2010, "Random data", 4th ed., §9.2.4, Table 9.6): for n_d independent averages

    Ĥ₁ = Ĝ_xy/Ĝ_xx,  γ̂² = |Ĝ_xy|²/(Ĝ_xx Ĝ_yy),
    ε[|Ĥ|] ≈ √(1 − γ²)/(|γ| √(2 n_d)),  σ[φ̂] ≈ ε[|Ĥ|] (radians),

H₁ being unbiased by noise on the output y (noise on the input x biases it low). Overlapped Welch
segments are not independent: n_d = ν/2 with ν the equivalent degrees of freedom of a bin
(:func:`vtrials.reduce.spectra.welch_dof`). The 95 % intervals here are normal: |H|(1 ± z ε), φ ± z ε.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import stats

from vtrials.reduce.spectra import cross_spectrum


@dataclasses.dataclass(frozen=True)
class TransferFunction:
    """Ĥ(ω) [unit_y/unit_x] with coherence γ², normalized random error ε and the averages n_d."""

    omega: np.ndarray  # [rad/s]
    H: np.ndarray  # complex
    coherence: np.ndarray  # γ² ∈ [0, 1]
    error: np.ndarray  # ε = √(1 − γ²)/(|γ| √(2 n_d)), relative error of |H| and std of the phase [rad]
    n_d: float

    @property
    def amplitude(self) -> np.ndarray:
        return np.abs(self.H)

    @property
    def phase(self) -> np.ndarray:
        """Phase of y relative to x [rad] (y = |H| x delayed: negative)."""
        return np.angle(self.H)

    def amplitude_interval(self, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        z = stats.norm.ppf(0.5 + level / 2.0)
        a = self.amplitude
        return a * (1.0 - z * self.error), a * (1.0 + z * self.error)

    def phase_interval(self, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        z = stats.norm.ppf(0.5 + level / 2.0)
        return self.phase - z * self.error, self.phase + z * self.error

    def covers(self, H_true, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        """(amplitude covered, phase covered) per bin for a reference H_true (complex, same grid)."""
        H_true = np.asarray(H_true)
        lo, hi = self.amplitude_interval(level)
        a = np.abs(H_true)
        dphi = np.angle(H_true * np.conj(self.H))  # wrapped difference
        z = stats.norm.ppf(0.5 + level / 2.0)
        return (lo <= a) & (a <= hi), np.abs(dphi) <= z * self.error


def random_error(coherence, n_d: float):
    """ε = √(1 − γ²)/(|γ| √(2 n_d)) (Bendat & Piersol 2010, Table 9.6)."""
    g2 = np.clip(np.asarray(coherence, dtype=float), 1e-12, 1.0)
    return np.sqrt(1.0 - g2) / (np.sqrt(g2) * math.sqrt(2.0 * n_d))


def transfer_function(x, y, fs: float, nperseg: int, noverlap: int | None = None,
                      window: str = "hann") -> TransferFunction:
    """Ĥ₁ from input record x to output record y (both sampled at fs [Hz]), Welch segments of nperseg."""
    gxx = cross_spectrum(x, x, fs, nperseg, noverlap, window)
    gyy = cross_spectrum(y, y, fs, nperseg, noverlap, window)
    gxy = cross_spectrum(x, y, fs, nperseg, noverlap, window)
    Gxx = gxx.S.real
    Gyy = gyy.S.real
    with np.errstate(invalid="ignore", divide="ignore"):
        H = np.where(Gxx > 0.0, gxy.S / np.where(Gxx > 0.0, Gxx, 1.0), np.nan)
        coh = np.where((Gxx > 0.0) & (Gyy > 0.0), np.abs(gxy.S) ** 2 / (Gxx * Gyy), 0.0)
    coh = np.clip(coh, 0.0, 1.0)
    n_d = gxx.dof / 2.0
    return TransferFunction(gxx.omega, H, coh, random_error(coh, n_d), n_d)
