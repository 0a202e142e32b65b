"""How honest an interval is, measured over many replicates (docs/uncertainty.md in the project's brief).

* Coverage: the fraction k/n of replicates whose 95 % interval holds the truth, with its Wilson score
  interval (Wilson 1927, J. Am. Stat. Assoc. 22:209–212):
      (p̂ + z²/2n ± z √(p̂(1 − p̂)/n + z²/4n²)) / (1 + z²/n),  z = 1.96.
* Sharpness: mean half-width of the intervals divided by the empirical 95 % quantile of |error|;
  1 is ideal, above 1.5 the intervals are wasteful, below 0.7 overconfident.
* Verdict: "calibrated" when the Wilson interval contains 0.95 or lies within [0.90, 0.99] and the
  sharpness is within [0.7, 1.5]; otherwise "uncalibrated", with the reason.
"""

from __future__ import annotations

import math

import numpy as np

Z95 = 1.959963984540054


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion k/n (n ≥ 1)."""
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


def verdict(covered, half_widths, errors, min_n: int = 20) -> dict:
    """Coverage, its Wilson interval, sharpness and the calibration verdict of one quantity."""
    c = [bool(x) for x in covered if x is not None]
    n, k = len(c), sum(c)
    lo, hi = wilson(k, n)
    sh = sharpness(half_widths, errors)
    e = np.asarray(errors, dtype=float)
    e = e[np.isfinite(e)]
    out = {"n": n, "covered": k, "coverage": k / n if n else math.nan, "wilson_lo": lo, "wilson_hi": hi,
           "sharpness": sh, "rms_error": float(np.sqrt(np.mean(e ** 2))) if e.size else math.nan,
           "mean_error": float(np.mean(e)) if e.size else math.nan}
    reasons = []
    if n < min_n:
        reasons.append(f"only {n} replicates with an interval")
    elif not (lo <= 0.95 <= hi or (lo >= 0.90 and hi <= 0.99)):
        reasons.append(f"coverage {k}/{n} (Wilson [{lo:.3f}, {hi:.3f}])")
    if not (math.isfinite(sh) and 0.7 <= sh <= 1.5):
        reasons.append(f"sharpness {sh:.2f} outside [0.7, 1.5]")
    out["verdict"] = "calibrated" if not reasons else "uncalibrated"
    out["why"] = "; ".join(reasons)
    return out
