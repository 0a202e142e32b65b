"""The true sea over an instrument's window, by the definitions the wave reductions use (issue 13).

From the seaway's components (:class:`vtrials.physics.environment.waves.WaveField`: energy e_j = a_j²/2 at
ω_j, direction μ_j towards), never from a reduction on cleaner data:

* H_s over a band: 4 √(Σ_band e_j) — the spectrum's m0 in the band (the expectation a record estimates);
* H_s of a window: 4 × the standard deviation of the true surface elevation at the instrument's
  position(s) over [t0, t1] (what a perfect gauge there would have read in that window: the estimate's
  sampling variability is part of the sea, not of the instrument);
* mean direction and spreading over a band: the energy-weighted first circular moment
  A₁ + i B₁ = Σ e_j e^{iμ_j}/Σ e_j, mean direction atan2(B₁, A₁) (towards), circular spread
  σ₁ = √(2(1 − |A₁ + i B₁|)) (Kuik, van Vledder & Holthuijsen 1988) — the same bulk definition as a buoy's
  S-weighted a₁, b₁ (:meth:`vtrials.reduce.directional.FourierCoefficients.bulk`);
* the true directional spectrum S(ω) D(μ; ω) of the wave systems on a grid
  (:meth:`WaveField.directional_spectrum`), and per frequency the first moments a₁(ω), b₁(ω) in closed form
  (:meth:`WaveSystem.first_moments`).
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.physics.environment.waves import elevation

TWO_PI = 2.0 * math.pi


def _band(field, omega_lo: float, omega_hi: float) -> np.ndarray:
    w = field.components[:, 1]
    return (w >= omega_lo) & (w <= omega_hi)


def band_truth(field, omega_lo: float = 0.0, omega_hi: float = math.inf, bins=None) -> dict:
    """{hs_m, mean_direction_to, spread, m0} of the seaway's components with ω in [omega_lo, omega_hi] [rad/s]
    — or, with ``bins`` = (centres ω_k, width Δω), in the union of the bins [ω_k − Δω/2, ω_k + Δω/2) (the
    frequencies a reduction actually used)."""
    if field is None or field.components.shape[0] == 0:
        return {"hs_m": 0.0, "mean_direction_to": math.nan, "spread": math.nan, "m0": 0.0}
    if bins is not None:
        centres, width = np.asarray(bins[0], dtype=float), float(bins[1])
        w = field.components[:, 1]
        k = np.floor((w - (centres[0] - 0.5 * width)) / width + 1e-12).astype(int)
        grid = np.round((centres - centres[0]) / width).astype(int)
        c = field.components[np.isin(k, grid)]
    else:
        c = field.components[_band(field, omega_lo, omega_hi)]
    return _moments(c)


def _moments(c: np.ndarray) -> dict:
    """H_s, first-moment mean direction (towards) and circular spread σ₁ of components (n, 6)."""
    e = 0.5 * c[:, 0] ** 2
    m0 = float(np.sum(e))
    if m0 <= 0.0:
        return {"hs_m": 0.0, "mean_direction_to": math.nan, "spread": math.nan, "m0": 0.0}
    z = complex(np.sum(e * c[:, 3]), np.sum(e * c[:, 4])) / m0
    return {"hs_m": 4.0 * math.sqrt(m0), "mean_direction_to": math.atan2(z.imag, z.real) % TWO_PI,
            "spread": math.sqrt(2.0 * (1.0 - min(1.0, abs(z)))), "m0": m0}


def sea_truth(components, heading: float | None = None) -> dict:
    """The whole stationary sea of components (n, 6) [a, ω, k, cos μ, sin μ, ε] (μ towards, from north):
    {"hs", "mean_to" [rad], "spread" [rad]} by the definitions above, and with ``heading`` [rad] (the
    ship's true mean heading over a run, :func:`window_heading`): "mu_rel" (towards, relative to the
    heading, (−π, π]) and "from_rel_deg" (where the waves come from relative to the bow, + starboard) —
    what ship-as-a-wave-buoy and wave fusion are scored against."""
    m = _moments(np.asarray(components, dtype=float))
    out = {"hs": m["hs_m"], "mean_to": m["mean_direction_to"], "spread": m["spread"]}
    if heading is not None:
        mu_rel = math.remainder(out["mean_to"] - heading, TWO_PI)
        out["mu_rel"] = mu_rel
        out["from_rel_deg"] = math.degrees(math.remainder(mu_rel + math.pi, TWO_PI))
    return out


def window_heading(t, heading, t0: float, t1: float) -> float:
    """Circular mean of the true heading [rad] over t0 ≤ t ≤ t1."""
    t = np.asarray(t, dtype=float)
    h = np.asarray(heading, dtype=float)
    k = (t >= t0) & (t <= t1)
    return math.atan2(float(np.mean(np.sin(h[k]))), float(np.mean(np.cos(h[k])))) % TWO_PI


def window_hs(field, north, east, t0: float, t1: float, rate_hz: float = 4.0) -> float:
    """H_s = 4 σ_η of the true surface over [t0, t1] at a fixed point (north, east [m]) or along a track
    given as callables north(t), east(t) (a drifting buoy), sampled at ``rate_hz``."""
    if field is None or field.components.shape[0] == 0:
        return 0.0
    t = np.arange(t0, t1, 1.0 / rate_hz)
    x = north(t) if callable(north) else np.full(t.size, float(north))
    y = east(t) if callable(east) else np.full(t.size, float(east))
    eta = elevation(field.components, x, y, t)
    return 4.0 * float(np.std(eta))


def directional_spectrum(field, omega, mu) -> np.ndarray:
    """The true S(ω, μ) [m² s/rad²] on omega × mu (μ towards) — the wave systems' target spectrum."""
    return field.directional_spectrum(omega, mu)
