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

From a trial record, :func:`fuse_run` does the whole thing for one run: the radar's mean directional
spectrum over the run (turned into the ship's frame with the gyro heading), the design-stage RAOs
(:mod:`vtrials.reduce.design_rao`) at the run's mean log speed, the measured RMS of heave (IMU, double
integrated), pitch, roll and vertical acceleration (:mod:`vtrials.reduce.seamotion`). Measured on
simulator records: benchmarks/campaign_wavefusion.py (results in benchmarks/results/).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.errors import InputError
from vtrials.units import G

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


# ------------------------------------------------------------------------------------------ from records

COMPONENTS = ("heave", "pitch", "roll", "acc")


@dataclasses.dataclass(frozen=True)
class RunFusion:
    """Wave fusion of one run: the radar's H_s (mean over the run's spectra), each component's measured and
    predicted RMS, and the fused H_s for every requested combination of components."""

    hs_radar: float
    n_spectra: int
    measured: dict
    predicted: dict
    fused: dict          # {"heave+pitch": Fusion, ...}
    U: float
    heading: float
    heading_std: float = 0.0


def radar_window(record, t0: float, t1: float, radar: str = "radar"):
    """(ω [rad/s], directions towards [rad], mean S(ω, μ) [m² s/rad²], mean H_s [m], n) of the radar's
    spectra stamped inside [t0, t1] (each is stamped at the end of its acquisition)."""
    if radar not in record.instruments:
        raise InputError(str(getattr(record, "path", "record")), radar, "no wave radar in the record")
    t, spec = record.channel(radar, "spectrum")
    hs = record.channel(radar, "hs")[1]
    m = record.meta(radar)
    k = (t >= t0) & (t <= t1) & np.isfinite(hs)
    if not np.any(k):
        raise InputError(str(getattr(record, "path", "record")), radar, f"no radar spectrum between {t0:.0f} and {t1:.0f} s")
    S = np.asarray(spec)[k]
    return (np.asarray(m["omega_rad_s"], float), np.asarray(m["directions_to_rad"], float), S.mean(axis=0),
            float(np.mean(hs[k])), int(np.count_nonzero(k)))


def fuse_run(record, t0: float, t1: float, design, combos=(("heave", "pitch"),), radar: str = "radar",
             omega_c: float = 0.25, fs: float = 2.0, instruments: dict | None = None) -> RunFusion:
    """Seed 004's fusion for one run from its record (module doc): the radar's mean directional spectrum
    over the run, turned into the ship's frame with the gyro heading, predicts each motion component's RMS
    through the team's design RAOs (``design``, :class:`vtrials.reduce.design_rao.DesignRAO`) at the run's
    mean log speed; the record gives the measured RMS (:func:`vtrials.reduce.seamotion.run_motions`).
    The heave prediction carries the same high-pass (``omega_c`` on the encounter frequency, half-cosine
    from ω_c/2) as the double integration that measures it. ``combos``: tuples of 'heave', 'pitch', 'roll',
    'acc' (vertical acceleration at the IMU) fused together (r = mean of their ratios). ``instruments``:
    the record's instrument names by run_motions' role (imu, attitude, log, compass) where not the default."""
    from vtrials.reduce.seamotion import design_responses, run_motions

    bad = sorted({c for combo in combos for c in combo} - set(COMPONENTS))
    if bad or not combos or any(len(c) == 0 for c in combos):
        raise InputError("record", "combos", f"{bad or list(combos)}: each combination is a non-empty tuple of "
                         f"motion components; allowed heave, roll, pitch, acc")
    mot = run_motions(record, t0, t1, fs_out=fs, omega_c=omega_c, **(instruments or {}))
    w, mu_to, S, hs_r, n = radar_window(record, t0, t1, radar)
    mu_rel = mu_to - mot.heading
    W, M = np.meshgrid(w, mu_rel, indexing="ij")
    names = sorted({c for combo in combos for c in combo}, key=COMPONENTS.index)
    H = design_responses(design, names, W, M, mot.U, mot.site)
    we = np.abs(W - W * W * mot.U * np.cos(M) / G)
    taper = np.clip((we - 0.5 * omega_c) / (0.5 * omega_c), 0.0, 1.0)
    taper = 0.5 - 0.5 * np.cos(math.pi * taper)
    meas, pred = {}, {}
    ser = mot.series(names)
    for i, c in enumerate(names):
        h = H[i] * taper if c == "heave" else H[i]
        pred[c] = predicted_rms(w, mu_rel, S, h)
        meas[c] = float(np.std(ser[i]))
    fused = {"+".join(combo): fuse(hs_r, S, [meas[c] for c in combo], [pred[c] for c in combo]) for combo in combos}
    return RunFusion(hs_r, n, meas, pred, fused, mot.U, mot.heading, mot.heading_std)
