"""Reducing a seakeeping trial record (star pattern, seed 004): per leg the response spectra and RMS,
the transfer functions from the measured wave to the motions, and the encounter-frequency bookkeeping.

Inputs, from the record only: the log sheet (legs, EXECUTE/FINEX), the bow wave probe's surface
elevation (a point moving with the ship: the wave the ship meets, in the encounter frame), the motion
package (IMU specific forces and rates at its surveyed site), the vertical gyro (roll, pitch), the
gyro compass and the speed log, and the team's sea-state observation (mean wave direction).

Per leg, on a common grid at the probe's rate over [COMEX, FINEX] (the approach minute pads the
double integration; spectra use [EXECUTE, FINEX]):

* heave (up) of the IMU's site by strapdown with orientation: the earth-vertical acceleration from the
  specific-force triad rotated with roll and pitch from the vertical gyro, doubly integrated in the
  frequency domain with a high-pass at ``OMEGA_C`` (:mod:`vtrials.reduce.heave`); the vertical
  acceleration (up) of the same site; roll and pitch;
* response spectra S(ω_e) and RMS with chi-square 95 % intervals (:mod:`vtrials.reduce.spectra`); the
  probe's H_s = 4√m0 (m0 is the same on either frequency axis);
* transfer functions Ĥ₁ = Ĝ_xy/Ĝ_xx from the probe elevation x to each response y in encounter
  frequency, with coherence γ² and the random error ε of Bendat & Piersol (2010, Table 9.6,
  :mod:`vtrials.reduce.transfer`). The probe's stated gain accuracy (1σ) is added to ε in quadrature
  for the amplitude (a gain error scales every |Ĥ|); the phase interval is ε alone;
* encounter frequency ↔ wave frequency: a = U cos μ / g with U the log speed and μ the direction the
  waves travel relative to the heading (observed wave direction, gyro heading). Head to beam seas
  (a ≤ 0): each ω_e has one wave frequency. Following and quartering seas (a > 0): below
  ω_e* = 1/(4a) three wave frequencies share one |ω_e| — these bins are flagged ``ambiguous`` and
  given no wave frequency (:mod:`vtrials.reduce.encounter`); the transfer function itself is defined
  in ω_e and needs no mapping.

The phase of Ĥ refers to the probe's footprint, not to the ship's reference point (the wave phase at
the footprint differs by k·r_probe).
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.records.netcdf import Record
from vtrials.reduce import encounter as ENC
from vtrials.reduce import heave as HV
from vtrials.reduce import spectra as SPC
from vtrials.reduce import transfer as TF
from vtrials.units import G

OMEGA_C = 0.25  # high-pass corner of the heave double integration [rad/s] (below the encounter band of the sea)
SEGMENT_S = 120.0  # Welch segment length for a 25-min leg [s]; shorter legs use a quarter of the leg
RESPONSES = {"heave": "m", "vertical_acc": "m s-2", "roll": "rad", "pitch": "rad"}
COHERENCE_MIN = 0.8  # bins where the transfer function is reported as determined (issue 13)


def _by_kind(rec: Record) -> dict:
    out: dict = {}
    for name in rec.instruments:
        out.setdefault(rec.meta(name).get("kind"), []).append(name)
    return out


def _interp(rec: Record, inst: str, ch: str, t: np.ndarray, angular: bool = False) -> np.ndarray:
    ti, y = rec.channel(inst, ch)
    ok = np.isfinite(y)
    ti, y = ti[ok], y[ok]
    if angular:
        y = np.unwrap(y)
    return np.interp(t, ti, y)


def segment_length(duration_s: float) -> float:
    """Welch segment length [s] for a leg of ``duration_s``: 120 s, or a quarter of a shorter leg."""
    return min(SEGMENT_S, 0.25 * duration_s)


def _rms(x: np.ndarray, fs: float, nper: int) -> dict:
    v = SPC.variance_estimate(x, fs, nper)
    lo, hi = v.rms_interval()
    return {"value": v.rms, "lo95": lo, "hi95": hi, "dof": v.dof}


def reduce_leg(rec: Record, run: dict, kinds: dict) -> dict:
    """Spectra, RMS and transfer functions of one accepted leg (module doc)."""
    probe = kinds["wave_probe"][0]
    imu = kinds["imu"][0]
    vg = kinds["attitude"][0]
    fs = float(rec.meta(probe).get("nominal_rate_hz", 10.0))
    t_pad0, t0, t1 = float(run["t_comex"]), float(run["t_execute"]), float(run["t_finex"])
    n = int(math.floor((t1 - t_pad0) * fs))
    t = t_pad0 + np.arange(n) / fs
    roll = _interp(rec, vg, "roll", t)
    pitch = _interp(rec, vg, "pitch", t)
    ax, ay, az = (_interp(rec, imu, c, t) for c in ("ax", "ay", "az"))
    heave = HV.heave_from_accelerometers(ax, ay, az, roll, pitch, fs, OMEGA_C)
    acc_up = -HV.vertical_acceleration(ax, ay, az, roll, pitch)
    eta = _interp(rec, probe, "elevation", t)
    w = t >= t0
    series = {"heave": heave[w], "vertical_acc": acc_up[w] - np.mean(acc_up[w]), "roll": roll[w], "pitch": pitch[w]}
    x = eta[w] - np.mean(eta[w])
    T = float(np.count_nonzero(w)) / fs
    nper = int(round(segment_length(T) * fs))
    # the encounter geometry as the team knows it: log speed, gyro heading, observed wave direction
    heading = kinds.get("heading", [None])[0]
    psi = math.nan
    if heading is not None:
        h = _interp(rec, heading, "heading", t[w], angular=True)
        psi = math.atan2(float(np.mean(np.sin(h))), float(np.mean(np.cos(h))))
    logs = kinds.get("em_log") or kinds.get("doppler_log") or kinds.get("knotmeter") or []
    U = math.nan
    if logs:
        ch = "u" if rec.meta(logs[0]).get("kind") == "doppler_log" else "speed"
        U = float(np.mean(_interp(rec, logs[0], ch, t[w])))
    sea = rec.team.get("sea_observed") or []
    mu = math.nan
    if sea and math.isfinite(psi):
        mu = math.remainder(float(sea[0]["from_rad"]) + math.pi - psi, 2 * math.pi)  # travel direction re heading
    a = U * math.cos(mu) / G if math.isfinite(U) and math.isfinite(mu) else math.nan
    gain_sd = float(rec.meta(probe).get("scale_std", 0.0) or 0.0)
    out = {"run": run["run"], "label": run["label"], "wave_heading": run["maneuver"].get("wave_heading"),
           "station_keeping": bool(run["maneuver"].get("station_keeping")), "course_deg": run["course_deg"],
           "heading": psi, "speed": U, "mu": mu, "a": a, "duration_s": T, "fs_hz": fs, "segment_s": nper / fs,
           "omega_c": OMEGA_C, "probe_gain_std": gain_sd,
           "probe_site_m": rec.meta(probe).get("surveyed_position_m"),
           "imu_site_m": rec.meta(imu).get("surveyed_position_m")}
    out["singular_omega_e"] = 0.25 / a if a > 0 else None
    hs = SPC.variance_estimate(x, fs, nper)
    lo, hi = hs.hs_interval()
    out["hs_probe"] = {"value": hs.hs, "lo95": lo, "hi95": hi, "dof": hs.dof}
    sx = SPC.response_spectrum(x, fs, nper)
    out["omega_e"] = sx.omega.tolist()
    out["probe_spectrum"] = sx.S.tolist()
    if math.isfinite(a):
        W = ENC.wave_frequencies(sx.omega, U, mu)
        amb = np.isfinite(W[:, 1]) | (a > 0) & ~np.isfinite(W[:, 0])
        out["ambiguous"] = amb.tolist()
        out["omega_wave"] = np.where(amb, np.nan, W[:, 0] if a <= 0 else np.where(np.isfinite(W[:, 0]), W[:, 0], W[:, 2])).tolist()
    resp = {}
    for name, y in series.items():
        y = y - np.mean(y)
        sp = SPC.response_spectrum(y, fs, nper)
        tf = TF.transfer_function(x, y, fs, nper)
        eps = tf.error
        eps_amp = np.sqrt(eps ** 2 + gain_sd ** 2)
        z = 1.959963984540054
        amp = tf.amplitude
        resp[name] = {"units": RESPONSES[name], "rms": _rms(y, fs, nper), "spectrum": sp.S.tolist(),
                      "H_re": tf.H.real.tolist(), "H_im": tf.H.imag.tolist(), "coherence": tf.coherence.tolist(),
                      "error": eps.tolist(), "amp_error": eps_amp.tolist(), "n_d": tf.n_d,
                      "amp_lo95": (amp * (1 - z * eps_amp)).tolist(), "amp_hi95": (amp * (1 + z * eps_amp)).tolist(),
                      "phase_lo95": (tf.phase - z * eps).tolist(), "phase_hi95": (tf.phase + z * eps).tolist()}
    out["responses"] = resp
    return out


def reduce_seakeeping(rec: Record) -> dict:
    """Every accepted leg of a seakeeping record (:func:`reduce_leg`)."""
    kinds = _by_kind(rec)
    missing = [k for k in ("wave_probe", "imu", "attitude") if not kinds.get(k)]
    legs = []
    notes = []
    if missing:
        notes.append(f"the record has no {', '.join(missing)}: no transfer functions")
    else:
        for run in sorted([r for r in rec.run_log if r["accepted"]], key=lambda r: r["run"]):
            legs.append(reduce_leg(rec, run, kinds))
    return {"kind": "seakeeping", "legs": legs, "notes": notes, "coherence_min": COHERENCE_MIN}
