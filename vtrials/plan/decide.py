"""When does an agenda meet its target, and what does the search predict for one it has not run.

Decision rule (on a campaign's errors e_i of the target quantity against truth, i = 1..n):

* k = #{|e_i| ≤ tolerance} (a replicate without the quantity counts as outside), p̂ = k/n, with its
  Wilson score interval (:func:`vtrials.score.coverage.wilson`);
* ``rule = "quantile"`` (default): the agenda meets the target when p̂ ≥ confidence — the same as "the
  empirical confidence-quantile of |e| (the ⌈confidence·n⌉-th smallest) is within the tolerance". This
  is the accuracy statement a trial specification makes ("within ±0.1 kn at 95 %"), estimated without
  a distributional assumption; its Wilson interval is reported beside it, so a verdict resting on a
  few replicates is visible as such.
* ``rule = "wilson"``: the agenda meets the target only when the Wilson lower bound of p is ≥ confidence
  — demonstrated at 95 % confidence; it needs many replicates (with n = 200 and confidence 0.95,
  p̂ ≥ 0.98) and so chooses longer agendas.

Surrogate (the search's prediction between campaigns): the mean squared error of the target quantity

    MSE = A[spots, runs] + B / (runs · run_s)

— a floor per pattern (what current elimination and the all-runs analysis leave: it depends on how
many runs, how far apart, not on their length) plus the instruments' noise averaged over the measured
time at the target spot — fitted by non-negative least squares to the search campaigns. The shape of
the error distribution: ``shape = "normal"`` (the default) takes the errors as normal — predicted
fraction within ±tol erf(tol/√(2 MSE)), predicted confidence-quantile z·√MSE, z = Φ⁻¹((1 + confidence)/2);
``shape = "empirical"`` pools |e|/√MSE of every search replicate (each campaign scaled by its own MSE)
and uses that pool's fraction within tol/√MSE and its quantile times √MSE. Measured on the patrol
vessel's plan (benchmarks/results/plan_patrol51): the 40-replicate pool put the 95 % quantile of
|e|/√MSE at 1.62, the 200-replicate verification of the chosen agenda at 1.91 (normal: 1.96) — the
pool's tail was too light and the agenda it chose missed its target by one replicate in 200, hence
the normal default. Both are reported beside the campaigns' own numbers.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import optimize, special, stats

from vtrials.score.coverage import wilson


def empirical(errors, tolerance: float, confidence: float) -> dict:
    """Fraction within tolerance (with its Wilson interval) and the empirical quantile of |error|."""
    e = np.abs(np.asarray(errors, dtype=float))
    e = np.where(np.isfinite(e), e, np.inf)
    n = int(e.size)
    k = int(np.sum(e <= tolerance))
    lo, hi = wilson(k, n)
    q = float(np.sort(e)[min(n - 1, max(0, math.ceil(confidence * n) - 1))]) if n else math.nan
    fin = e[np.isfinite(e)]
    return {"n": n, "within": k, "fraction": k / n if n else math.nan, "wilson_lo": lo, "wilson_hi": hi,
            "quantile_abs_error": q, "rms_error": float(np.sqrt(np.mean(fin ** 2))) if fin.size else math.nan,
            "mean_error": float(np.mean(np.asarray(errors, float)[np.isfinite(errors)])) if fin.size else math.nan,
            "missing": int(n - fin.size)}


def meets(stats_: dict, confidence: float, rule: str) -> bool:
    """The decision rule on an :func:`empirical` summary."""
    if stats_["n"] == 0:
        return False
    if rule == "wilson":
        return stats_["wilson_lo"] >= confidence
    return stats_["within"] >= confidence * stats_["n"] - 1e-9


def error_shape(campaigns) -> np.ndarray:
    """The pooled shape of the error distribution: |e|/√MSE of every replicate of every campaign
    (``campaigns``: (errors, mse) pairs; a replicate without the quantity is +inf), sorted."""
    z = []
    for errs, mse in campaigns:
        e = np.abs(np.asarray(errs, dtype=float))
        if not (math.isfinite(mse) and mse > 0):
            continue
        z.append(np.where(np.isfinite(e), e / math.sqrt(mse), np.inf))
    return np.sort(np.concatenate(z)) if z else np.zeros(0)


def predicted_fraction(mse: float, tolerance: float, shape: np.ndarray | None = None) -> float:
    """P(|e| ≤ tol) for errors of mean square ``mse``: normal (``shape`` None), or distributed like
    the pooled campaigns' ``shape`` (:func:`error_shape`) scaled to √mse."""
    if mse <= 0:
        return 1.0
    if shape is None or shape.size == 0:
        return float(special.erf(tolerance / math.sqrt(2.0 * mse)))
    return float(np.mean(shape <= tolerance / math.sqrt(mse)))


def predicted_quantile(mse: float, confidence: float, shape: np.ndarray | None = None) -> float:
    if shape is None or shape.size == 0:
        return float(stats.norm.ppf(0.5 * (1.0 + confidence)) * math.sqrt(max(mse, 0.0)))
    k = min(shape.size - 1, max(0, math.ceil(confidence * shape.size) - 1))
    return float(shape[k] * math.sqrt(max(mse, 0.0)))


def predicted_meets(mse: float, tolerance: float, confidence: float, rule: str, n_verify: int,
                    shape: np.ndarray | None = None) -> bool:
    p = predicted_fraction(mse, tolerance, shape)
    if rule == "wilson":
        return wilson(int(round(p * n_verify)), n_verify)[0] >= confidence
    return p >= confidence


@dataclasses.dataclass
class Surrogate:
    """MSE = A[pattern] + B·x, x = 1/(runs·run_s), fitted to the evaluated candidates."""

    floors: dict  # pattern -> A
    slope: float  # B
    slope_identified: bool
    x_range: dict  # pattern -> (min x, max x) evaluated

    def known(self, pattern, x: float) -> bool:
        """Can the surrogate predict this candidate (its pattern has been run, and it interpolates in
        run length or the run-length term is identified)?"""
        if pattern not in self.floors:
            return False
        lo, hi = self.x_range[pattern]
        return self.slope_identified or lo - 1e-12 <= x <= hi + 1e-12

    def mse(self, pattern, x: float) -> float:
        return self.floors[pattern] + self.slope * x


def fit_surrogate(points: list[tuple]) -> Surrogate:
    """Fit to (pattern, x, mse, n) points by non-negative least squares (weights √n)."""
    pats = sorted({p[0] for p in points})
    xr = {pt: (min(p[1] for p in points if p[0] == pt), max(p[1] for p in points if p[0] == pt)) for pt in pats}
    ident = any(hi > lo * (1 + 1e-9) for lo, hi in xr.values())
    if not points:
        return Surrogate({}, 0.0, False, {})
    w = np.sqrt([p[3] for p in points])
    A = np.zeros((len(points), len(pats) + (1 if ident else 0)))
    for i, p in enumerate(points):
        A[i, pats.index(p[0])] = 1.0
        if ident:
            A[i, -1] = p[1]
    y = np.array([p[2] for p in points])
    scale = np.max(np.abs(A), axis=0)
    coef, _ = optimize.nnls((A * w[:, None]) / scale, y * w)
    coef = coef / scale
    return Surrogate({pt: float(coef[i]) for i, pt in enumerate(pats)}, float(coef[-1]) if ident else 0.0, ident, xr)
