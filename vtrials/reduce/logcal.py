"""Speed-log calibration (seed 000, R/V ATHENA Kenyon knotmeter) and smoothing study.

Units: speeds through water m/s; log readings in the log's own unit (counts per second, displayed
m/s, …) — the calibration maps reading → STW [m/s]; times s.

Regression (simple linear, optionally weighted) following Montgomery & Runger, *Applied Statistics and
Probability for Engineers* (3rd ed. and later), ch. 11 "Simple Linear Regression and Correlation":
with x̄, ȳ, S_xx = Σ(x − x̄)², S_xy = Σ(x − x̄)(y − ȳ):

    β̂₁ = S_xy/S_xx,  β̂₀ = ȳ − β̂₁x̄,  σ̂² = SSE/(n − 2)   (standard error of estimate σ̂)
    se(β̂₁) = √(σ̂²/S_xx),  se(β̂₀) = √(σ̂²(1/n + x̄²/S_xx)),  R² = 1 − SSE/SST
    mean response at x₀:  ŷ₀ ± t_{α/2,n−2} √(σ̂²(1/n + (x₀ − x̄)²/S_xx))
    prediction at x₀:     ŷ₀ ± t_{α/2,n−2} √(σ̂²(1 + 1/n + (x₀ − x̄)²/S_xx))

(the same as Draper & Smith, *Applied Regression Analysis*, 3rd ed., ch. 1). Weighted form (weights
wᵢ = 1/σᵢ²): x̄, ȳ, S_xx, S_xy with weights and 1/n → 1/Σw (Draper & Smith ch. 9); with
absolute_sigma the σ̂² above is replaced by 1 (the σᵢ are taken as known).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import stats

from vtrials.reduce.estimate import Estimate


@dataclasses.dataclass(frozen=True)
class Calibration:
    """STW = β₀ + β₁ · reading.

    beta0 [m/s], beta1 [m/s per reading unit] as Estimates (dof n − 2); r2, r (correlation);
    see: standard error of estimate √(Σ eᵢ² / (n − 2)) [m/s] of the plain residuals, whatever the
    weights; scale2: the fit's variance factor Σ wᵢeᵢ² / (n − 2) — σ̂² in m²/s² when unweighted, the
    dimensionless reduced χ² when wᵢ = 1/σᵢ² (≈ 1 when the stated σᵢ explain the scatter);
    residuals [m/s]; xbar, sxx (weighted if weights); sum_w (n when unweighted); cov: covariance of
    (β₀, β₁).
    """

    beta0: Estimate
    beta1: Estimate
    r2: float
    r: float
    see: float
    scale2: float
    residuals: np.ndarray
    x: np.ndarray
    y: np.ndarray
    n: int
    dof: int
    xbar: float
    sxx: float
    sum_w: float
    cov: np.ndarray
    absolute_sigma: bool

    def __call__(self, reading):
        """STW [m/s] for log reading(s)."""
        return self.beta0.value + self.beta1.value * np.asarray(reading, dtype=float)

    def _s2(self):
        return 1.0 if self.absolute_sigma else self.scale2

    def _q(self, level):
        if self.absolute_sigma:
            return stats.norm.ppf(0.5 + level / 2.0)
        return stats.t.ppf(0.5 + level / 2.0, self.dof)

    def se_mean(self, reading):
        """Standard error of the mean response at reading(s) x₀: √(σ̂²(1/Σw + (x₀ − x̄)²/S_xx))."""
        x0 = np.asarray(reading, dtype=float)
        return np.sqrt(self._s2() * (1.0 / self.sum_w + (x0 - self.xbar) ** 2 / self.sxx))

    def band(self, reading, level=0.95, prediction=False):
        """(lo, hi) confidence band of the mean response, or with ``prediction=True`` the prediction
        band for one new reading (adds σ̂² — for a new point of unit weight)."""
        x0 = np.asarray(reading, dtype=float)
        var = self.se_mean(x0) ** 2
        if prediction:
            var = var + self._s2()
        h = self._q(level) * np.sqrt(var)
        y = self(x0)
        return y - h, y + h

    def stw(self, reading) -> Estimate:
        """Calibrated STW [m/s] at one reading (mean response) as an Estimate."""
        return Estimate(float(self(reading)), float(self.se_mean(reading)),
                        None if self.absolute_sigma else self.dof)

    def reading_for(self, stw) -> Estimate:
        """Inverse use: the log reading expected at a true STW [m/s], x₀ = (y₀ − β̂₀)/β̂₁, with the
        delta-method standard error se(x₀) = se_mean(x₀)/|β̂₁| (the first-order form of the
        Fieller/inverse-prediction interval, Draper & Smith §3.2 / Montgomery & Runger; valid when
        β̂₁ is many standard errors from zero)."""
        x0 = (stw - self.beta0.value) / self.beta1.value
        return Estimate(float(x0), float(self.se_mean(x0)) / abs(self.beta1.value),
                        None if self.absolute_sigma else self.dof)


def calibrate(log_reading, true_stw, std=None, absolute_sigma=None) -> Calibration:
    """Regress true STW [m/s] (from the current elimination) on the mean log readings.

    std: optional standard uncertainty of each true STW (e.g. the four-leg resolution's σ_U); then
    weighted least squares with wᵢ = 1/σᵢ²; absolute_sigma (default True when std is given) treats the
    σᵢ as known, otherwise they are relative weights and σ̂² is estimated from the residuals.
    See the module docstring for the formulas (Montgomery & Runger ch. 11; Draper & Smith ch. 1, 9).
    """
    x = np.asarray(log_reading, dtype=float)
    y = np.asarray(true_stw, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError("log_reading and true_stw must be equal-length 1-D arrays")
    n = x.size
    if n < 3:
        raise ValueError("need at least 3 points (n − 2 > 0 degrees of freedom)")
    w = np.ones(n) if std is None else 1.0 / np.broadcast_to(np.asarray(std, dtype=float), (n,)) ** 2
    if absolute_sigma is None:
        absolute_sigma = std is not None
    sw = float(w.sum())
    xbar = float(np.dot(w, x) / sw)
    ybar = float(np.dot(w, y) / sw)
    dx = x - xbar
    dy = y - ybar
    sxx = float(np.dot(w, dx * dx))
    if sxx <= 0:
        raise ValueError("readings have no spread")
    sxy = float(np.dot(w, dx * dy))
    syy = float(np.dot(w, dy * dy))
    b1 = sxy / sxx
    b0 = ybar - b1 * xbar
    res = y - b0 - b1 * x
    sse = float(np.dot(w, res * res))
    dof = n - 2
    s2 = sse / dof
    see = math.sqrt(float(np.dot(res, res)) / dof)
    s2_use = 1.0 if absolute_sigma else s2
    var_b1 = s2_use / sxx
    var_b0 = s2_use * (1.0 / sw + xbar * xbar / sxx)
    cov01 = -s2_use * xbar / sxx
    r2 = 1.0 - sse / syy if syy > 0 else 1.0
    est_dof = None if absolute_sigma else dof
    return Calibration(
        beta0=Estimate(b0, math.sqrt(var_b0), est_dof), beta1=Estimate(b1, math.sqrt(var_b1), est_dof),
        r2=r2, r=math.copysign(math.sqrt(max(r2, 0.0)), b1), see=see, scale2=s2, residuals=res, x=x, y=y, n=n,
        dof=dof, xbar=xbar, sxx=sxx, sum_w=sw, cov=np.array([[var_b0, cov01], [cov01, var_b1]]),
        absolute_sigma=bool(absolute_sigma))


# ==================================================================================================
# smoothing study (seed 000, Figures 4–5)
# ==================================================================================================
def counts_to_rate(counts, window_s=10.0):
    """Pulse counts accumulated over ``window_s`` seconds → count rate [counts/s] (the Kenyon meter
    of seed 000 counted for 10 s every 20 s; nominal display 0.3 kn per count/s)."""
    return np.asarray(counts, dtype=float) / window_s


def running_average(x, k: int):
    """Trailing running mean over k samples ("accumulating the 10-second counts for a given number of
    cycles … dropping the oldest sample and adding the last", seed 000). Length n − k + 1."""
    x = np.asarray(x, dtype=float)
    if k < 1 or k > x.size:
        raise ValueError("1 ≤ k ≤ len(x) required")
    c = np.cumsum(np.r_[0.0, x])
    return (c[k:] - c[:-k]) / k


@dataclasses.dataclass(frozen=True)
class SmoothingStudy:
    """For each k: the smoothed series (times of the newest sample in each average), its mean and
    std, the std expected if the raw cycles were independent (std₁/√k), and a rough standard error
    of each std, std/√(2(m_k − 1)) with m_k = n/k non-overlapping blocks (the overlapping running
    averages are not independent; this is indicative only)."""

    k: np.ndarray
    times: list
    series: list
    mean: np.ndarray
    std: np.ndarray
    std_white: np.ndarray
    std_se: np.ndarray


def smoothing_study(t, counts, k_values) -> SmoothingStudy:
    """Running averages of a pulse-count log over k counting cycles and their scatter vs k.

    t [s]: time of each count (end of its accumulation window); counts: counts (or rates, or
    calibrated speeds — the study is linear) per cycle; k_values: iterable of cycle counts, e.g.
    (1, 2, 3, 6) for the seed's 10-s, 20-s, 30-s and recommended 60-s time bases. A std falling
    slower than 1/√k shows the long-period (80–120 s, helm) variation the seed reports.
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(counts, dtype=float)
    if t.shape != x.shape:
        raise ValueError("t and counts must have equal length")
    ks = np.asarray(list(k_values), dtype=int)
    n = x.size
    series, times, means, stds, ses = [], [], [], [], []
    for k in ks:
        y = running_average(x, int(k))
        series.append(y)
        times.append(t[k - 1:])
        means.append(float(y.mean()))
        sd = float(y.std(ddof=1)) if y.size > 1 else math.nan
        stds.append(sd)
        m = n / k
        ses.append(sd / math.sqrt(2.0 * (m - 1.0)) if m > 1 else math.nan)
    std1 = float(x.std(ddof=1))
    return SmoothingStudy(k=ks, times=times, series=series, mean=np.array(means), std=np.array(stds),
                          std_white=std1 / np.sqrt(ks), std_se=np.array(ses))
