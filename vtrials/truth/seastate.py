"""The true sea over a run: what a wave-estimation reduction is scored against.

From the realized seaway's components (n, 6) [a, ω, k, cos μ, sin μ, ε] (:mod:`vtrials.physics.
environment.waves`; μ the direction the component travels TOWARDS, from north, clockwise): the
stationary sea's H_s = 4 √(Σ a²/2) (exactly the band-limited spectrum's), the energy-weighted mean
direction atan2(Σ a² sin μ, Σ a² cos μ) (a buoy's first-moment mean direction) and its circular spread
σ₁ = √(2(1 − R̄)), and the same relative to the ship's true mean heading over the run window (from the
truth file's heading column), as the direction the waves come FROM relative to the bow, + starboard.
"""

from __future__ import annotations

import math

import numpy as np

TWO_PI = 2.0 * math.pi


def sea_truth(components, heading: float | None = None) -> dict:
    """{"hs", "mean_to" [rad], "spread" [rad], and with ``heading`` [rad]: "mu_rel" (towards, relative to the
    heading, (−π, π]) and "from_rel_deg" (from, relative to the bow, + starboard)}."""
    c = np.asarray(components, dtype=float)
    e = 0.5 * c[:, 0] ** 2
    hs = 4.0 * math.sqrt(float(np.sum(e)))
    sx, sy = float(np.sum(e * c[:, 3])), float(np.sum(e * c[:, 4]))
    mean_to = math.atan2(sy, sx) % TWO_PI
    rbar = math.hypot(sx, sy) / float(np.sum(e))
    out = {"hs": hs, "mean_to": mean_to, "spread": math.sqrt(max(2.0 * (1.0 - rbar), 0.0))}
    if heading is not None:
        mu_rel = math.remainder(mean_to - heading, TWO_PI)
        out["mu_rel"] = mu_rel
        out["from_rel_deg"] = math.degrees(math.remainder(mu_rel + math.pi, TWO_PI))
    return out


def window_heading(t, heading, t0: float, t1: float) -> float:
    """Circular mean of the true heading [rad] over t0 ≤ t ≤ t1."""
    t = np.asarray(t, dtype=float)
    h = np.asarray(heading, dtype=float)
    k = (t >= t0) & (t <= t1)
    return math.atan2(float(np.mean(np.sin(h[k]))), float(np.mean(np.cos(h[k])))) % TWO_PI
