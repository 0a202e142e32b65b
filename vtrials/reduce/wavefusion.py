"""Wave fusion: scale a wave radar's spectrum by measured over predicted ship motions (seed 004).

Stredulinsky & Thornhill (2009, DRDC Atlantic TM 2009-…, "Shipboard wave measurement through fusion of
wave radar and ship motion data", eqs. 1–5): the radar gives the shape of the directional spectrum
S(ω, μ) well and its height poorly. Motion component i (heave displacement, pitch angle, vertical
acceleration, …) is predicted from the radar spectrum through the ship's RAOs,

    δ_pred,i² = ∫∫ |H_i(ω, μ)|² S(ω, μ) dμ dω      (RMS of a linear response; encounter frequency does not
                                                   change a variance),

and measured over the same run, δ_meas,i (RMS of the record). Then r_i = δ_meas,i/δ_pred,i, r = the
mean of r_i over the chosen components (eq. 5), H_s = r H_s,radar (eq. 1) and S′ = r² S (eq. 3).

The RAOs are an INPUT: the design-stage model the trials team has (seed 004 used the strip-theory code
ShipMo7), never the simulator's truth. Angles μ are the wave propagation direction relative to the
ship's heading (0 following, π head seas) on a uniform grid over one turn.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.errors import InputError

TWO_PI = 2.0 * math.pi


def predicted_rms(omega, mu, S_dir, rao) -> float:
    """δ_pred = √(∫∫ |H|² S dμ dω) for S_dir (n_ω, n_μ) [m² s/rad²] and RAO amplitudes or complex (n_ω, n_μ).

    ω [rad/s] any increasing grid (trapezoid); μ [rad] a uniform grid over one turn (rectangle rule).
    Units: those of the RAO per metre of wave amplitude.
    """
    omega = np.asarray(omega, dtype=float)
    mu = np.asarray(mu, dtype=float)
    S_dir = np.asarray(S_dir, dtype=float)
    H2 = np.abs(np.asarray(rao)) ** 2
    if S_dir.shape != (omega.size, mu.size) or H2.shape != S_dir.shape:
        raise InputError("record", "rao", f"S_dir {S_dir.shape} and rao {H2.shape} must both be "
                         f"(n_omega, n_mu) = ({omega.size}, {mu.size})")
    dmu = TWO_PI / mu.size
    return math.sqrt(float(np.trapezoid(np.sum(H2 * S_dir, axis=1) * dmu, omega)))


@dataclasses.dataclass(frozen=True)
class Fusion:
    """Ratios r_i per component, their mean r, the corrected H_s [m] and spectrum S′ = r² S."""

    ratios: np.ndarray
    r: float
    hs: float
    S: np.ndarray


def fuse(hs_radar: float, S_radar, measured_rms, predicted_rms_values) -> Fusion:
    """Seed 004 eqs. 1–5: r_i = δ_meas,i/δ_pred,i, r = mean r_i, H_s = r H_s,radar, S′ = r² S_radar."""
    meas = np.atleast_1d(np.asarray(measured_rms, dtype=float))
    pred = np.atleast_1d(np.asarray(predicted_rms_values, dtype=float))
    if meas.shape != pred.shape or meas.size == 0:
        raise InputError("record", "measured_rms", f"{meas.size} measured and {pred.size} predicted motion "
                         "components: give one predicted RMS per measured one (at least one)")
    if np.any(~np.isfinite(pred)) or np.any(pred <= 0.0):
        raise InputError("record", "predicted_rms", f"{pred.tolist()}: predicted RMS must be finite and > 0")
    if np.any(~np.isfinite(meas)) or np.any(meas < 0.0):
        raise InputError("record", "measured_rms", f"{meas.tolist()}: measured RMS must be finite and ≥ 0")
    ratios = meas / pred
    r = float(np.mean(ratios))
    return Fusion(ratios, r, r * float(hs_radar), r * r * np.asarray(S_radar, dtype=float))
