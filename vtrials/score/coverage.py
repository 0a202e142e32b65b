"""How honest an interval is, measured over many replicates (docs/uncertainty.md in the project's brief).

* Coverage: the fraction k/n of replicates whose 95 % interval holds the truth, with its Wilson score
  interval (Wilson 1927, J. Am. Stat. Assoc. 22:209–212):
      (p̂ + z²/2n ± z √(p̂(1 − p̂)/n + z²/4n²)) / (1 + z²/n),  z = 1.96.
* Sharpness: mean half-width of the intervals divided by the empirical 95 % quantile of |error|;
  1 is ideal, above 1.5 the intervals are wasteful, below 0.7 overconfident.
* Rows of one replicate are not independent trials: a trial day's spots share its torsionmeter's
  scale error, its legs the day's current model, its runs the gyro's drift, so their coverage
  indicators are correlated within the day. The Wilson interval then takes the effective number of
  independent trials (Kish 1965, Survey Sampling, design effect): n_eff = p̂(1 − p̂) / V̂, V̂ the
  cluster-robust (between-replicate) variance of p̂ = Σ k_c / Σ m_c,
      V̂ = C/(C − 1) Σ_c (k_c − p̂ m_c)² / n²,
  clamped to [C, n] (a day counts at least once and its rows at most once each). With every row its
  own replicate this is the plain Wilson interval.
* Verdict: "calibrated" when the Wilson interval contains 0.95 or lies within [0.90, 0.99] and the
  sharpness is within [0.7, 1.5]; otherwise "uncalibrated", with the reason.
"""

from __future__ import annotations

import math

import numpy as np

Z95 = 1.959963984540054


def effective_trials(covered, clusters) -> float:
    """Kish's effective number of independent trials of the indicators ``covered`` grouped by
    ``clusters`` (replicate of each row): p̂(1 − p̂) over the cluster-robust variance of p̂, clamped to
    [number of clusters, number of rows] (see the module docstring)."""
    y = np.asarray(covered, dtype=float)
    c = np.asarray(clusters)
    n = y.size
    ids, inv = np.unique(c, return_inverse=True)
    C = ids.size
    if n == 0 or C < 2:
        return float(n)
    p = float(y.mean())
    k = np.bincount(inv, weights=y)
    m = np.bincount(inv).astype(float)
    var = C / (C - 1) * float(np.sum((k - p * m) ** 2)) / n ** 2
    if var <= 0.0:
        return float(n) if 0.0 < p < 1.0 else float(C)
    return float(min(max(p * (1.0 - p) / var, C), n))


def wilson(k: float, n: float, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion k/n (n > 0; k and n may be effective counts)."""
    if n <= 0:
        return (math.nan, math.nan)
    p = k / n
    den = 1.0 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (max(0.0, mid - half), min(1.0, mid + half))


def sharpness(half_widths, errors) -> float:
    """Mean half-width over the empirical 95 % quantile of |error| (NaN if undefined)."""
    h = np.asarray(half_widths, dtype=float)
    e = np.abs(np.asarray(errors, dtype=float))
    ok = np.isfinite(h) & np.isfinite(e)
    if ok.sum() < 2:
        return math.nan
    q = float(np.quantile(e[ok], 0.95))
    return float(np.mean(h[ok]) / q) if q > 0 else math.inf


def verdict(covered, half_widths, errors, min_n: int = 20, clusters=None) -> dict:
    """Coverage, its Wilson interval, sharpness and the calibration verdict of one quantity.
    ``clusters``: the replicate of each row (the Wilson interval on the effective number of trials,
    :func:`effective_trials`); None: every row independent."""
    keep = [i for i, x in enumerate(covered) if x is not None]
    c = [bool(covered[i]) for i in keep]
    n, k = len(c), sum(c)
    n_eff = float(n) if clusters is None else effective_trials(c, [clusters[i] for i in keep])
    lo, hi = wilson(k * n_eff / n if n else 0.0, n_eff)
    sh = sharpness(half_widths, errors)
    e = np.asarray(errors, dtype=float)
    e = e[np.isfinite(e)]
    out = {"n": n, "n_eff": n_eff, "covered": k, "coverage": k / n if n else math.nan, "wilson_lo": lo, "wilson_hi": hi,
           "sharpness": sh, "rms_error": float(np.sqrt(np.mean(e ** 2))) if e.size else math.nan,
           "mean_error": float(np.mean(e)) if e.size else math.nan}
    reasons = []
    if n < min_n:
        reasons.append(f"only {n} replicates with an interval")
    elif not (lo <= 0.95 <= hi or (lo >= 0.90 and hi <= 0.99)):
        reasons.append(f"coverage {k}/{n} (Wilson [{lo:.3f}, {hi:.3f}] on {n_eff:.0f} effective trials)")
    if not (math.isfinite(sh) and 0.7 <= sh <= 1.5):
        reasons.append(f"sharpness {sh:.2f} outside [0.7, 1.5]")
    out["verdict"] = "calibrated" if not reasons else "uncalibrated"
    out["why"] = "; ".join(reasons)
    return out
